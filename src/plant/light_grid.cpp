#include "plant/light_grid.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace sylva::plant {
namespace {

Diagnostic GridError(std::string message) {
  Diagnostic d;
  d.kind = ErrorKind::kRuntime;
  d.message = std::move(message);
  return d;
}

}  // namespace

bool LightGrid::CellOf(const Vec3& p, int64_t* i, int64_t* j, int64_t* k) const {
  int64_t c[3];
  for (int a = 0; a < 3; ++a) {
    const double v = std::floor(p[a] / def_.cell) - double(origin_[a]);
    if (!(v >= 0 && v < double(size_[a]))) return false;  // NaN: outside
    c[a] = int64_t(v);
  }
  *i = c[0];
  *j = c[1];
  *k = c[2];
  return true;
}

// Adds strength * b^-q to the pyramid below voxel (i, j, k), clipped to the
// grid; (i, j, k) may lie outside it (a wall above or beside the buds).
void LightGrid::Cast(int64_t i, int64_t j, int64_t k, double strength) {
  const int64_t nx = size_[0], ny = size_[1], nz = size_[2];
  double w = strength;
  for (int64_t q = 0; q <= def_.depth; ++q, w /= def_.falloff) {
    const int64_t y = j - q;
    if (y < 0) break;
    if (y >= ny) continue;
    const int64_t x0 = std::max<int64_t>(0, i - q), x1 = std::min<int64_t>(nx - 1, i + q);
    const int64_t z0 = std::max<int64_t>(0, k - q), z1 = std::min<int64_t>(nz - 1, k + q);
    const float fw = float(w);
    for (int64_t z = z0; z <= z1; ++z) {
      float* row = shadow_.data() + (y * nz + z) * nx;
      for (int64_t x = x0; x <= x1; ++x) row[x] += fw;
    }
  }
}

Status LightGrid::Update(std::span<const Vec3> buds) {
  shadow_.clear();
  opaque_.clear();
  size_[0] = size_[1] = size_[2] = 0;
  if (buds.empty()) return {};
  const double cell = def_.cell;
  double lo[3], hi[3];
  for (int a = 0; a < 3; ++a) lo[a] = hi[a] = std::floor(buds[0][a] / cell);
  for (const Vec3& p : buds) {
    for (int a = 0; a < 3; ++a) {
      const double v = std::floor(p[a] / cell);
      if (!std::isfinite(v) || std::abs(v) > 1e15) {
        return GridError("a bud at a position that is not finite or too far (" +
                         std::to_string(p[a]) + ") cannot be placed in the light grid");
      }
      lo[a] = std::min(lo[a], v);
      hi[a] = std::max(hi[a], v);
    }
  }
  // Sideways and downward by the shadow's reach.
  lo[0] -= def_.depth;
  hi[0] += def_.depth;
  lo[2] -= def_.depth;
  hi[2] += def_.depth;
  lo[1] -= def_.depth;
  double cells = 1;
  for (int a = 0; a < 3; ++a) cells *= hi[a] - lo[a] + 1;
  if (cells > double(kMaxLightCells)) {
    return GridError("the light grid would hold " + std::to_string(uint64_t(cells)) +
                     " voxels, more than the limit of " + std::to_string(kMaxLightCells) +
                     ": the plant spans too many cells of " + std::to_string(cell) +
                     " (raise 'cell=' in 'environment: light')");
  }
  for (int a = 0; a < 3; ++a) {
    origin_[a] = int64_t(lo[a]);
    size_[a] = int64_t(hi[a] - lo[a] + 1);
  }
  shadow_.assign(size_t(cells), 0.0f);
  opaque_.assign(size_t(cells), 0);

  // Walls: every voxel of a wall that can reach the grid casts like a bud;
  // those inside the grid are opaque. First their extent, clipped to the
  // reach of the grid, so that the work is known before it is done.
  struct WallSpan {
    int64_t lo[3], hi[3];
    double strength;
  };
  std::vector<WallSpan> spans;
  double work = 0;
  for (const LightBox& w : def_.walls) {
    WallSpan span;
    bool empty = false;
    double voxels = 1;
    for (int a = 0; a < 3; ++a) {
      const double reachLo = double(origin_[a]) - (a == 1 ? 0 : def_.depth);
      const double reachHi = double(origin_[a] + size_[a] - 1) + def_.depth;
      const double l = std::max(std::floor(std::min(w.lo[a], w.hi[a]) / cell), reachLo);
      const double h = std::min(std::floor(std::max(w.lo[a], w.hi[a]) / cell), reachHi);
      if (!(l <= h)) empty = true;
      span.lo[a] = empty ? 0 : int64_t(l) - origin_[a];
      span.hi[a] = empty ? 0 : int64_t(h) - origin_[a];
      voxels *= empty ? 0 : h - l + 1;
    }
    if (empty) continue;
    span.strength = w.shadow >= 0 ? w.shadow : def_.shadow;
    spans.push_back(span);
    work += voxels;
  }
  double pyramid = 0;
  for (int q = 0; q <= def_.depth; ++q) pyramid += double(2 * q + 1) * double(2 * q + 1);
  work = (work + double(buds.size())) * pyramid;
  if (work > double(kMaxLightWork)) {
    shadow_.clear();
    opaque_.clear();
    size_[0] = size_[1] = size_[2] = 0;
    return GridError("the light grid would take " + std::to_string(uint64_t(work)) +
                     " voxel updates a step, more than the limit of " +
                     std::to_string(kMaxLightWork) +
                     " (raise 'cell=' or lower 'depth=' in 'environment: light')");
  }
  for (const WallSpan& w : spans) {
    for (int64_t y = w.lo[1]; y <= w.hi[1]; ++y) {
      for (int64_t z = w.lo[2]; z <= w.hi[2]; ++z) {
        for (int64_t x = w.lo[0]; x <= w.hi[0]; ++x) {
          Cast(x, y, z, w.strength);
          if (x >= 0 && x < size_[0] && y >= 0 && y < size_[1] && z >= 0 && z < size_[2])
            opaque_[size_t((y * size_[2] + z) * size_[0] + x)] = 1;
        }
      }
    }
  }
  // Buds.
  for (const Vec3& p : buds) {
    int64_t i, j, k;
    if (CellOf(p, &i, &j, &k)) Cast(i, j, k, def_.shadow);
  }
  return {};
}

double LightGrid::Exposure(const Vec3& p) const {
  int64_t i, j, k;
  if (shadow_.empty() || !CellOf(p, &i, &j, &k)) return 1.0;
  const size_t c = size_t((j * size_[2] + k) * size_[0] + i);
  if (opaque_[c]) return 0.0;
  // The bud's own shadow is taken out in float, as it was added: a lone
  // bud reads exactly 1.
  return std::clamp(1.0 - double(shadow_[c] - float(def_.shadow)), 0.0, 1.0);
}

Status LightEnvironment::Answer(std::span<EnvQuery> queries) {
  buds_.clear();
  buds_.reserve(queries.size());
  for (const EnvQuery& q : queries) buds_.push_back(q.position);
  if (Status s = grid_.Update(buds_); !s.ok()) return s;
  for (EnvQuery& q : queries) {
    if (!q.params.empty()) q.params[0] = grid_.Exposure(q.position);
  }
  return {};
}

}  // namespace sylva::plant
