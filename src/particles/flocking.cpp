#include "particles/flocking.h"

#include <algorithm>
#include <cmath>

namespace sylva::particles {

void Flocking::Accumulate(const ParticleState& s, const Vec3* x, const Vec3* v, Vec3* f) const {
  const size_t n = s.size();
  grid_.Build(x, n, def_.radius, pool_);
  const double sep2 = def_.separationRadius * def_.separationRadius;
  ForRanges(pool_, n, 1024, [&](size_t b, size_t e) {
  for (size_t i = b; i < e; ++i) {
    if (s.invMass[i] == 0) continue;
    Vec3 centre = Vec3::Zero(), velocity = Vec3::Zero(), away = Vec3::Zero();
    int count = 0;
    grid_.ForEachNeighbour(x, i, def_.radius, [&](size_t j) {
      centre += x[j];
      velocity += v[j];
      ++count;
      const Vec3 d = x[i] - x[j];
      const double d2 = d.squaredNorm();
      if (d2 < sep2 && d2 > 1e-24) away += d / d2;  // stronger the closer
    });
    Vec3 steer = def_.separation * away;
    if (count) {
      steer += def_.cohesion * (centre / count - x[i]);
      steer += def_.alignment * (velocity / count - v[i]);
    }
    steer += def_.seek * (def_.target - x[i]);
    for (const auto& [obstacle, radius] : def_.obstacles) {
      const Vec3 r = x[i] - obstacle;
      const double len = r.norm();
      const double dist = len - radius;
      if (!(len > 0) || dist >= def_.avoidDistance) continue;
      const Vec3 out = r / len;
      const double closeness = (def_.avoidDistance - dist) / def_.avoidDistance;  // 0 .. 1 (more inside)
      steer += def_.avoid * closeness / std::max(dist, 0.01 * def_.avoidDistance) * out;
      const double vn = v[i].dot(out);
      if (vn < 0) steer -= def_.avoid * closeness * vn * out;
    }
    f[i] += s.mass[i] * steer;
  }
  });
}

double OrderParameter(const ParticleState& s) {
  Vec3 sum = Vec3::Zero();
  size_t n = 0;
  for (const Vec3& v : s.velocity) {
    const double len = v.norm();
    if (len > 0) {
      sum += v / len;
      ++n;
    }
  }
  return n ? sum.norm() / double(n) : 0;
}

}  // namespace sylva::particles
