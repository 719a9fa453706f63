// The ball scenes that bench_particles (BM_SelfCollidingBalls) and
// pile_stats share: each adds its forces, box, balls and particle
// collisions to an empty System and returns the first status that is not
// ok (a caller reports it rather than timing a scene that is not the one
// named).
#pragma once

#include <memory>
#include <random>

#include "particles/system.h"

namespace sylva::bench {

// Issue 17's self-colliding balls: 10,000 balls of radius 0.05 m
// (restitution 0.3, friction 0.5 on the walls) in a box 2 m wide, under
// gravity, dropped as a jittered lattice 18 balls a side.
inline Status AddSelfCollidingBalls(particles::System& sys) {
  sys.AddForce(std::make_shared<particles::Gravity>(Vec3(0, -9.81, 0)));
  Status box = sys.AddCollider(particles::Collider::Box(Vec3(-1, 0, -1), Vec3(1, 10, 1), true)
                                   .Restitution(0.3)
                                   .Friction(0.5));
  if (!box.ok()) return box;
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-0.004, 0.004);
  for (int k = 0; k < 10000; ++k) {
    const int x = k % 18, z = (k / 18) % 18, y = k / 324;
    sys.state.Add(Vec3(-0.9 + 0.106 * x + u(rng), 0.06 + 0.11 * y, -0.9 + 0.106 * z + u(rng)),
                  Vec3::Zero());
    sys.state.radius.back() = 0.05f;
  }
  return sys.EnableParticleCollisions(0.05, 0.3);
}

// The pile of the PairContacts tests (tests/particles/pairs_test.cpp):
// 2,880 balls of radius 0.05 m, 12 x 12 x 20, in a box 1.2 m wide.
inline Status AddPile2880(particles::System& sys) {
  sys.AddForce(std::make_shared<particles::Gravity>(Vec3(0, -9.81, 0)));
  Status box =
      sys.AddCollider(particles::Collider::Box(Vec3(-0.6, 0, -0.6), Vec3(0.6, 10, 0.6), true)
                          .Restitution(0.3)
                          .Friction(0.5));
  if (!box.ok()) return box;
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> jitter(-0.005, 0.005);
  for (int y = 0; y < 20; ++y)
    for (int z = 0; z < 12; ++z)
      for (int x = 0; x < 12; ++x) {
        sys.state.Add(
            Vec3(-0.55 + 0.1 * x + jitter(rng), 0.1 + 0.11 * y, -0.55 + 0.1 * z + jitter(rng)),
            Vec3::Zero());
        sys.state.radius.back() = 0.05f;
      }
  return sys.EnableParticleCollisions(0.05, 0.3);
}

}  // namespace sylva::bench
