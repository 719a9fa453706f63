#include "particles/flocking.h"

#include <algorithm>
#include <cmath>

#include "particles/def_check.h"

namespace sylva::particles {

Status Validate(const FlockingDef& d) {
  using namespace check;
  SYLVA_CHECK_OK(Range("FlockingDef.radius", d.radius, 1e-9, 1e6, "m"));
  SYLVA_CHECK_OK(Range("FlockingDef.cohesion", d.cohesion, 0, 1e6));
  SYLVA_CHECK_OK(Range("FlockingDef.separation", d.separation, 0, 1e6));
  SYLVA_CHECK_OK(Range("FlockingDef.separationRadius", d.separationRadius, 0, 1e6, "m"));
  SYLVA_CHECK_OK(Range("FlockingDef.alignment", d.alignment, 0, 1e6));
  SYLVA_CHECK_OK(Range("FlockingDef.seek", d.seek, 0, 1e6));
  SYLVA_CHECK_OK(Finite("FlockingDef.target", d.target, 1e12, "m"));
  SYLVA_CHECK_OK(Range("FlockingDef.avoid", d.avoid, 0, 1e6));
  SYLVA_CHECK_OK(Range("FlockingDef.avoidDistance", d.avoidDistance, 1e-9, 1e6, "m"));
  for (size_t k = 0; k < d.obstacles.size(); ++k) {
    const std::string name = "FlockingDef.obstacles[" + std::to_string(k) + "]";
    SYLVA_CHECK_OK(Finite(name + ".centre", d.obstacles[k].first, 1e12, "m"));
    SYLVA_CHECK_OK(Range(name + ".radius", d.obstacles[k].second, 0, 1e6, "m"));
  }
  return {};
}

Expected<std::shared_ptr<Flocking>> Flocking::Create(const FlockingDef& def) {
  if (Status st = Validate(def); !st.ok()) return st.error();
  return std::shared_ptr<Flocking>(new Flocking(def));
}

void Flocking::Accumulate(const ParticleState& s, const Vec3* x, const Vec3* v, Vec3* f) const {
  const size_t n = s.size();
  grid_.Build(x, n, def_.radius, pool_, /*copyPositions=*/true);
  const double sep2 = def_.separationRadius * def_.separationRadius;
  // Boids in slot order, with positions and velocities copied in that order:
  // consecutive boids share their neighbourhood, which is read contiguously
  // and stays in the cache. Each boid's sums still run in the grid's fixed
  // order, so the result does not depend on the thread count.
  const uint32_t* order = grid_.order().data();
  const Vec3* sx = grid_.sortedPositions().data();
  sortedV_.resize(n);
  steer_.resize(n);
  ForRanges(pool_, n, BalancedGrain(pool_, n, 1024, 16384), [&](size_t b, size_t e) {
    for (size_t k = b; k < e; ++k) sortedV_[k] = v[order[k]];
  });
  const Vec3* sv = sortedV_.data();
  ForRanges(pool_, n, 1024, [&](size_t b, size_t e) {
    for (size_t k = b; k < e; ++k) {
      const Vec3 xi = sx[k], vi = sv[k];
      Vec3 centre = Vec3::Zero(), velocity = Vec3::Zero(), away = Vec3::Zero();
      int count = 0;
      grid_.ForEachInSlotOrder(xi, def_.radius, [&](size_t q) {
        if (q == k) return;
        centre += sx[q];
        velocity += sv[q];
        ++count;
        const Vec3 d = xi - sx[q];
        const double d2 = d.squaredNorm();
        if (d2 < sep2 && d2 > 1e-24) away += d / d2;  // stronger the closer
      });
      Vec3 steer = def_.separation * away;
      if (count) {
        steer += def_.cohesion * (centre / count - xi);
        steer += def_.alignment * (velocity / count - vi);
      }
      steer += def_.seek * (def_.target - xi);
      for (const auto& [obstacle, radius] : def_.obstacles) {
        const Vec3 r = xi - obstacle;
        const double len = r.norm();
        const double dist = len - radius;
        if (!(len > 0) || dist >= def_.avoidDistance) continue;
        const Vec3 out = r / len;
        const double closeness =
            (def_.avoidDistance - dist) / def_.avoidDistance;  // 0 .. 1 (more inside)
        steer += def_.avoid * closeness / std::max(dist, 0.01 * def_.avoidDistance) * out;
        const double vn = vi.dot(out);
        if (vn < 0) steer -= def_.avoid * closeness * vn * out;
      }
      steer_[k] = steer;
    }
  });
  // Back to particle order (each boid written once: no races).
  ForRanges(pool_, n, BalancedGrain(pool_, n, 1024, 16384), [&](size_t b, size_t e) {
    for (size_t k = b; k < e; ++k) {
      const size_t i = order[k];
      if (s.invMass[i] != 0) f[i] += s.mass[i] * steer_[k];
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
