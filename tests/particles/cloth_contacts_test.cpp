// Cloth against colliders, against itself, and in the wind.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "particles/capsules.h"
#include "particles/cloth.h"
#include "particles/collider.h"
#include "particles/helpers.h"

namespace sylva::particles {
namespace {

const Vec3 kG(0, -9.81, 0);

// A 1 m square sheet lying flat (in the xz plane) at height y, centred on
// the y axis.
ClothDef FlatSheet(int k, double y) {
  ClothDef def;
  def.columns = k;
  def.rows = k;
  def.origin = Vec3(-0.5, y, -0.5);
  def.u = Vec3(1, 0, 0);
  def.v = Vec3(0, 0, 1);
  def.windDrag = def.windLift = 0;
  return def;
}

// A sheet dropped on a ball drapes over it; with no collider it falls
// through. Both solvers; no particle ends inside the ball.
TEST(ClothContacts, SheetDropsOntoASphereAndDrapesOverIt) {
  const double R = 0.3;
  const Vec3 centre(0, 0, 0);
  for (ClothSolver solver : {ClothSolver::kXPBD, ClothSolver::kImplicit}) {
    for (bool collide : {false, true}) {
      ClothDef def = FlatSheet(24, R + 0.1);
      def.solver = solver;
      def.implicitStiffness = 5e4;
      def.cgIterations = 60;
      auto cloth = testing::Made(Cloth::Create(def));
      if (collide) ASSERT_OK(cloth->AddCollider(Collider::Sphere(centre, R).Friction(0.5)));
      for (int i = 0; i < 90; ++i) ASSERT_OK(cloth->Step(1.0 / 60, kG));
      double inside = 0;  // the deepest particle below the surface
      for (const Vec3& p : cloth->positions()) inside = std::max(inside, R - (p - centre).norm());
      const Vec3 middle = cloth->positions()[size_t(cloth->Index(12, 12))];
      const char* name = solver == ClothSolver::kXPBD ? "XPBD" : "implicit";
      if (collide) {
        EXPECT_LT(inside, 1e-6) << name << ": a particle is " << inside << " m inside the ball";
        EXPECT_NEAR(middle.y(), R, 0.02) << name << ": the middle of the sheet rests on top";
        if (solver == ClothSolver::kXPBD) {
          EXPECT_GT(cloth->lastContacts(), 0u) << name;
        }
      } else {
        EXPECT_LT(middle.y(), -3) << name << ": without the collider the sheet falls through";
      }
    }
  }
}

// Coulomb friction: on a plane tilted 20 degrees (tan 20 = 0.36) a sheet
// with mu = 0.6 stays where it landed; with mu = 0.1 it slides down.
TEST(ClothContacts, FrictionHoldsASheetOnASlopeThatAFrictionlessOneSlidesDown) {
  const double tilt = 20 * M_PI / 180;
  const Vec3 n(std::sin(tilt), std::cos(tilt), 0);  // downhill is +x
  double slid[2];
  for (int k = 0; k < 2; ++k) {
    const double mu = k == 0 ? 0.6 : 0.1;
    ClothDef def = FlatSheet(12, 0);
    // Lying on the slope, a millimetre above it.
    const Vec3 along(std::cos(tilt), -std::sin(tilt), 0);
    def.origin = -0.5 * along - Vec3(0, 0, 0.5) + 1e-3 * n;
    def.u = along;
    auto cloth = testing::Made(Cloth::Create(def));
    ASSERT_OK(cloth->AddCollider(Collider::Plane(Vec3::Zero(), n).Friction(mu)));
    const Vec3 start = cloth->positions()[0];
    for (int i = 0; i < 60; ++i) ASSERT_OK(cloth->Step(1.0 / 60, kG));
    slid[k] = (cloth->positions()[0] - start).dot(along);
    for (const Vec3& p : cloth->positions())
      ASSERT_GE(n.dot(p), -1e-9) << "mu " << mu << ": a particle under the plane";
  }
  EXPECT_LT(std::abs(slid[0]), 0.005) << "mu 0.6 slid " << slid[0] << " m in 1 s";
  // Sliding with mu = 0.1: a = g (sin - mu cos) = 2.43 m/s^2, 1.2 m in 1 s.
  EXPECT_GT(slid[1], 0.8) << "mu 0.1 slid " << slid[1] << " m in 1 s";
}

// A sheet dropped across a branch (a capsule) hangs over it; a triangle
// mesh floor under it holds it. No particle inside the capsule or under the
// floor.
TEST(ClothContacts, SheetHangsOverACapsuleAndRestsOnAMeshFloor) {
  auto branch = std::make_shared<const CapsuleBvh>(
      std::vector<Capsule>{{Vec3(-1, 0.5, 0), Vec3(1, 0.5, 0), 0.05}});
  auto floor = std::make_shared<const TriangleBvh>(
      std::vector<Vec3>{{-2, 0, -2}, {2, 0, -2}, {2, 0, 2}, {-2, 0, 2}},
      std::vector<std::array<uint32_t, 3>>{{0, 1, 2}, {0, 2, 3}});
  ClothDef def = FlatSheet(20, 0.7);
  def.u = Vec3(0.6, 0, 0);
  def.origin = Vec3(-0.3, 0.7, -0.5);  // 0.6 m along the branch, 1 m across it
  auto cloth = testing::Made(Cloth::Create(def));
  ASSERT_OK(cloth->AddCollider(Collider::Capsules(branch).Friction(0.5)));
  ASSERT_OK(cloth->AddCollider(Collider::Mesh(floor).Friction(0.5)));
  for (int i = 0; i < 120; ++i) ASSERT_OK(cloth->Step(1.0 / 60, kG));
  size_t insideBranch = 0, underFloor = 0;
  for (const Vec3& p : cloth->positions()) {
    insideBranch += branch->Contains(p - Vec3(0, 1e-9, 0)) && branch->Contains(p);
    underFloor += p.y() < 0;
  }
  EXPECT_EQ(insideBranch, 0u);
  EXPECT_EQ(underFloor, 0u);
  // The middle row lies on the branch; the free ends hang to the floor.
  const Vec3 middle = cloth->positions()[size_t(cloth->Index(10, 10))];
  EXPECT_NEAR(middle.y(), 0.55, 0.02) << "middle " << middle.transpose();
  const Vec3 end = cloth->positions()[size_t(cloth->Index(10, 0))];
  EXPECT_LT(end.y(), 0.2) << "end " << end.transpose();
}

// A sheet folded in two (the upper half one row spacing above the lower
// one) dropped onto a ball. A crossing is a particle of the upper half
// over the top of the ball that ends less than 1 mm farther from the
// centre than the lower half under it (the particle of the lower half in
// the nearest direction), or nearer: the layers merged or the upper one
// went through. Without self-collision they merge; with it, none crosses
// (the upper particles settle in the hollows between the lower ones, about
// 0.45 thickness above them).
TEST(ClothContacts, FoldedSheetDroppedOnABallDoesNotPassThroughItself) {
  const int C = 16, K = 10;  // columns; rows of each half
  const double s = 1.0 / (C - 1);
  const double R = 0.25, thickness = 0.8 * s;
  const Vec3 centre(0.5, -R - 0.05, 0.5 * (K - 1) * s);
  for (ClothSolver solver : {ClothSolver::kXPBD, ClothSolver::kImplicit}) {
    const char* name = solver == ClothSolver::kXPBD ? "XPBD" : "implicit";
    size_t crossings[2];
    for (int self = 0; self < 2; ++self) {
      ClothDef def;
      def.solver = solver;
      def.columns = C;
      def.rows = 2 * K;
      def.u = Vec3(1, 0, 0);
      def.v = Vec3(0, 0, (2 * K - 1) * s);  // square cells of side s
      def.bendCompliance = 1;
      def.windDrag = def.windLift = 0;
      def.thickness = self ? thickness : 0;
      auto cloth = testing::Made(Cloth::Create(def));
      std::vector<Vec3>& x = cloth->mutablePositions();
      for (int r = 0; r < 2 * K; ++r) {
        for (int c = 0; c < C; ++c) {
          const bool upper = r >= K;
          x[size_t(cloth->Index(c, r))] =
              Vec3(c * s, upper ? s : 0, (upper ? 2 * K - 1 - r : r) * s);
        }
      }
      ASSERT_OK(cloth->AddCollider(Collider::Sphere(centre, R).Friction(0.5)));
      for (int i = 0; i < 90; ++i) ASSERT_OK(cloth->Step(1.0 / 60, kG));
      size_t crossed = 0, counted = 0;
      for (int r = K; r < 2 * K; ++r) {
        for (int c = 0; c < C; ++c) {
          const Vec3 dt = x[size_t(cloth->Index(c, r))] - centre;
          if (dt.normalized().y() < 0.7) continue;  // over the top of the ball only
          double best = -2, rb = 0;
          for (int rr = 0; rr < K; ++rr) {
            for (int cc = 0; cc < C; ++cc) {
              const Vec3 db = x[size_t(cloth->Index(cc, rr))] - centre;
              const double cosine = db.normalized().dot(dt.normalized());
              if (cosine > best) {
                best = cosine;
                rb = db.norm();
              }
            }
          }
          ++counted;
          crossed += dt.norm() < rb + 1e-3;
        }
      }
      ASSERT_GT(counted, 20u) << name << ": too few upper particles over the ball to count";
      crossings[self] = crossed;
      if (self) {
        EXPECT_GT(cloth->lastContacts(), 0u) << name;
      }
    }
    EXPECT_GT(crossings[0], 10u) << name << ": without self-collision the layers should merge";
    EXPECT_EQ(crossings[1], 0u) << name << ": with self-collision (thickness " << thickness
                                << " m)";
  }
}

// The free edge of a flag in a steady, uniform wind: with the per-triangle
// drag and lift it flutters (its cross-wind position keeps changing); with
// only a drag on each particle toward the wind's velocity it streams out
// and goes still.
TEST(ClothWind, FlagFluttersInUniformWindWhereParticleDragGoesStill) {
  double variance[2];
  for (int perTriangle = 0; perTriangle < 2; ++perTriangle) {
    ClothDef def;
    def.columns = 36;
    def.rows = 24;
    def.u = Vec3(2.4, 0, 0);
    def.v = Vec3(0, -1.6, 0);
    def.mass = 0.2 * 2.4 * 1.6;
    def.substeps = 16;
    def.bendCompliance = 2;
    def.damping = 0.02;
    for (int j = 0; j < def.rows; ++j) def.pinned.push_back(j * def.columns);
    const Vec3 wind(6, 0, 1.5);
    if (!perTriangle) def.windDrag = def.windLift = 0;
    auto cloth = testing::Made(Cloth::Create(def));
    if (!perTriangle) {
      const double k = 0.02;  // N s/m a particle: the flag's weight at 3 m/s
      cloth->SetExternalForce(
          [k, wind](size_t, const Vec3&, const Vec3& v) { return Vec3(k * (wind - v)); });
    }
    double sum = 0, sum2 = 0;
    int samples = 0;
    for (int i = 0; i < 900; ++i) {
      ASSERT_OK(cloth->Step(1.0 / 60, kG, wind));
      if (i < 600) continue;  // the last 5 s of 15
      const double z = cloth->positions()[size_t(cloth->Index(35, 12))].z();
      sum += z;
      sum2 += z * z;
      ++samples;
    }
    variance[perTriangle] = sum2 / samples - (sum / samples) * (sum / samples);
  }
  EXPECT_GT(variance[1], 1e-3) << "per-triangle air forces: the free edge's variance (m^2)";
  EXPECT_LT(variance[0], 1e-5) << "per-particle drag: the free edge's variance (m^2)";
}

// A sheet falls face-on slower than edge-on: the plate's drag acts on the
// face, not along it.
TEST(ClothWind, SheetFallsSlowerFaceOnThanEdgeOn) {
  double drop[2];
  for (int faceOn = 0; faceOn < 2; ++faceOn) {
    ClothDef def;
    def.columns = def.rows = 10;
    def.mass = 0.05;  // 50 g/m^2, paper
    def.u = Vec3(0.5, 0, 0);
    def.v = faceOn ? Vec3(0, 0, 0.5) : Vec3(0, -0.5, 0);
    auto cloth = testing::Made(Cloth::Create(def));
    const double y0 = cloth->positions()[0].y();
    for (int i = 0; i < 60; ++i) ASSERT_OK(cloth->Step(1.0 / 60, kG));
    drop[faceOn] = y0 - cloth->positions()[0].y();
  }
  // Edge-on it falls freely (4.9 m in 1 s); face-on the plate's drag,
  // c_d A |u| = 0.25 N per m/s on 50 g... settles near 0.05 x 9.81 / 0.25 = 2 m/s.
  EXPECT_GT(drop[0], 4.8) << "edge-on drop in 1 s (m)";
  EXPECT_LT(drop[1], 0.6 * drop[0]) << "face-on " << drop[1] << " m, edge-on " << drop[0] << " m";
}

// The wind field is read at each triangle's centroid: a wind blowing only
// where x > 0.5 pushes the right half of a flat sheet (c_d A U for its
// area) and not the left.
TEST(ClothWind, WindFieldActsOnEachTriangleWhereItIs) {
  const double U = 4, dt = 1.0 / 60;
  ClothDef def;
  def.columns = 3;
  def.rows = 2;
  def.u = Vec3(1, 0, 0);
  def.v = Vec3(0, 1, 0);
  def.mass = 0.6;
  def.windDrag = 1;
  def.windLift = 1;
  auto cloth = testing::Made(Cloth::Create(def));
  ASSERT_OK(cloth->StepInWindField(dt, Vec3::Zero(), [&](const Vec3& x) {
    return x.x() > 0.5 ? Vec3(0, 0, U) : Vec3(0, 0, 0);
  }));
  Vec3 momentum = Vec3::Zero();
  for (const Vec3& v : cloth->velocities()) momentum += (def.mass / 6) * v;
  const Vec3 force = momentum / dt, want(0, 0, 1 * 0.5 * U);
  EXPECT_LT((force - want).norm(), 1e-9) << "force " << force.transpose();
  // A non-finite wind is reported, not dropped.
  const Status st = cloth->StepInWindField(dt, Vec3::Zero(),
                                           [](const Vec3&) { return Vec3(0, 0, std::nan("")); });
  EXPECT_FALSE(st.ok());
}

// A kStick collider holds what touches it: the particles on a ball stay
// where they landed while the rest of the sheet hangs around it.
TEST(ClothContacts, StickyColliderHoldsTheParticlesThatTouchIt) {
  const double R = 0.3;
  for (ClothSolver solver : {ClothSolver::kXPBD, ClothSolver::kImplicit}) {
    const char* name = solver == ClothSolver::kXPBD ? "XPBD" : "implicit";
    ClothDef def = FlatSheet(20, R + 0.05);
    def.solver = solver;
    def.implicitStiffness = 5e4;
    auto cloth = testing::Made(Cloth::Create(def));
    ASSERT_OK(cloth->AddCollider(Collider::Sphere(Vec3::Zero(), R).Respond(Response::kStick)));
    for (int i = 0; i < 30; ++i) ASSERT_OK(cloth->Step(1.0 / 60, kG));
    std::vector<size_t> held;
    for (size_t i = 0; i < cloth->positions().size(); ++i)
      if (cloth->positions()[i].norm() < R + 1e-6) held.push_back(i);
    ASSERT_GT(held.size(), 3u) << name << ": particles on the ball";
    const std::vector<Vec3> before = cloth->positions();
    for (int i = 0; i < 60; ++i) ASSERT_OK(cloth->Step(1.0 / 60, kG));
    double moved = 0;
    for (size_t i : held) moved = std::max(moved, (cloth->positions()[i] - before[i]).norm());
    EXPECT_LT(moved, 1e-3) << name << ": the farthest a held particle moved in 1 s (m)";
  }
}

// XPBD contacts are inelastic and keep the collider's thickness: a flat
// sheet dropped from 0.3 m onto a floor of restitution 1, kept 5 cm away,
// lands on the floor's grown surface and does not rise again; a thickness
// out of 0..1e3 m is a Diagnostic that adds nothing.
TEST(ClothContacts, ASheetKeepsTheThicknessFromAColliderAndDoesNotBounce) {
  const double thickness = 0.05;
  ClothDef def = FlatSheet(12, thickness + 0.3);
  auto cloth = testing::Made(Cloth::Create(def));
  const Collider floor = Collider::Plane(Vec3::Zero(), Vec3::UnitY()).Restitution(1);
  for (double bad : {-0.01, 1e4, std::nan("")})
    EXPECT_FALSE(cloth->AddCollider(floor, bad).ok()) << "thickness " << bad;
  EXPECT_TRUE(cloth->colliders().empty());
  ASSERT_OK(cloth->AddCollider(floor, thickness));
  double lowest = HUGE_VAL, riseAfterLanding = 0;
  bool landed = false;
  for (int i = 0; i < 120; ++i) {
    ASSERT_OK(cloth->Step(1.0 / 60, kG));
    double low = HUGE_VAL, high = -HUGE_VAL;
    for (const Vec3& p : cloth->positions()) {
      low = std::min(low, p.y());
      high = std::max(high, p.y());
    }
    lowest = std::min(lowest, low);
    if (landed) riseAfterLanding = std::max(riseAfterLanding, high - thickness);
    landed = landed || low < thickness + 1e-6;
  }
  EXPECT_TRUE(landed) << "lowest " << lowest;
  EXPECT_GE(lowest, thickness - 1e-9) << "a particle came closer than the thickness";
  EXPECT_LT(riseAfterLanding, 1e-3) << "the sheet rose after landing (m)";
}

TEST(ClothContacts, BadCollidersAndThicknessAreDiagnostics) {
  auto cloth = testing::Made(Cloth::Create(FlatSheet(4, 0)));
  Collider zero = Collider::Plane(Vec3::Zero(), Vec3::Zero());
  EXPECT_FALSE(cloth->AddCollider(zero).ok()) << "a plane with a zero normal";
  const Status kill =
      cloth->AddCollider(Collider::Sphere(Vec3::Zero(), 1).Respond(Response::kKill));
  ASSERT_FALSE(kill.ok());
  EXPECT_NE(kill.error().message.find("kKill"), std::string::npos) << kill.error().message;
  EXPECT_TRUE(cloth->colliders().empty());
  ClothDef def = FlatSheet(4, 0);
  def.thickness = std::nan("");
  EXPECT_FALSE(Validate(def).ok());
  def.thickness = 0.01;
  def.selfFriction = -1;
  EXPECT_FALSE(Validate(def).ok());
}

TEST(ClothContacts, OneAndTwoThreadsAreBitIdenticalWithContacts) {
  auto run = [](int threads) {
    ClothDef def = FlatSheet(40, 0.4);
    def.threads = threads;
    def.thickness = 0.02;
    auto cloth = testing::Made(Cloth::Create(def));
    EXPECT_OK(cloth->AddCollider(Collider::Sphere(Vec3::Zero(), 0.3).Friction(0.3)));
    EXPECT_OK(cloth->AddCollider(Collider::Plane(Vec3(0, -0.2, 0), Vec3::UnitY()).Friction(0.3)));
    for (int i = 0; i < 60; ++i) EXPECT_OK(cloth->Step(1.0 / 60, kG));
    return cloth->positions();
  };
  const auto one = run(1), two = run(2);
  size_t differ = 0;
  for (size_t i = 0; i < one.size(); ++i) differ += one[i] != two[i];
  EXPECT_EQ(differ, 0u) << "particles that differ between 1 and 2 threads";
}

}  // namespace
}  // namespace sylva::particles
