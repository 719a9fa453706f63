// Kinematic colliders: a moving plane, ball, mesh or capsule pushes and
// carries particles, with its velocity in the contact response
// (Collider::velocity).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "helpers.h"
#include "particles/bulk.h"
#include "particles/capsules.h"
#include "particles/collider.h"
#include "particles/system.h"

namespace sylva::particles {
namespace {

// A floor rising at 1 m/s under a resting ball of radius 0.05 under gravity:
// the ball rides on it, its centre 0.05 above the floor at every step and
// its velocity the floor's.
TEST(MovingCollider, ARisingFloorCarriesARestingParticle) {
  System sys(1);
  sys.AddForce(std::make_shared<Gravity>(Vec3(0, -9.81, 0)));
  ASSERT_OK(sys.AddCollider(
      Collider::Plane({0, 0, 0}, {0, 1, 0}).Restitution(0).Velocity(Vec3(0, 1, 0))));
  sys.state.Add(Vec3(0.3, 0.05, -0.2), Vec3(0, 1, 0));
  sys.state.radius.back() = 0.05f;
  double worstGap = 0, worstSpeed = 0;
  for (int s = 1; s <= 60; ++s) {
    STEP_OK(sys, 1.0 / 60, Integrator::kSymplecticEuler);
    const double floor = sys.colliders()[0].point.y();
    EXPECT_NEAR(floor, s / 60.0, 1e-12) << "the floor moved to " << floor << " at step " << s;
    worstGap = std::max(worstGap, std::abs(sys.state.position[0].y() - (floor + 0.05)));
    worstSpeed = std::max(worstSpeed, (sys.state.velocity[0] - Vec3(0, 1, 0)).norm());
  }
  EXPECT_LT(worstGap, 1e-9) << "the centre left the rising floor's surface by " << worstGap << " m";
  EXPECT_LT(worstSpeed, 1e-9) << "the velocity differed from the floor's by " << worstSpeed
                              << " m/s";
}

// A ball of radius 0.5 moving at 2 m/s along x hits a resting particle
// (radius 0.1) head on, no gravity: an elastic contact sends it off at
// 2 * 2 = 4 m/s (the ball's mass is infinite), an inelastic one at the
// ball's 2 m/s; its centre never comes within 0.6 of the ball's centre.
TEST(MovingCollider, AMovingBallPushesAParticle) {
  for (double e : {1.0, 0.0}) {
    System sys(1);
    ASSERT_OK(
        sys.AddCollider(Collider::Sphere({0, 0, 0}, 0.5).Restitution(e).Velocity(Vec3(2, 0, 0))));
    sys.state.Add(Vec3(1.5, 0, 0), Vec3::Zero());
    sys.state.radius.back() = 0.1f;
    double closest = HUGE_VAL;
    for (int s = 0; s < 120; ++s) {
      STEP_OK(sys, 1.0 / 60, Integrator::kSymplecticEuler);
      closest = std::min(closest, (sys.state.position[0] - sys.colliders()[0].point).norm());
    }
    const double expected = e == 1 ? 4 : 2;
    EXPECT_NEAR(sys.state.velocity[0].x(), expected, 1e-9)
        << "restitution " << e << ": the pushed particle moves at " << sys.state.velocity[0].x()
        << " m/s";
    EXPECT_NEAR(sys.state.velocity[0].y(), 0, 1e-12) << "restitution " << e;
    EXPECT_NEAR(sys.state.velocity[0].z(), 0, 1e-12) << "restitution " << e;
    EXPECT_GE(closest, 0.6 - 1e-9) << "restitution " << e << ": the centre came within " << closest
                                   << " m of the ball's centre";
  }
}

// A wall sweeping at 3 m/s across a floor pushes a row of resting
// particles ahead of it (restitution 0, friction 0.5): every particle ends
// ahead of the wall by at least its radius and moves with it.
TEST(MovingCollider, ASweepingWallPushesParticlesAlongAFloor) {
  System sys(1);
  sys.AddForce(std::make_shared<Gravity>(Vec3(0, -9.81, 0)));
  ASSERT_OK(sys.AddCollider(Collider::Plane({0, 0, 0}, {0, 1, 0}).Friction(0.5).Restitution(0)));
  ASSERT_OK(sys.AddCollider(
      Collider::Plane({0, 0, 0}, {1, 0, 0}).Restitution(0).Velocity(Vec3(3, 0, 0))));
  for (int i = 0; i < 10; ++i) {
    sys.state.Add(Vec3(0.2 + 0.1 * i, 0.02, 0.05 * i), Vec3::Zero());
    sys.state.radius.back() = 0.02f;
  }
  double worst = HUGE_VAL;
  for (int s = 0; s < 60; ++s) {
    STEP_OK(sys, 1.0 / 60, Integrator::kSymplecticEuler);
    const double wall = sys.colliders()[1].point.x();
    for (const Vec3& p : sys.state.position) worst = std::min(worst, p.x() - 0.02 - wall);
  }
  EXPECT_GE(worst, -1e-9) << "a centre came " << -worst << " m inside its radius of the wall";
  for (size_t i = 0; i < sys.state.size(); ++i) {
    EXPECT_NEAR(sys.state.velocity[i].x(), 3, 1e-9)
        << "particle " << i << " moves at " << sys.state.velocity[i].x() << " m/s after 1 s";
    EXPECT_GE(sys.state.position[i].y(), 0.02 - 1e-9) << "particle " << i << " sank";
  }
}

TEST(MovingCollider, BulkRisingFloorCarriesARestingParticle) {
  BulkSystem sys(1);
  sys.fields.gravity = Vec3(0, -9.81, 0);
  ASSERT_OK(sys.AddCollider(
      Collider::Plane({0, 0, 0}, {0, 1, 0}).Restitution(0).Velocity(Vec3(0, 1, 0))));
  sys.state.Add(Vec3(0.3, 0.05, -0.2), Vec3(0, 1, 0));
  sys.state.radius.back() = 0.05f;
  double worstGap = 0;
  for (int s = 1; s <= 60; ++s) {
    ASSERT_OK(sys.Step(1.0 / 60));
    const double floor = sys.colliders()[0].point.y();
    worstGap = std::max(worstGap, std::abs(sys.state.position(0).y() - (floor + 0.05)));
  }
  EXPECT_LT(worstGap, 1e-6) << "the centre left the rising floor's surface by " << worstGap << " m";
  EXPECT_NEAR(sys.state.velocity(0).y(), 1, 1e-6)
      << "the particle moves at " << sys.state.velocity(0).y() << " m/s";
}

// A mesh floor (two triangles, 4 m square) rising at 1 m/s under a resting
// ball of radius 0.05 under gravity: as with the plane, the ball rides on it
// at its radius, at the floor's velocity; the mesh moves by its offset.
TEST(MovingCollider, ARisingMeshCarriesARestingParticle) {
  auto bvh = std::make_shared<TriangleBvh>(
      std::vector<Vec3>{Vec3(-2, 0, -2), Vec3(2, 0, -2), Vec3(2, 0, 2), Vec3(-2, 0, 2)},
      std::vector<std::array<uint32_t, 3>>{{0, 2, 1}, {0, 3, 2}});
  for (bool bulk : {false, true}) {
    System sys(1);
    BulkSystem bsys(1);
    const Collider floor = Collider::Mesh(bvh).Restitution(0).Velocity(Vec3(0, 1, 0));
    double worstGap = 0, worstSpeed = 0;
    if (!bulk) {
      sys.AddForce(std::make_shared<Gravity>(Vec3(0, -9.81, 0)));
      ASSERT_OK(sys.AddCollider(floor));
      sys.state.Add(Vec3(0.3, 0.05, -0.2), Vec3(0, 1, 0));
      sys.state.radius.back() = 0.05f;
    } else {
      bsys.fields.gravity = Vec3(0, -9.81, 0);
      ASSERT_OK(bsys.AddCollider(floor));
      bsys.state.Add(Vec3(0.3, 0.05, -0.2), Vec3(0, 1, 0));
      bsys.state.radius.back() = 0.05f;
    }
    for (int s = 1; s <= 60; ++s) {
      if (!bulk) {
        STEP_OK(sys, 1.0 / 60, Integrator::kSymplecticEuler);
      } else {
        ASSERT_OK(bsys.Step(1.0 / 60));
      }
      const double y = bulk ? bsys.colliders()[0].offset.y() : sys.colliders()[0].offset.y();
      ASSERT_NEAR(y, s / 60.0, 1e-6) << "the mesh moved to " << y << " at step " << s;
      const Vec3 p = bulk ? bsys.state.position(0) : sys.state.position[0];
      const Vec3 v = bulk ? bsys.state.velocity(0) : sys.state.velocity[0];
      worstGap = std::max(worstGap, std::abs(p.y() - (y + 0.05)));
      worstSpeed = std::max(worstSpeed, (v - Vec3(0, 1, 0)).norm());
    }
    // A mesh is thin: its contacts keep a skin of about 1e-9 m (collider.h).
    const double tol = bulk ? 1e-5 : 1e-8;
    EXPECT_LT(worstGap, tol) << (bulk ? "BulkSystem" : "System")
                             << ": the centre left the rising mesh by " << worstGap << " m";
    EXPECT_LT(worstSpeed, 1e-5) << (bulk ? "BulkSystem" : "System")
                                << ": the velocity differed from the mesh's by " << worstSpeed
                                << " m/s";
  }
}

// A capsule (radius 0.5, along z) moving at 2 m/s along x hits a resting
// particle (radius 0.1) head on: elastic, it leaves at 4 m/s; inelastic, at
// the capsule's 2 m/s; its centre never comes within 0.6 of the axis.
TEST(MovingCollider, AMovingCapsulePushesAParticle) {
  auto bvh = std::make_shared<CapsuleBvh>(
      std::vector<Capsule>{Capsule{Vec3(0, 0, -1), Vec3(0, 0, 1), 0.5}});
  for (double e : {1.0, 0.0}) {
    System sys(1);
    ASSERT_OK(sys.AddCollider(Collider::Capsules(bvh).Restitution(e).Velocity(Vec3(2, 0, 0))));
    sys.state.Add(Vec3(1.5, 0, 0), Vec3::Zero());
    sys.state.radius.back() = 0.1f;
    double closest = HUGE_VAL;
    for (int s = 0; s < 120; ++s) {
      STEP_OK(sys, 1.0 / 60, Integrator::kSymplecticEuler);
      const Vec3 axis = sys.colliders()[0].offset;  // the capsule's centre
      closest = std::min(closest, (sys.state.position[0] - axis).head<2>().norm());
    }
    const double expected = e == 1 ? 4 : 2;
    EXPECT_NEAR(sys.state.velocity[0].x(), expected, 1e-9)
        << "restitution " << e << ": the pushed particle moves at " << sys.state.velocity[0].x()
        << " m/s";
    EXPECT_NEAR(sys.state.velocity[0].y(), 0, 1e-12) << "restitution " << e;
    EXPECT_NEAR(sys.state.velocity[0].z(), 0, 1e-12) << "restitution " << e;
    EXPECT_GE(closest, 0.6 - 1e-9) << "restitution " << e << ": the centre came within " << closest
                                   << " m of the capsule's axis";
  }
}

TEST(MovingCollider, ANonFiniteVelocityOrOffsetIsADiagnostic) {
  System sys(1);
  EXPECT_FALSE(sys.AddCollider(Collider::Sphere({0, 0, 0}, 1).Velocity(Vec3(0, NAN, 0))).ok())
      << "a NaN velocity was accepted";
  auto bvh =
      std::make_shared<TriangleBvh>(std::vector<Vec3>{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, 1)},
                                    std::vector<std::array<uint32_t, 3>>{{0, 1, 2}});
  Collider mesh = Collider::Mesh(bvh);
  mesh.offset = Vec3(0, 0, INFINITY);
  const Status s = sys.AddCollider(mesh);
  ASSERT_FALSE(s.ok()) << "an infinite offset was accepted";
  EXPECT_NE(s.error().message.find("offset"), std::string::npos) << s.error().message;
}

}  // namespace
}  // namespace sylva::particles
