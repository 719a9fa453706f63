#include "particles/grid.h"

#include <cmath>

namespace sylva::particles {

void NeighbourGrid::Build(const Vec3* x, size_t n, double cellSize) {
  cell_ = cellSize > 0 ? cellSize : 1;
  uint32_t slots = 1;
  while (slots < 2 * n && slots < (1u << 30)) slots <<= 1;
  mask_ = slots - 1;
  count_.assign(slots, 0);
  slotOf_.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const uint32_t s = Slot(int64_t(std::floor(x[i].x() / cell_)), int64_t(std::floor(x[i].y() / cell_)),
                            int64_t(std::floor(x[i].z() / cell_)));
    slotOf_[i] = s;
    ++count_[s];
  }
  start_.resize(size_t(slots) + 1);
  uint32_t sum = 0;
  for (uint32_t s = 0; s < slots; ++s) {
    start_[s] = sum;
    sum += count_[s];
  }
  start_[slots] = sum;
  order_.resize(n);
  for (size_t i = 0; i < n; ++i) order_[start_[slotOf_[i]] + --count_[slotOf_[i]]] = uint32_t(i);
}

Vec3 InverseSquare::Pair(const ParticleState& s, const Vec3* x, size_t i, size_t j) const {
  const Vec3 d = x[i] - x[j];
  const double r2 = d.squaredNorm() + eps2_;
  return k_ * s.mass[i] * s.mass[j] * d / (r2 * std::sqrt(r2));
}

void InverseSquare::Accumulate(const ParticleState& s, const Vec3* x, const Vec3*, Vec3* f) const {
  grid_.Build(x, s.size(), cutoff_);
  for (size_t i = 0; i < s.size(); ++i) {
    grid_.ForEachNeighbour(x, i, cutoff_, [&](size_t j) { f[i] += Pair(s, x, i, j); });
  }
}

void InverseSquare::AccumulateAllPairs(const ParticleState& s, const Vec3* x, Vec3* f) const {
  const double c2 = cutoff_ * cutoff_;
  for (size_t i = 0; i < s.size(); ++i) {
    for (size_t j = 0; j < s.size(); ++j) {
      if (i != j && (x[i] - x[j]).squaredNorm() <= c2) f[i] += Pair(s, x, i, j);
    }
  }
}

}  // namespace sylva::particles
