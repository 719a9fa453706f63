// Capsule colliders (a plant's branches) against closed forms: side, end
// balls, paths along the axis, starting inside, misses; the hierarchy
// against brute force; rain on a branch never ends inside it.
#include "particles/capsules.h"

#include <gtest/gtest.h>

#include "core/rng.h"
#include "particles/system.h"

namespace sylva::particles {
namespace {

TEST(Capsule, SideHitAtTheClosedFormFraction) {
  // Axis along x from 0 to 2, radius 0.5; a path straight down at x = 1
  // from y = 2 to y = -2 enters at y = 0.5: s = 1.5 / 4.
  const Capsule c{Vec3(0, 0, 0), Vec3(2, 0, 0), 0.5};
  double s;
  Vec3 n;
  ASSERT_TRUE(IntersectCapsule(c, Vec3(1, 2, 0), Vec3(1, -2, 0), &s, &n));
  EXPECT_NEAR(s, 1.5 / 4, 1e-12);
  EXPECT_NEAR((n - Vec3(0, 1, 0)).norm(), 0, 1e-12) << n.transpose();
  // An oblique path, z offset 0.3: enters where y^2 + 0.09 = 0.25.
  ASSERT_TRUE(IntersectCapsule(c, Vec3(1, 2, 0.3), Vec3(1, -2, 0.3), &s, &n));
  EXPECT_NEAR(2 - 4 * s, 0.4, 1e-12) << "entry height";
  EXPECT_NEAR(n.norm(), 1, 1e-12);
}

TEST(Capsule, EndBallsAndPathsAlongTheAxis) {
  const Capsule c{Vec3(0, 0, 0), Vec3(0, 3, 0), 0.25};
  double s;
  Vec3 n;
  // Down the axis from above: the top ball at y = 3.25.
  ASSERT_TRUE(IntersectCapsule(c, Vec3(0, 5, 0), Vec3(0, 1, 0), &s, &n));
  EXPECT_NEAR(5 - 4 * s, 3.25, 1e-12);
  EXPECT_NEAR((n - Vec3(0, 1, 0)).norm(), 0, 1e-12);
  // Beyond the bottom end, sideways through the bottom ball at y = -0.1.
  ASSERT_TRUE(IntersectCapsule(c, Vec3(-1, -0.1, 0), Vec3(1, -0.1, 0), &s, &n));
  EXPECT_NEAR(-1 + 2 * s, -std::sqrt(0.25 * 0.25 - 0.01), 1e-12);
  EXPECT_LT(n.y(), 0) << "the bottom ball's normal points down";
  // A miss, and a path that stops short.
  EXPECT_FALSE(IntersectCapsule(c, Vec3(1, 1, 0), Vec3(1, -1, 0), &s, &n));
  EXPECT_FALSE(IntersectCapsule(c, Vec3(0, 5, 0), Vec3(0, 3.3, 0), &s, &n));
}

TEST(Capsule, StartingInsideIsAContactAtOnce) {
  const Capsule c{Vec3(0, 0, 0), Vec3(1, 0, 0), 0.5};
  double s = 1;
  Vec3 n;
  ASSERT_TRUE(IntersectCapsule(c, Vec3(0.5, 0.2, 0), Vec3(0.5, 0.1, 0), &s, &n));
  EXPECT_EQ(s, 0);
  EXPECT_NEAR((n - Vec3(0, 1, 0)).norm(), 0, 1e-12);
}

TEST(CapsuleBvh, FindsWhatBruteForceFinds) {
  RandomStream rng{7};
  std::vector<Capsule> caps;
  for (int i = 0; i < 2000; ++i) {
    const Vec3 a(rng.Uniform() * 20 - 10, rng.Uniform() * 20 - 10, rng.Uniform() * 20 - 10);
    const Vec3 d(rng.Uniform() - 0.5, rng.Uniform() - 0.5, rng.Uniform() - 0.5);
    caps.push_back({a, a + d, 0.02 + 0.2 * rng.Uniform()});
  }
  const CapsuleBvh bvh(caps);
  EXPECT_EQ(bvh.size(), caps.size());
  int hits = 0;
  for (int k = 0; k < 6000; ++k) {
    const Vec3 a(rng.Uniform() * 22 - 11, rng.Uniform() * 22 - 11, rng.Uniform() * 22 - 11);
    // Long paths (the hierarchy) and short ones (the grid's cells).
    const double length = k % 2 ? 4 : 0.3;
    const Vec3 b = a + Vec3(rng.Uniform() - 0.5, rng.Uniform() - 0.5, rng.Uniform() - 0.5) * length;
    double best = 2;
    for (const Capsule& c : caps) {
      double s;
      Vec3 n;
      if (IntersectCapsule(c, a, b, &s, &n)) best = std::min(best, s);
    }
    Contact contact;
    const bool hit = bvh.Intersect(a, b, &contact);
    ASSERT_EQ(hit, best <= 1) << "path " << k;
    if (hit) {
      ++hits;
      EXPECT_EQ(contact.s, best) << "path " << k;
    }
  }
  EXPECT_GT(hits, 150) << "paths that hit a capsule";
}

TEST(CapsuleBvh, RainOnABranchNeverEndsInsideIt) {
  // A diagonal branch of 4 capsules; 2,000 drops fall through it at 10 m/s.
  std::vector<Capsule> branch;
  for (int i = 0; i < 4; ++i)
    branch.push_back({Vec3(i * 0.5, 1 + i * 0.25, 0), Vec3((i + 1) * 0.5, 1 + (i + 1) * 0.25, 0),
                      0.08 - 0.01 * i});
  auto bvh = std::make_shared<const CapsuleBvh>(branch);
  System sys(1);
  ASSERT_TRUE(sys.AddCollider(Collider::Capsules(bvh).Restitution(0.3).Friction(0.2)).ok());
  RandomStream rng{11};
  for (int i = 0; i < 2000; ++i)
    sys.state.Add(Vec3(rng.Uniform() * 2, 3 + rng.Uniform(), rng.Uniform() * 0.2 - 0.1),
                  Vec3(0, -10, 0));
  sys.AddForce(std::make_shared<Gravity>(Vec3(0, -9.81, 0)));
  int stopped = 0;
  for (int step = 0; step < 60; ++step) {
    ASSERT_TRUE(sys.Step(1.0 / 60, Integrator::kSymplecticEuler).ok());
    for (size_t i = 0; i < sys.state.size(); ++i)
      ASSERT_FALSE(bvh->Contains(sys.state.position[i]))
          << "particle " << i << " inside the branch at step " << step << ": "
          << sys.state.position[i].transpose();
  }
  for (size_t i = 0; i < sys.state.size(); ++i) stopped += sys.state.position[i].y() > 0.5;
  EXPECT_GT(stopped, 0) << "drops caught on top of the branch";
}

}  // namespace
}  // namespace sylva::particles
