#include "plant/density_environment.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace sylva::plant {
namespace {

// A point as the programs store it: floats; in 2D (x, z) with z = 0.
struct Point {
  float p[3];
};

Point ProgramPoint(const Vec3& v, bool is3d) {
  if (is3d) return Point{{float(v.x()), float(v.y()), float(v.z())}};
  return Point{{float(v.x()), float(v.z()), 0.0f}};
}

float Dist2(const Point& a, const Point& b) {
  const float d0 = a.p[0] - b.p[0], d1 = a.p[1] - b.p[1], d2 = a.p[2] - b.p[2];
  return d0 * d0 + d1 * d1 + d2 * d2;
}

// The programs' group: the second parameter converted to C's int.
int64_t Group(std::span<const double> params) {
  if (params.size() < 2) return 0;
  const double v = params[1];
  if (!std::isfinite(v)) return 0;
  return int64_t(std::clamp(std::trunc(v), -4e18, 4e18));
}

// Visits, for each point i, every j != i whose x lies within reach(i) +
// reachAll of x_i (a superset of the pairs that can collide), through one
// sort by x.
template <typename Fn>
void ForNeighbours(const std::vector<Point>& pts, const std::vector<float>& reach, float reachAll,
                   Fn&& visit) {
  const size_t n = pts.size();
  std::vector<uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(),
                   [&](uint32_t a, uint32_t b) { return pts[a].p[0] < pts[b].p[0]; });
  std::vector<float> xs(n);
  for (size_t k = 0; k < n; ++k) xs[k] = pts[order[k]].p[0];
  for (size_t k = 0; k < n; ++k) {
    const uint32_t i = order[k];
    // A little wider than the float test can accept (a product that
    // underflows to 0 still collides).
    const double r = (double(reach[i]) + double(reachAll)) * (1 + 1e-5) + 1e-20;
    const double x = xs[k];
    auto lo = std::lower_bound(xs.begin(), xs.end(), float(x - r));
    auto hi = std::upper_bound(xs.begin(), xs.end(), float(x + r));
    for (auto it = lo; it != hi; ++it) {
      const uint32_t j = order[size_t(it - xs.begin())];
      if (j != i) visit(i, j);
    }
  }
}

}  // namespace

std::vector<double> Honda81Answers(const Honda81Def& def, std::span<const DensityQuery> queries) {
  const size_t n = queries.size();
  std::vector<Point> pts(n);
  std::vector<float> vigor(n);
  std::vector<int64_t> group(n);
  for (size_t i = 0; i < n; ++i) {
    pts[i] = ProgramPoint(queries[i].position, def.is3d);
    vigor[i] = float(queries[i].params[0]);
    group[i] = Group(queries[i].params);
  }
  const float radius = float(def.radius);
  const float radius2 = radius * radius;
  std::vector<double> answer(n, 1.0);
  ForNeighbours(pts, std::vector<float>(n, std::abs(radius)), 0.0f, [&](uint32_t i, uint32_t j) {
    if (group[i] == group[j] && vigor[i] <= vigor[j] && Dist2(pts[i], pts[j]) <= radius2)
      answer[i] = 0.0;
  });
  return answer;
}

std::vector<double> EcosystemAnswers(const EcosystemDef& def,
                                     std::span<const DensityQuery> queries) {
  const size_t n = queries.size();
  std::vector<Point> pts(n);
  std::vector<float> radius(n), reach(n), vigor(n, 1.0f);
  std::vector<int64_t> group(n, 0);
  float maxReach = 0;
  for (size_t i = 0; i < n; ++i) {
    const auto params = queries[i].params;
    pts[i] = ProgramPoint(queries[i].position, def.is3d);
    radius[i] = float(params[0]);
    reach[i] = std::abs(radius[i]);
    maxReach = std::max(maxReach, reach[i]);
    if (def.vigor)
      vigor[i] = params.size() > 1 ? float(params[1]) : 1.0f;
    else
      group[i] = Group(params);
  }
  auto overlap = [&](uint32_t i, uint32_t j) {
    const float r = radius[i] + radius[j];
    return Dist2(pts[i], pts[j]) <= r * r;
  };
  std::vector<double> answer(n, 1.0);
  if (!def.vigor) {
    ForNeighbours(pts, reach, maxReach, [&](uint32_t i, uint32_t j) {
      if (group[i] == group[j] && radius[i] <= radius[j] && overlap(i, j)) answer[i] = 0.0;
    });
    return answer;
  }
  // With vigor the answers depend on the order: a disc removed earlier in
  // the word no longer dominates. Gather each disc's candidates first, then
  // decide in word order.
  std::vector<std::vector<uint32_t>> near(n);
  ForNeighbours(pts, reach, maxReach, [&](uint32_t i, uint32_t j) {
    if (overlap(i, j) &&
        (vigor[i] < vigor[j] || (vigor[i] == vigor[j] && radius[i] < radius[j])))
      near[i].push_back(j);
  });
  std::vector<char> removed(n, 0);
  for (size_t i = 0; i < n; ++i) {
    for (uint32_t j : near[i]) {
      if (!removed[j]) {
        removed[i] = 1;
        answer[i] = 0.0;
        break;
      }
    }
  }
  return answer;
}

}  // namespace sylva::plant
