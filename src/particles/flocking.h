// Flocking (Reynolds 1987, "Flocks, herds and schools"; Angel & Shreiner
// 9.4): each particle steers toward its neighbours' centre (cohesion), away
// from the ones too close (separation), toward their mean velocity
// (alignment), and optionally toward a target (seek) and away from
// obstacles (avoid). Neighbours are those
// within `radius`, found on the uniform grid.
#pragma once

#include <memory>
#include <utility>
#include <vector>

#include "particles/grid.h"

namespace sylva::particles {

// Ranges (Validate rejects anything outside, NaN included); gains are in
// N per m (or per m/s), 0..1e6:
struct FlockingDef {
  double radius = 1;              // neighbourhood, m, 1e-9..1e6
  double cohesion = 1;            // gain toward the neighbours' centre
  double separation = 1;          // gain away from close neighbours
  double separationRadius = 0.3;  // "too close", m, 0..1e6
  double alignment = 1;           // gain toward the neighbours' mean velocity
  double seek = 0;                // gain toward `target`
  Vec3 target{0, 0, 0};           // m, each component within +-1e12
  // Avoid: spherical obstacles (centre, radius). Within `avoidDistance` of
  // an obstacle's surface a boid is pushed out along the normal, harder the
  // closer it is, and its speed toward the obstacle is damped.
  double avoid = 0;                                // gain, 0..1e6
  double avoidDistance = 1;                        // m, 1e-9..1e6
  std::vector<std::pair<Vec3, double>> obstacles;  // centre within +-1e12, radius 0..1e6 m
};

// The first field of `def` outside its range, or ok.
Status Validate(const FlockingDef& def);

class Flocking : public Force {
 public:
  // A flocking force of a valid definition, or the Diagnostic of Validate.
  static Expected<std::shared_ptr<Flocking>> Create(const FlockingDef& def);
  // Gains and the target may change between steps (a moving target); they
  // must stay in the ranges above (not checked again).
  FlockingDef& def() { return def_; }
  void Accumulate(const ParticleState& s, const Vec3* x, const Vec3* v, Vec3* f) const override;

 private:
  explicit Flocking(const FlockingDef& def) : def_(def) {}
  FlockingDef def_;
  mutable NeighbourGrid grid_;
  mutable std::vector<Vec3> sortedV_, steer_;  // in the grid's slot order
};

// Order parameter: |sum of unit velocities| / n, 1 when all move alike.
double OrderParameter(const ParticleState& s);

}  // namespace sylva::particles
