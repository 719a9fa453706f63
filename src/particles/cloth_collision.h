// Cloth contacts (internal to the particles library): a cloth particle
// against the colliders of collider.h, and the cloth against itself.
//
// Both work on positions, once a substep, after the constraints: the
// substep moved a particle from p (its position at the substep's start) to
// x, and the contact moves x; the solver's velocity (x - p) / h then carries
// the response. Position-level contacts are inelastic (restitution is not
// used: cloth does not bounce).
//
// Colliders (Macklin, Muller, Chentanez & Kim, "Unified particle physics
// for real-time applications", SIGGRAPH 2014, sections 6.1 and 6.3): the
// first entry of the path p -> x into a collider gives a contact point and
// normal n; x goes back onto the contact's tangent plane by the depth
// d = n.(point - x), and Coulomb friction takes the substep's tangential
// displacement t: all of it when |t| <= mu d (static), else mu d of it
// (kinetic). Up to four contacts a substep (a crease between two
// colliders), then half-space solids project the particle out.
//
// Self-collision (Muller, "Ten minute physics" 15, 2022; Bridson, Fedkiw &
// Anderson 2002 for the idea of a thickness): every two particles closer
// than the cloth's thickness that were farther apart than that at rest are
// pushed apart to the thickness, each by its share of the inverse masses,
// with the same friction on their relative tangential motion. One Jacobi
// pass a substep (each particle averages the pushes of its neighbours, read
// from the positions before the pass): parallel and the same for any thread
// count. A sheet cannot pass through itself between two particles when the
// thickness is at least the diagonal gap of a cell (spacing / sqrt 2) and a
// substep moves no particle by more than the thickness.
#pragma once

#include <vector>

#include "core/math.h"
#include "core/parallel.h"
#include "particles/collider.h"
#include "particles/grid.h"

namespace sylva::particles::clothcontact {

// Moves x (reached from p over the substep) out of the colliders, with
// friction; returns the last collider it touched (null: none). A kStick
// collider takes the particle's tangential motion entirely (the caller
// then makes it immovable).
// radii[k]: the thickness kept from collider k (0: the surface itself; a
// sheet met from either side, such as another cloth, needs one, or a
// particle resting on it starts its next path on the surface and passes).
const Collider* Collide(const std::vector<Collider>& colliders, const std::vector<double>& radii,
                        const Vec3& p, Vec3& x);

class SelfCollision {
 public:
  // rest: the particles' rest positions (pairs closer than `thickness` at
  // rest are left to the cloth's constraints); thickness in m, > 0.
  SelfCollision(std::vector<Vec3> rest, double thickness, double friction);
  // The corrections dx of one pass over positions x (reached from prev
  // over the substep), inverse masses w (0: pinned, never moved).
  // Returns the number of particles pushed.
  size_t Pass(ThreadPool* pool, const Vec3* prev, const Vec3* x, const double* w,
              std::vector<Vec3>& dx);

 private:
  std::vector<Vec3> rest_;
  double thickness_, friction_;
  NeighbourGrid grid_;
};

}  // namespace sylva::particles::clothcontact
