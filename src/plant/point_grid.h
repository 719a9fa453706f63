// PointGrid: points bucketed in a uniform grid of cubic cells, to find the
// pairs closer than a reach without testing every pair (the collision and
// light programs of plant/density_environment.h, plant/chiba_environment.h).
// Cells are at least `reach` wide, so every point within reach of another
// lies in one of the 27 cells around it. Cells are keyed by 21 bits per
// axis over the points' bounding box (the cell grows when the box is more
// than 2^20 reaches wide); points with a NaN or infinite coordinate are in
// no cell and are never visited. Memory: 4 bytes a point plus one hash
// entry a non-empty cell.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <unordered_map>
#include <vector>

namespace sylva::plant {

class PointGrid {
 public:
  // `xyz` holds 3 floats a point.
  PointGrid(const std::vector<float>& xyz, double reach) : xyz_(xyz) {
    const size_t n = xyz.size() / 3;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < n; ++i) {
      if (!Finite(i)) continue;
      for (int c = 0; c < 3; ++c) {
        lo[c] = std::min(lo[c], double(xyz[3 * i + size_t(c)]));
        hi[c] = std::max(hi[c], double(xyz[3 * i + size_t(c)]));
      }
    }
    double extent = 0;
    for (int c = 0; c < 3; ++c) {
      origin_[c] = lo[c] <= hi[c] ? lo[c] : 0;
      extent = std::max(extent, hi[c] - lo[c]);
    }
    cell_ = std::max({std::abs(reach) * (1 + 1e-4), extent / double(1 << 20), 1e-20});
    keys_.assign(n, kNone);
    for (size_t i = 0; i < n; ++i)
      if (Finite(i)) keys_[i] = Key(Cell(i, 0), Cell(i, 1), Cell(i, 2));
    order_.resize(n);
    std::iota(order_.begin(), order_.end(), 0u);
    std::sort(order_.begin(), order_.end(), [&](uint32_t a, uint32_t b) {
      return keys_[a] < keys_[b] || (keys_[a] == keys_[b] && a < b);
    });
    for (size_t k = 0; k < n;) {
      size_t e = k;
      while (e < n && keys_[order_[e]] == keys_[order_[k]]) ++e;
      if (keys_[order_[k]] != kNone) ranges_.emplace(keys_[order_[k]], std::make_pair(k, e));
      k = e;
    }
  }

  // Calls fn(j) for every point j != i in the 27 cells around point i,
  // until fn returns false.
  template <typename Fn>
  void ForNear(uint32_t i, Fn&& fn) const {
    if (keys_[i] == kNone) return;
    const int64_t c[3] = {Cell(i, 0), Cell(i, 1), Cell(i, 2)};
    for (int64_t dz = -1; dz <= 1; ++dz)
      for (int64_t dy = -1; dy <= 1; ++dy)
        for (int64_t dx = -1; dx <= 1; ++dx) {
          const int64_t x = c[0] + dx, y = c[1] + dy, z = c[2] + dz;
          if (x < 0 || y < 0 || z < 0) continue;
          auto it = ranges_.find(Key(x, y, z));
          if (it == ranges_.end()) continue;
          for (size_t k = it->second.first; k < it->second.second; ++k)
            if (order_[k] != i && !fn(order_[k])) return;
        }
  }

 private:
  static constexpr uint64_t kNone = ~uint64_t(0);
  bool Finite(size_t i) const {
    return std::isfinite(xyz_[3 * i]) && std::isfinite(xyz_[3 * i + 1]) &&
           std::isfinite(xyz_[3 * i + 2]);
  }
  int64_t Cell(size_t i, int c) const {
    const double v = (double(xyz_[3 * i + size_t(c)]) - origin_[c]) / cell_;
    return std::clamp(int64_t(std::floor(v)), int64_t(0), (int64_t(1) << 21) - 1);
  }
  static uint64_t Key(int64_t x, int64_t y, int64_t z) {
    return uint64_t(x) | uint64_t(y) << 21 | uint64_t(z) << 42;
  }
  const std::vector<float>& xyz_;
  double origin_[3] = {0, 0, 0};
  double cell_ = 1;
  std::vector<uint64_t> keys_;
  std::vector<uint32_t> order_;
  std::unordered_map<uint64_t, std::pair<size_t, size_t>> ranges_;
};

}  // namespace sylva::plant
