#include "plant/density_environment.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "plant/point_grid.h"

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

// Visits, for each point i, every j != i that may lie within `reach` of
// it (a superset of the pairs that can collide), until visit returns false.
template <typename Fn>
void ForNeighbours(const std::vector<Point>& pts, float reach, Fn&& visit) {
  std::vector<float> xyz;
  xyz.reserve(pts.size() * 3);
  for (const Point& p : pts) xyz.insert(xyz.end(), p.p, p.p + 3);
  const PointGrid grid(xyz, double(reach));
  for (uint32_t i = 0; i < pts.size(); ++i)
    grid.ForNear(i, [&](uint32_t j) { return visit(i, j); });
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
  ForNeighbours(pts, std::abs(radius), [&](uint32_t i, uint32_t j) {
    if (group[i] == group[j] && vigor[i] <= vigor[j] && Dist2(pts[i], pts[j]) <= radius2)
      answer[i] = 0.0;
    return answer[i] != 0.0;  // one collision settles it
  });
  return answer;
}

std::vector<double> EcosystemAnswers(const EcosystemDef& def,
                                     std::span<const DensityQuery> queries) {
  const size_t n = queries.size();
  std::vector<Point> pts(n);
  std::vector<float> radius(n), vigor(n, 1.0f);
  std::vector<int64_t> group(n, 0);
  float maxReach = 0;
  for (size_t i = 0; i < n; ++i) {
    const auto params = queries[i].params;
    pts[i] = ProgramPoint(queries[i].position, def.is3d);
    radius[i] = float(params[0]);
    maxReach = std::max(maxReach, std::abs(radius[i]));
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
    ForNeighbours(pts, 2 * maxReach, [&](uint32_t i, uint32_t j) {
      if (group[i] == group[j] && radius[i] <= radius[j] && overlap(i, j)) answer[i] = 0.0;
      return answer[i] != 0.0;
    });
    return answer;
  }
  // With vigor the answers depend on the order: a disc removed earlier in
  // the word no longer dominates. Gather each disc's candidates first, then
  // decide in word order.
  std::vector<std::vector<uint32_t>> near(n);
  ForNeighbours(pts, 2 * maxReach, [&](uint32_t i, uint32_t j) {
    if (overlap(i, j) && (vigor[i] < vigor[j] || (vigor[i] == vigor[j] && radius[i] < radius[j])))
      near[i].push_back(j);
    return true;
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
