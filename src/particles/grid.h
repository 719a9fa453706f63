// A uniform grid of cells for neighbour queries (Angel & Shreiner 9.5:
// "divide space into cells and only sum over the own and adjacent cells").
// Rebuilt every step by counting sort: cell of each particle, prefix sums,
// scatter; O(n) and allocation-free after the first build. Cells are hashed
// into a table of a power-of-two size, so space need not be bounded.
#pragma once

#include <cstdint>
#include <vector>

#include "core/math.h"
#include "particles/system.h"

namespace sylva::particles {

class NeighbourGrid {
 public:
  // cellSize should be at least the query radius.
  void Build(const Vec3* x, size_t n, double cellSize);
  // Calls fn(j) for every particle j != i within `radius` of x[i].
  template <typename Fn>
  void ForEachNeighbour(const Vec3* x, size_t i, double radius, Fn&& fn) const;

 private:
  uint32_t Slot(int64_t cx, int64_t cy, int64_t cz) const;
  double cell_ = 1;
  uint32_t mask_ = 0;
  std::vector<uint32_t> start_, count_, order_, slotOf_;
};

// Inverse-square attraction (strength < 0) or repulsion (strength > 0)
// between all pairs closer than `cutoff`, softened:
// f_i = strength * m_i m_j * d / (|d|^2 + eps^2)^(3/2), d = x_i - x_j.
// Summed over the grid; equal to the all-pairs sum within the cut-off.
class InverseSquare : public Force {
 public:
  InverseSquare(double strength, double cutoff, double softening)
      : k_(strength), cutoff_(cutoff), eps2_(softening * softening) {}
  void Accumulate(const ParticleState& s, const Vec3* x, const Vec3* v, Vec3* f) const override;
  // The O(n^2) reference.
  void AccumulateAllPairs(const ParticleState& s, const Vec3* x, Vec3* f) const;

 private:
  Vec3 Pair(const ParticleState& s, const Vec3* x, size_t i, size_t j) const;
  double k_, cutoff_, eps2_;
  mutable NeighbourGrid grid_;
};

// --- inline ---

inline uint32_t NeighbourGrid::Slot(int64_t cx, int64_t cy, int64_t cz) const {
  uint64_t h = uint64_t(cx) * 0x9E3779B185EBCA87ULL ^ uint64_t(cy) * 0xC2B2AE3D27D4EB4FULL ^
               uint64_t(cz) * 0x165667B19E3779F9ULL;
  return uint32_t((h ^ (h >> 29)) & mask_);
}

template <typename Fn>
void NeighbourGrid::ForEachNeighbour(const Vec3* x, size_t i, double radius, Fn&& fn) const {
  const double r2 = radius * radius;
  const int64_t cx = int64_t(std::floor(x[i].x() / cell_)), cy = int64_t(std::floor(x[i].y() / cell_)),
                cz = int64_t(std::floor(x[i].z() / cell_));
  // Hashing can map two of the 27 cells to one slot: visit each slot once.
  uint32_t seen[27];
  int nseen = 0;
  for (int64_t dz = -1; dz <= 1; ++dz) {
    for (int64_t dy = -1; dy <= 1; ++dy) {
      for (int64_t dx = -1; dx <= 1; ++dx) {
        const uint32_t slot = Slot(cx + dx, cy + dy, cz + dz);
        bool dup = false;
        for (int k = 0; k < nseen; ++k) dup |= seen[k] == slot;
        if (dup) continue;
        seen[nseen++] = slot;
        for (uint32_t k = start_[slot]; k < start_[slot + 1]; ++k) {
          const uint32_t j = order_[k];
          if (j != i && (x[j] - x[i]).squaredNorm() <= r2) fn(size_t(j));
        }
      }
    }
  }
}

}  // namespace sylva::particles
