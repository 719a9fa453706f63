#include "particles/grid.h"

#include <cmath>

namespace sylva::particles {

void NeighbourGrid::Build(const Vec3* x, size_t n, double cellSize, ThreadPool* pool) {
  cell_ = cellSize > 0 ? cellSize : 1;
  uint32_t slots = 1;
  while ((slots < 2 * n || slots < 64) && slots < (1u << 30)) slots <<= 1;
  // Row offsets B dy + C dz (dy, dz in -1..1) must be 3 or more slots apart
  // modulo the table, or two rows of one neighbourhood would share a slot.
  static constexpr uint64_t kB[] = {0x9E3779B97F4A7C15ULL, 0xC2B2AE3D27D4EB4FULL, 0x165667B19E3779F9ULL,
                                    0xD6E8FEB86659FD93ULL, 0xA0761D6478BD642FULL, 0xE7037ED1A0B428DBULL};
  for (bool found = false; !found; slots <<= 1) {
    mask_ = slots - 1;
    for (uint64_t attempt = 0; attempt < 64 && !found; ++attempt) {
      B_ = (kB[attempt % 6] * (attempt / 6 + 1)) | 1;
      C_ = (kB[(attempt + 3) % 6] * (attempt + 1)) | 1;
      uint64_t row[9];
      int r = 0;
      for (int64_t dz = -1; dz <= 1; ++dz) {
        for (int64_t dy = -1; dy <= 1; ++dy) row[r++] = (uint64_t(dy) * B_ + uint64_t(dz) * C_) & mask_;
      }
      found = true;
      for (int a = 0; a < 9 && found; ++a) {
        for (int b = a + 1; b < 9 && found; ++b) {
          const uint64_t d = (row[a] - row[b]) & mask_;
          found = d >= 3 && d <= mask_ - 2;
        }
      }
    }
    if (found) break;
  }
  count_.assign(slots, 0);
  slotOf_.resize(n);
  ForRanges(pool, n, 65536, [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      slotOf_[i] = Slot(int64_t(std::floor(x[i].x() / cell_)), int64_t(std::floor(x[i].y() / cell_)),
                        int64_t(std::floor(x[i].z() / cell_)));
    }
  });
  for (size_t i = 0; i < n; ++i) ++count_[slotOf_[i]];
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
  grid_.Build(x, s.size(), cutoff_, pool_);
  // Each particle gathers its own sum: ranges of particles are independent.
  ForRanges(pool_, s.size(), 1024, [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      Vec3 sum = Vec3::Zero();
      grid_.ForEachNeighbour(x, i, cutoff_, [&](size_t j) { sum += Pair(s, x, i, j); });
      f[i] += sum;
    }
  });
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
