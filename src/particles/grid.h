// A uniform grid of cells for neighbour queries (Angel & Shreiner 9.5:
// "divide space into cells and only sum over the own and adjacent cells").
// Rebuilt every step, O(n) and allocation-free after the first build: the
// slot of each particle, then a stable two-pass sort of (slot, index) pairs:
// a counting sort by the slot's top 8 bits over ranges of particles in
// parallel, then each of the 256 buckets, small enough for the cache,
// counting-sorted by the remaining bits, which writes the table of slot
// starts as it goes. Within a slot the particles are in index order
// whatever the thread count. (A plain counting sort scatters into the whole
// table at random: three times slower at a million points; an 8-bit LSD
// radix sort takes three passes over memory and was 1.4x slower.) Cells are
// hashed into a table of a power-of-two size, so
// space need not be bounded.
//
// The hash is linear, slot = (cx + B cy + C cz) mod 2^k, so the three cells
// of a row (dx = -1, 0, 1) are three consecutive slots and their particles
// one contiguous range: a query reads 9 ranges, not 27 cells. Build checks
// that the 9 rows of a neighbourhood never overlap modulo the table size
// (it depends only on B, C and the size), picking other constants if they
// would; so no slot is ever visited twice and no de-duplication is needed.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/assert.h"
#include "core/math.h"
#include "particles/system.h"

namespace sylva::particles {

class NeighbourGrid {
 public:
  // cellSize should be at least the query radius.
  // The pool, if any, runs every pass in parallel. With copyPositions the
  // grid keeps a copy of the positions in slot order, so queries read the
  // candidates contiguously instead of through the index (about one more
  // pass over x; worth it when every particle queries, and valid only
  // while x does not change).
  void Build(const Vec3* x, size_t n, double cellSize, ThreadPool* pool = nullptr,
             bool copyPositions = false);
  // Calls fn(j) for every particle j != i within `radius` of x[i], in the
  // same order whatever the thread count.
  template <typename Fn>
  void ForEachNeighbour(const Vec3* x, size_t i, double radius, Fn&& fn) const;
  // After a Build with copyPositions: calls fn(k) for every neighbour of
  // the point p (closer than `radius`), where k is the neighbour's place in
  // slot order: it is particle order()[k], at sortedPositions()[k]. The
  // point itself, if it is a particle, is included (its distance is 0).
  template <typename Fn>
  void ForEachInSlotOrder(const Vec3& p, double radius, Fn&& fn) const;
  // The particles in slot order: neighbours are near each other in it, so
  // a loop over all particles in this order reuses the cache.
  const std::vector<uint32_t>& order() const { return order_; }
  const std::vector<Vec3>& sortedPositions() const { return sorted_; }
  // Calls visit(from, to) for the 9 ranges of slot order that hold the 27
  // cells around p (every particle within a cell size of p is in one; a
  // range may hold farther ones), in the same order whatever the thread
  // count.
  template <typename Fn>
  void ForEachCandidateRange(const Vec3& p, Fn&& visit) const;
  // Half of that neighbourhood, so that a loop over all particles meets
  // each pair once: for particle k of slot order (at p = sortedPositions()
  // [k]), calls visit(from, to) for the particles after k in its own cell,
  // the cell after it in x, and the 4 rows of 3 cells above its row in
  // (z, y). Of two particles in neighbouring cells exactly one has the
  // other in its half (the 27 cells of a neighbourhood have 27 distinct
  // slots); of two in one cell, the first in slot order.
  template <typename Fn>
  void ForEachHalfCandidateRange(const Vec3& p, uint32_t k, Fn&& visit) const;

 private:
  uint32_t Slot(int64_t cx, int64_t cy, int64_t cz) const;
  // The cell coordinate of c (Build and queries must agree exactly).
  int64_t CellOf(double c) const;
  double cell_ = 1, invCell_ = 1;
  uint32_t mask_ = 0;
  uint64_t B_ = 0, C_ = 0;
  std::vector<uint32_t> start_, order_;
  std::vector<Vec3> sorted_;  // x in slot order (copyPositions)
  bool copied_ = false;
  std::vector<uint64_t> keys_, tmp_;   // slot << 32 | index
  std::vector<uint32_t> hist_;         // per range, per top digit
  std::vector<uint32_t> bucketStart_;  // per top digit
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

inline int64_t NeighbourGrid::CellOf(double c) const {
  // floor without a libm call; clamped so the conversion is defined (NaN
  // goes to cell 0).
  const double v = std::clamp(c * invCell_, -4e18, 4e18);
  if (!(v == v)) return 0;
  const int64_t i = int64_t(v);
  return i - int64_t(v < double(i));
}

inline uint32_t NeighbourGrid::Slot(int64_t cx, int64_t cy, int64_t cz) const {
  return uint32_t((uint64_t(cx) + uint64_t(cy) * B_ + uint64_t(cz) * C_) & mask_);
}

// Calls visit(from, to) for the 9 contiguous ranges of slot order that
// hold the 27 cells around p.
template <typename Fn>
void NeighbourGrid::ForEachCandidateRange(const Vec3& p, Fn&& visit) const {
  const int64_t cx = CellOf(p.x()), cy = CellOf(p.y()), cz = CellOf(p.z());
  for (int64_t dz = -1; dz <= 1; ++dz) {
    for (int64_t dy = -1; dy <= 1; ++dy) {
      const uint32_t first = Slot(cx - 1, cy + dy, cz + dz);
      if (first + 2 <= mask_) {  // the row's three slots are contiguous
        visit(start_[first], start_[first + 3]);
      } else {
        for (uint32_t d = 0; d < 3; ++d) {
          const uint32_t slot = (first + d) & mask_;
          visit(start_[slot], start_[slot + 1]);
        }
      }
    }
  }
}

template <typename Fn>
void NeighbourGrid::ForEachHalfCandidateRange(const Vec3& p, uint32_t k, Fn&& visit) const {
  const int64_t cx = CellOf(p.x()), cy = CellOf(p.y()), cz = CellOf(p.z());
  const uint32_t own = Slot(cx, cy, cz);
  SYLVA_DCHECK(start_[own] <= k && k < start_[own + 1]);
  if (own + 1 <= mask_) {  // the own cell and the next are contiguous
    visit(k + 1, start_[own + 2]);
  } else {
    visit(k + 1, start_[own + 1]);
    visit(start_[0], start_[1]);
  }
  static constexpr int64_t kRows[4][2] = {{0, 1}, {1, -1}, {1, 0}, {1, 1}};  // dz, dy
  for (const auto& row : kRows) {
    const uint32_t first = Slot(cx - 1, cy + row[1], cz + row[0]);
    if (first + 2 <= mask_) {
      visit(start_[first], start_[first + 3]);
    } else {
      for (uint32_t d = 0; d < 3; ++d) {
        const uint32_t slot = (first + d) & mask_;
        visit(start_[slot], start_[slot + 1]);
      }
    }
  }
}

template <typename Fn>
void NeighbourGrid::ForEachNeighbour(const Vec3* x, size_t i, double radius, Fn&& fn) const {
  const double r2 = radius * radius;
  const Vec3 xi = x[i];
  const Vec3* sx = sorted_.data();
  ForEachCandidateRange(xi, [&](uint32_t from, uint32_t to) {
    if (copied_) {
      for (uint32_t k = from; k < to; ++k) {
        if ((sx[k] - xi).squaredNorm() <= r2 && order_[k] != i) fn(size_t(order_[k]));
      }
      return;
    }
    for (uint32_t k = from; k < to; ++k) {
      const uint32_t j = order_[k];
      if (j != i && (x[j] - xi).squaredNorm() <= r2) fn(size_t(j));
    }
  });
}

template <typename Fn>
void NeighbourGrid::ForEachInSlotOrder(const Vec3& p, double radius, Fn&& fn) const {
  const double r2 = radius * radius;
  const Vec3* sx = sorted_.data();
  ForEachCandidateRange(p, [&](uint32_t from, uint32_t to) {
    for (uint32_t k = from; k < to; ++k) {
      if ((sx[k] - p).squaredNorm() <= r2) fn(size_t(k));
    }
  });
}

}  // namespace sylva::particles
