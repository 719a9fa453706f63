// Bad numbers in definitions (docs/design.md): every particle Def and entry
// point rejects an out-of-range number with a Diagnostic naming the field
// and the value, before any work starts; nothing is clamped, nothing aborts.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "particles/bulk.h"
#include "particles/cloth.h"
#include "particles/emitter.h"
#include "particles/flocking.h"
#include "particles/forces.h"
#include "particles/helpers.h"

namespace sylva::particles {
namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();

// The status is an error whose message names `field` (and `value`, if given).
void ExpectRejected(const Status& st, const std::string& field, const std::string& value = "") {
  ASSERT_FALSE(st.ok()) << "accepted; expected a diagnostic naming " << field << " " << value;
  EXPECT_NE(st.error().message.find(field), std::string::npos) << st.error().message;
  EXPECT_NE(st.error().message.find(value), std::string::npos) << st.error().message;
}
template <typename T>
void ExpectRejected(const Expected<T>& e, const std::string& field, const std::string& value = "") {
  ASSERT_FALSE(e.ok()) << "accepted; expected a diagnostic naming " << field << " " << value;
  ExpectRejected(Status(e.error()), field, value);
}

TEST(EmitterDef, DefaultsAreValid) {
  EXPECT_OK(Validate(EmitterDef{}));
}

TEST(EmitterDef, RejectsEveryOutOfRangeField) {
  auto bad = [](auto set, const std::string& field, const std::string& value) {
    EmitterDef d;
    set(d);
    ExpectRejected(Emitter::Create(d), field, value);
  };
  bad([](EmitterDef& d) { d.rate = 1e30; }, "EmitterDef.rate", "1e+30");
  bad([](EmitterDef& d) { d.rate = kInf; }, "EmitterDef.rate", "inf");
  bad([](EmitterDef& d) { d.rate = -1; }, "EmitterDef.rate", "-1");
  bad([](EmitterDef& d) { d.rate = kNaN; }, "EmitterDef.rate", "nan");
  bad([](EmitterDef& d) { d.size.z() = kNaN; }, "EmitterDef.size", "nan");
  bad([](EmitterDef& d) { d.size.y() = -1; }, "EmitterDef.size", "-1");
  bad([](EmitterDef& d) { d.size.x() = 2e6; }, "EmitterDef.size", "2e+06");
  bad([](EmitterDef& d) { d.spreadDegrees = 190; }, "EmitterDef.spreadDegrees", "190");
  bad([](EmitterDef& d) { d.shape = EmitterShape::kMesh; }, "EmitterDef.mesh", "empty");
  bad([](EmitterDef& d) { d.shape = EmitterShape::kFunction; }, "EmitterDef.place", "empty");
  bad(
      [](EmitterDef& d) {
        auto m = std::make_shared<EmitterMesh>();  // three points on a line: no area
        m->positions = {Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(2, 2, 2)};
        m->triangles = {{0, 1, 2}};
        d.shape = EmitterShape::kMesh;
        d.mesh = m;
      },
      "EmitterDef.mesh", "area 0");
  bad(
      [](EmitterDef& d) {
        auto m = std::make_shared<EmitterMesh>();
        m->positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
        m->triangles = {{0, 1, 7}};
        d.shape = EmitterShape::kMesh;
        d.mesh = m;
      },
      "EmitterDef.mesh triangle 0", "index 7");
  bad(
      [](EmitterDef& d) {
        auto m = std::make_shared<EmitterMesh>();
        m->positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, kNaN)};
        m->triangles = {{0, 1, 2}};
        d.shape = EmitterShape::kMesh;
        d.mesh = m;
      },
      "EmitterDef.mesh position 2", "nan");
  bad([](EmitterDef& d) { d.maxAlive = 0; }, "EmitterDef.maxAlive", "0");
  bad([](EmitterDef& d) { d.maxBirths = 0; }, "EmitterDef.maxBirths", "0");
  bad([](EmitterDef& d) { d.position.z() = kNaN; }, "EmitterDef.position", "nan");
  bad([](EmitterDef& d) { d.velocity.y() = kNaN; }, "EmitterDef.velocity", "nan");
  bad([](EmitterDef& d) { d.positionRadius = -0.5; }, "EmitterDef.positionRadius", "-0.5");
  bad([](EmitterDef& d) { d.velocitySpread = kNaN; }, "EmitterDef.velocitySpread", "nan");
  bad([](EmitterDef& d) { d.lifetime = 0; }, "EmitterDef.lifetime", "0");
  bad([](EmitterDef& d) { d.lifetimeJitter = 3; }, "EmitterDef.lifetimeJitter", "3");
  bad([](EmitterDef& d) { d.mass = -1; }, "EmitterDef.mass", "-1");
  bad([](EmitterDef& d) { d.mass = 0; }, "EmitterDef.mass", "0 kg");
  bad([](EmitterDef& d) { d.colorEnd.z() = std::nanf(""); }, "EmitterDef.colorEnd", "nan");
  bad([](EmitterDef& d) { d.radiusStart = -1; }, "EmitterDef.radiusStart", "-1");
}

TEST(ClothDef, DefaultsAreValid) {
  EXPECT_OK(Validate(ClothDef{}));
}

TEST(ClothDef, RejectsEveryOutOfRangeField) {
  auto bad = [](auto set, const std::string& field, const std::string& value) {
    ClothDef d;
    set(d);
    ExpectRejected(Cloth::Create(d), field, value);
  };
  bad([](ClothDef& d) { d.columns = 1; }, "ClothDef.columns", "1");  // was clamped to 2 silently
  bad([](ClothDef& d) { d.rows = -5; }, "ClothDef.rows", "-5");
  bad([](ClothDef& d) { d.columns = d.rows = 5000; }, "ClothDef.columns * rows", "2.5e+07");
  bad([](ClothDef& d) { d.origin.y() = kNaN; }, "ClothDef.origin", "nan");
  bad([](ClothDef& d) { d.v = d.u; }, "ClothDef.u", "parallel");
  bad([](ClothDef& d) { d.mass = 0; }, "ClothDef.mass", "0");
  bad([](ClothDef& d) { d.stretchCompliance = -1e-3; }, "ClothDef.stretchCompliance", "-0.001");
  bad([](ClothDef& d) { d.shearCompliance = kNaN; }, "ClothDef.shearCompliance", "nan");
  bad([](ClothDef& d) { d.bendCompliance = kInf; }, "ClothDef.bendCompliance", "inf");
  bad([](ClothDef& d) { d.substeps = 0; }, "ClothDef.substeps", "0");
  bad([](ClothDef& d) { d.iterations = 0; }, "ClothDef.iterations", "0");
  bad([](ClothDef& d) { d.damping = -1; }, "ClothDef.damping", "-1");
  bad([](ClothDef& d) { d.windDrag = kNaN; }, "ClothDef.windDrag", "nan");
  bad([](ClothDef& d) { d.windLift = kInf; }, "ClothDef.windLift", "inf");
  bad(
      [](ClothDef& d) {
        d.pinned = {0, 400};
      },
      "ClothDef.pinned[1]", "400");  // was dropped silently
  bad([](ClothDef& d) { d.threads = -1; }, "ClothDef.threads", "-1");
  bad([](ClothDef& d) { d.implicitStiffness = 0; }, "ClothDef.implicitStiffness", "0");
  bad([](ClothDef& d) { d.cgIterations = 0; }, "ClothDef.cgIterations", "0");  // was clamped to 1
  bad([](ClothDef& d) { d.thickness = kNaN; }, "ClothDef.thickness", "nan");
  bad([](ClothDef& d) { d.selfFriction = -1; }, "ClothDef.selfFriction", "-1");
  bad([](ClothDef& d) { d.implicitStrainLimit = kInf; }, "ClothDef.implicitStrainLimit", "inf");
  bad([](ClothDef& d) { d.implicitStrainIterations = 0; }, "ClothDef.implicitStrainIterations",
      "0");
}

TEST(FlockingDef, RejectsEveryOutOfRangeField) {
  EXPECT_OK(Validate(FlockingDef{}));
  auto bad = [](auto set, const std::string& field, const std::string& value) {
    FlockingDef d;
    set(d);
    ExpectRejected(Flocking::Create(d), field, value);
  };
  bad([](FlockingDef& d) { d.radius = 0; }, "FlockingDef.radius", "0");
  bad([](FlockingDef& d) { d.cohesion = kNaN; }, "FlockingDef.cohesion", "nan");
  bad([](FlockingDef& d) { d.separationRadius = -1; }, "FlockingDef.separationRadius", "-1");
  bad([](FlockingDef& d) { d.target.z() = kNaN; }, "FlockingDef.target", "nan");
  bad([](FlockingDef& d) { d.avoidDistance = 0; }, "FlockingDef.avoidDistance", "0");
  bad(
      [](FlockingDef& d) {
        d.obstacles = {{Vec3(0, kNaN, 0), 1.0}};
      },
      "FlockingDef.obstacles[0].centre", "nan");
  bad(
      [](FlockingDef& d) {
        d.obstacles = {{Vec3::Zero(), -2.0}};
      },
      "FlockingDef.obstacles[0].radius", "-2");
}

TEST(NoiseWindDef, RejectsEveryOutOfRangeField) {
  EXPECT_OK(Validate(NoiseWindDef{}));
  auto bad = [](auto set, const std::string& field, const std::string& value) {
    NoiseWindDef d;
    set(d);
    ExpectRejected(NoiseWind::Create(d), field, value);
  };
  bad([](NoiseWindDef& d) { d.mean.z() = kNaN; }, "NoiseWindDef.mean", "nan");
  bad([](NoiseWindDef& d) { d.speed = -1; }, "NoiseWindDef.speed", "-1");
  bad([](NoiseWindDef& d) { d.scale = 0; }, "NoiseWindDef.scale", "0");  // was a division by zero
  bad([](NoiseWindDef& d) { d.drag = kInf; }, "NoiseWindDef.drag", "inf");
  bad([](NoiseWindDef& d) { d.modes = 0; }, "NoiseWindDef.modes", "0");  // was clamped to 1
}

TEST(FieldGrid, RejectsBadShapesInsteadOfAsserting) {
  const Vec3 lo(0, 0, 0), hi(1, 1, 1);
  ExpectRejected(FieldGrid::Create(lo, hi, {2, 2, 2}, std::vector<Vec3>(7, Vec3::Zero())),
                 "FieldGrid has 7 samples");
  ExpectRejected(FieldGrid::Create(lo, hi, {1, 2, 2}, std::vector<Vec3>(4, Vec3::Zero())),
                 "FieldGrid n[0]", "1");
  ExpectRejected(FieldGrid::Create(hi, lo, {2, 2, 2}, std::vector<Vec3>(8, Vec3::Zero())),
                 "FieldGrid lo");
  std::vector<Vec3> samples(8, Vec3::Zero());
  samples[5].y() = kNaN;
  ExpectRejected(FieldGrid::Create(lo, hi, {2, 2, 2}, samples), "FieldGrid samples[5]", "nan");
}

TEST(Collider, ZeroOrNaNNormalIsRejectedNotSilentlyDisabled) {
  System s;
  ExpectRejected(s.AddCollider(Collider::Plane(Vec3::Zero(), Vec3::Zero())), "Collider.normal",
                 "(0, 0, 0)");
  ExpectRejected(s.AddCollider(Collider::Plane(Vec3::Zero(), Vec3(0, kNaN, 0))), "Collider.normal",
                 "nan");
  ExpectRejected(s.AddPlane(Plane{Vec3::Zero(), Vec3::Zero(), 1, 0}), "Collider.normal",
                 "(0, 0, 0)");
  ExpectRejected(s.AddCollider(Collider::Plane(Vec3(0, 0, kNaN), Vec3(0, 1, 0))), "Collider.point",
                 "nan");
  ExpectRejected(s.AddCollider(Collider::Sphere(Vec3::Zero(), -1)), "Collider.radius", "-1");
  ExpectRejected(s.AddCollider(Collider::Box(Vec3(0, kNaN, 0), Vec3(1, 1, 1))), "Collider.lo",
                 "nan");
  ExpectRejected(s.AddCollider(Collider::Polygon({Vec3(0, 0, 0), Vec3(1, 0, 0)})),
                 "Collider.polygon", "2");
  ExpectRejected(s.AddCollider(Collider::Polygon({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)})),
                 "Collider.normal");  // collinear: no winding
  ExpectRejected(s.AddCollider(Collider::Plane(Vec3::Zero(), Vec3(0, 1, 0)).Restitution(1.5)),
                 "Collider.restitution", "1.5");
  ExpectRejected(s.AddCollider(Collider::Plane(Vec3::Zero(), Vec3(0, 1, 0)).Friction(-0.1)),
                 "Collider.friction", "-0.1");
  EXPECT_EQ(s.colliders().size(), 0u) << "a rejected collider is not added";
  BulkSystem b;
  ExpectRejected(b.AddCollider(Collider::Plane(Vec3::Zero(), Vec3::Zero())), "Collider.normal",
                 "(0, 0, 0)");
  EXPECT_EQ(b.colliders().size(), 0u);
}

TEST(Springs, AddRejectsBadNumbersAndStepRejectsIndicesOutOfRange) {
  auto springs = std::make_shared<Springs>();
  ExpectRejected(springs->Add(0, 1, -1, 1, 0), "Springs.Add rest", "-1");
  ExpectRejected(springs->Add(0, 1, 1, kNaN, 0), "Springs.Add ks", "nan");
  ExpectRejected(springs->Add(0, 1, 1, 1, -2), "Springs.Add kd", "-2");
  ExpectRejected(springs->Add(3, 3, 1, 1, 0), "itself");
  EXPECT_EQ(springs->springs().size(), 0u);
  System s;
  s.state.Add(Vec3::Zero(), Vec3::Zero());
  s.state.Add(Vec3(1, 0, 0), Vec3::Zero());
  // Particle 1000000 does not exist: before, the step wrote past the end of
  // the force array (a heap overflow; the ASan build of particles_tests saw
  // it); now the step refuses before any work.
  EXPECT_OK(springs->Add(0, 1000000, 1, 10, 0));
  s.AddForce(springs);
  const Vec3 x0 = s.state.position[1];
  for (Integrator in :
       {Integrator::kSymplecticEuler, Integrator::kRK4, Integrator::kImplicitEuler}) {
    ExpectRejected(s.Step(0.01, in), "particle 1000000", "2 particles");
  }
  EXPECT_EQ(s.state.position[1], x0) << "nothing moved";
  EXPECT_EQ(s.steps, 0u);
}

TEST(Penalty, StepRejectsIndicesOutOfRange) {
  System s;
  s.state.Add(Vec3::Zero(), Vec3::Zero());
  auto pen = std::make_shared<Penalty>();
  pen->Distance(0, 7, 1, 10, 0);
  s.AddForce(pen);
  ExpectRejected(s.Step(0.01, Integrator::kSymplecticEuler), "particle 7", "1 particles");
}

TEST(Forces, GravityDragAndDriftWithBadNumbersStopTheStep) {
  auto run = [](std::shared_ptr<Force> f) {
    System s;
    s.state.Add(Vec3::Zero(), Vec3(1, 0, 0));
    s.AddForce(std::move(f));
    return s.Step(0.01, Integrator::kSymplecticEuler);
  };
  ExpectRejected(run(std::make_shared<Gravity>(Vec3(0, 0, kNaN))), "Gravity g", "nan");
  ExpectRejected(run(std::make_shared<Drag>(-0.5)), "Drag linear", "-0.5");
  ExpectRejected(run(std::make_shared<Drag>(0.1, kNaN)), "Drag quadratic", "nan");
  ExpectRejected(run(std::make_shared<RandomDrift>(-1, 7)), "RandomDrift sigma", "-1");
  EXPECT_OK(run(std::make_shared<Drag>(0.1, 0.01)));
}

TEST(System, StepRejectsZeroNegativeAndNaNSteps) {
  for (double h : {0.0, -0.01, kNaN, kInf, 1e7}) {
    System s;
    s.state.Add(Vec3::Zero(), Vec3(1, 0, 0));
    ExpectRejected(s.Step(h, Integrator::kSymplecticEuler), "System.Step h");
    EXPECT_EQ(s.state.position[0], Vec3::Zero()) << "h " << h;
    ExpectRejected(s.StepAdaptive(h, AdaptiveOptions{}), "System.StepAdaptive dt");
    EXPECT_EQ(s.time, 0.0) << "h " << h;
  }
  System s;
  s.maxMagnitude = kNaN;
  ExpectRejected(s.Step(0.01, Integrator::kSymplecticEuler), "System.maxMagnitude", "nan");
  System t;
  AdaptiveOptions opt;
  opt.minStep = 0;
  ExpectRejected(t.StepAdaptive(0.1, opt), "AdaptiveOptions.minStep", "0");
  ExpectRejected(t.EnableParticleCollisions(-1, 0.5), "EnableParticleCollisions radius", "-1");
  ExpectRejected(t.EnableParticleCollisions(0.1, kNaN), "EnableParticleCollisions restitution",
                 "nan");
}

TEST(BulkSystem, StepRejectsBadStepsAndFields) {
  for (double h : {0.0, -1.0, kNaN}) {
    BulkSystem b;
    b.state.Add(Vec3::Zero(), Vec3(1, 0, 0));
    ExpectRejected(b.Step(h), "BulkSystem.Step h");
    EXPECT_EQ(b.state.position(0), Vec3::Zero()) << "h " << h;
  }
  BulkSystem b;
  b.fields.gravity.z() = kNaN;  // NaN in z: every component is checked
  ExpectRejected(b.Step(0.01), "BulkFields.gravity", "nan");
  b.fields.gravity = Vec3::Zero();
  b.fields.linearDrag = -1;
  ExpectRejected(b.Step(0.01), "BulkFields.linearDrag", "-1");
  b.fields.linearDrag = 0;
  b.fields.wind.y() = kInf;
  ExpectRejected(b.Step(0.01), "BulkFields.wind", "inf");
  b.fields.wind = Vec3::Zero();
  EXPECT_OK(b.Step(0.01));
}

}  // namespace
}  // namespace sylva::particles
