#include "particles/grid.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace sylva::particles {

void NeighbourGrid::Build(const Vec3* x, size_t n, double cellSize, ThreadPool* pool,
                          bool copyPositions) {
  cell_ = cellSize > 0 ? cellSize : 1;
  invCell_ = 1 / cell_;
  uint32_t slots = 1;
  while ((slots < 2 * n || slots < 64) && slots < (1u << 30)) slots <<= 1;
  // Row offsets B dy + C dz (dy, dz in -1..1) must be 3 or more slots apart
  // modulo the table, or two rows of one neighbourhood would share a slot.
  static constexpr uint64_t kB[] = {0x9E3779B97F4A7C15ULL, 0xC2B2AE3D27D4EB4FULL,
                                    0x165667B19E3779F9ULL, 0xD6E8FEB86659FD93ULL,
                                    0xA0761D6478BD642FULL, 0xE7037ED1A0B428DBULL};
  for (bool found = false; !found; slots <<= 1) {
    mask_ = slots - 1;
    for (uint64_t attempt = 0; attempt < 64 && !found; ++attempt) {
      B_ = (kB[attempt % 6] * (attempt / 6 + 1)) | 1;
      C_ = (kB[(attempt + 3) % 6] * (attempt + 1)) | 1;
      uint64_t row[9];
      int r = 0;
      for (int64_t dz = -1; dz <= 1; ++dz) {
        for (int64_t dy = -1; dy <= 1; ++dy)
          row[r++] = (uint64_t(dy) * B_ + uint64_t(dz) * C_) & mask_;
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
  keys_.resize(n);
  tmp_.resize(n);
  order_.resize(n);
  start_.resize(size_t(slots) + 1);
  copied_ = copyPositions;
  if (copied_) sorted_.resize(n);
  // Two passes of a stable sort by slot. First a counting sort by the top
  // 8 bits of the slot into 256 buckets, in parallel over fixed ranges of
  // particles; then each bucket, small enough for the cache, is counting-
  // sorted by the remaining bits, which gives the slot starts directly.
  int bits = 0;
  while ((uint64_t(1) << bits) < slots) ++bits;
  const int topBits = std::min(bits, 8), lowBits = bits - topBits;
  const size_t buckets = size_t(1) << topBits, lowSlots = size_t(1) << lowBits;
  const uint32_t lowMask = uint32_t(lowSlots - 1);
  // Ranges of particles: a fixed split (a stable sort's result does not
  // depend on it), about four a thread.
  const size_t grain = BalancedGrain(pool, n, 16384);
  const size_t ranges = std::max<size_t>(1, (n + grain - 1) / grain);
  hist_.resize(ranges * buckets);
  bucketStart_.resize(buckets + 1);
  auto range = [&](size_t r) { return std::pair(r * grain, std::min(n, (r + 1) * grain)); };
  auto forRanges = [&](auto&& fn) {
    if (pool && ranges > 1) {
      pool->ParallelFor(ranges, fn);
    } else {
      for (size_t r = 0; r < ranges; ++r) fn(r);
    }
  };
  // The keys (slot << 32 | index) and each range's histogram of top digits.
  forRanges([&](size_t r) {
    uint32_t* h = hist_.data() + r * buckets;
    std::fill(h, h + buckets, 0u);
    const auto [b, e] = range(r);
    for (size_t i = b; i < e; ++i) {
      const uint32_t slot = Slot(CellOf(x[i].x()), CellOf(x[i].y()), CellOf(x[i].z()));
      keys_[i] = uint64_t(slot) << 32 | i;
      ++h[slot >> lowBits];
    }
  });
  // Offsets bucket-major, range-minor: the sort stays stable.
  uint32_t sum = 0;
  for (size_t d = 0; d < buckets; ++d) {
    bucketStart_[d] = sum;
    for (size_t r = 0; r < ranges; ++r) {
      const uint32_t c = hist_[r * buckets + d];
      hist_[r * buckets + d] = sum;
      sum += c;
    }
  }
  bucketStart_[buckets] = sum;
  forRanges([&](size_t r) {
    uint32_t* off = hist_.data() + r * buckets;
    const uint64_t* __restrict src = keys_.data();
    uint64_t* __restrict dst = tmp_.data();
    const auto [b, e] = range(r);
    for (size_t i = b; i < e; ++i) dst[off[uint32_t(src[i] >> 32) >> lowBits]++] = src[i];
  });
  // Each bucket: count its slots, write their starts, place its particles.
  auto sortBuckets = [&](size_t first, size_t last) {
    thread_local std::vector<uint32_t> cursor;
    cursor.resize(lowSlots);
    const uint64_t* __restrict keys = tmp_.data();
    for (size_t d = first; d < last; ++d) {
      const uint32_t b = bucketStart_[d], e = bucketStart_[d + 1];
      std::fill(cursor.begin(), cursor.end(), 0u);
      for (uint32_t k = b; k < e; ++k) ++cursor[uint32_t(keys[k] >> 32) & lowMask];
      uint32_t* start = start_.data() + (d << lowBits);
      uint32_t pos = b;
      for (size_t q = 0; q < lowSlots; ++q) {
        const uint32_t c = cursor[q];
        start[q] = pos;
        cursor[q] = pos;
        pos += c;
      }
      for (uint32_t k = b; k < e; ++k) {
        const uint32_t at = cursor[uint32_t(keys[k] >> 32) & lowMask]++;
        order_[at] = uint32_t(keys[k]);
        if (copyPositions) sorted_[at] = x[uint32_t(keys[k])];
      }
    }
  };
  if (pool && buckets > 1) {
    ForRanges(pool, buckets, BalancedGrain(pool, buckets, 1), sortBuckets);
  } else {
    sortBuckets(0, buckets);
  }
  start_[slots] = uint32_t(n);
}

Vec3 InverseSquare::Pair(const ParticleState& s, const Vec3* x, size_t i, size_t j) const {
  const Vec3 d = x[i] - x[j];
  const double r2 = d.squaredNorm() + eps2_;
  return k_ * s.mass[i] * s.mass[j] * d / (r2 * std::sqrt(r2));
}

void InverseSquare::Accumulate(const ParticleState& s, const Vec3* x, const Vec3*, Vec3* f) const {
  grid_.Build(x, s.size(), cutoff_, pool_, /*copyPositions=*/true);
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
