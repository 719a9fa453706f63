// Flocking (Reynolds 1987, "Flocks, herds and schools"; Angel & Shreiner
// 9.4): each particle steers toward its neighbours' centre (cohesion), away
// from the ones too close (separation), toward their mean velocity
// (alignment), and optionally toward a target (seek) and away from
// obstacles (avoid). Neighbours are those
// within `radius`, found on the uniform grid.
#pragma once

#include <utility>
#include <vector>

#include "particles/grid.h"

namespace sylva::particles {

struct FlockingDef {
  double radius = 1;              // neighbourhood
  double cohesion = 1;            // gain toward the neighbours' centre
  double separation = 1;          // gain away from close neighbours
  double separationRadius = 0.3;  // "too close"
  double alignment = 1;           // gain toward the neighbours' mean velocity
  double seek = 0;                // gain toward `target`
  Vec3 target{0, 0, 0};
  // Avoid: spherical obstacles (centre, radius). Within `avoidDistance` of
  // an obstacle's surface a boid is pushed out along the normal, harder the
  // closer it is, and its speed toward the obstacle is damped.
  double avoid = 0;
  double avoidDistance = 1;
  std::vector<std::pair<Vec3, double>> obstacles;
};

class Flocking : public Force {
 public:
  explicit Flocking(const FlockingDef& def) : def_(def) {}
  // Gains and the target may change between steps (a moving target).
  FlockingDef& def() { return def_; }
  void Accumulate(const ParticleState& s, const Vec3* x, const Vec3* v, Vec3* f) const override;

 private:
  FlockingDef def_;
  mutable NeighbourGrid grid_;
  mutable std::vector<Vec3> sortedV_, steer_;  // in the grid's slot order
};

// Order parameter: |sum of unit velocities| / n, 1 when all move alike.
double OrderParameter(const ParticleState& s);

}  // namespace sylva::particles
