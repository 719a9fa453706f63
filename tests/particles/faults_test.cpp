// Errors are reported, never swallowed: a non-finite number in any
// component (x, y or z) of a position or velocity, a non-positive-definite
// implicit system, a bad frame step for cloth or an emitter, each comes back
// as a Diagnostic naming the step and the particle.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "particles/bulk.h"
#include "particles/cloth.h"
#include "particles/emitter.h"
#include "particles/helpers.h"
#include "particles/system.h"

namespace sylva::particles {
namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();

// The status is an error whose message holds every one of `parts`.
void ExpectError(const Status& st, std::initializer_list<const char*> parts,
                 const std::string& context) {
  ASSERT_FALSE(st.ok()) << context << ": accepted";
  for (const char* p : parts) {
    EXPECT_NE(st.error().message.find(p), std::string::npos)
        << context << ": no \"" << p << "\" in: " << st.error().message;
  }
}

// Ten particles at rest; a force puts `bad` into component k of particle 7's
// force at step 3.
void AddBadForceAtStep3(System& s, int k, double bad) {
  for (int i = 0; i < 10; ++i) s.state.Add(Vec3(i, 0, 0), Vec3::Zero());
  s.AddForce(std::make_shared<ForceFunction>(
      [k, bad](const ParticleState& st, const Vec3*, const Vec3*, Vec3* f) {
        if (st.step == 3) f[7][k] = bad;
      }));
}

TEST(Faults, NonFiniteInAnyComponentIsReportedWithStepAndIdByEveryIntegrator) {
  for (Integrator in : {Integrator::kExplicitEuler, Integrator::kSymplecticEuler,
                        Integrator::kMidpoint, Integrator::kRK4, Integrator::kImplicitEuler}) {
    for (int k = 0; k < 3; ++k) {
      for (double bad : {kNaN, kInf, -kInf}) {
        const std::string ctx = "integrator " + std::to_string(int(in)) + ", component " +
                                std::to_string(k) + ", " + std::to_string(bad);
        System s;
        AddBadForceAtStep3(s, k, bad);
        for (int i = 0; i < 3; ++i) ASSERT_TRUE(s.Step(0.01, in).ok()) << ctx << " step " << i;
        ExpectError(s.Step(0.01, in), {"step 3", "particle id 7", "not finite"}, ctx);
        EXPECT_FALSE(s.Step(0.01, in).ok()) << ctx << ": a faulted system steps again";
      }
    }
  }
}

TEST(Faults, NonFiniteVelocityComponentIsReported) {
  // Explicit Euler moves x by the old velocity: NaN in vz alone reaches the
  // position's z and the velocity's z, nothing else.
  for (int k = 0; k < 3; ++k) {
    System s;
    for (int i = 0; i < 3; ++i) s.state.Add(Vec3(i, 0, 0), Vec3::Zero());
    s.state.velocity[2][k] = kNaN;
    ExpectError(s.Step(0.01, Integrator::kExplicitEuler), {"step 0", "particle id 2", "not finite"},
                "velocity component " + std::to_string(k));
  }
}

TEST(Faults, AdaptiveRK45ReportsANonFiniteDerivativeWithTheParticle) {
  for (int k = 0; k < 3; ++k) {
    System s;
    for (int i = 0; i < 10; ++i) s.state.Add(Vec3(i, 0, 0), Vec3::Zero());
    s.AddForce(std::make_shared<ForceFunction>(
        [k](const ParticleState& st, const Vec3*, const Vec3*, Vec3* f) {
          if (st.time > 0.05) f[7][k] = kNaN;
        }));
    ExpectError(s.StepAdaptive(0.1, AdaptiveOptions{}), {"particle id 7", "not finite"},
                "component " + std::to_string(k));
    EXPECT_FALSE(std::isnan(s.state.position[7][k])) << "the NaN was stored";
  }
}

// An anti-spring toward nothing: f = +k x, with its Jacobian df/dx = +k I,
// which makes M - h^2 df/dx negative definite once h^2 k > m.
class AntiSpring : public Force {
 public:
  explicit AntiSpring(double k) : k_(k) {}
  void Accumulate(const ParticleState& s, const Vec3* x, const Vec3*, Vec3* f) const override {
    for (size_t i = 0; i < s.size(); ++i) f[i] += k_ * x[i];
  }
  void AddJacobianProduct(const ParticleState& s, const Vec3*, const Vec3*, double cx, double,
                          const Vec3* p, Vec3* y) const override {
    for (size_t i = 0; i < s.size(); ++i) y[i] += cx * k_ * p[i];
  }

 private:
  double k_;
};

TEST(Faults, ImplicitSolveReportsANonPositiveDefiniteSystem) {
  System s;
  s.state.Add(Vec3(1, 0.5, 0.25), Vec3::Zero(), 1);
  s.AddForce(std::make_shared<AntiSpring>(1e4));  // h^2 k = 100 m at h = 0.1
  const Vec3 before = s.state.position[0];
  ExpectError(s.Step(0.1, Integrator::kImplicitEuler), {"step 0", "not positive definite"},
              "h^2 k = 100 m");
  EXPECT_EQ(s.state.position[0], before) << "a failed solve moved the particle";
  EXPECT_EQ(s.steps, 0u) << "a failed solve counted as a step";
  // A step small enough for the system to stay positive definite works.
  System t;
  t.state.Add(Vec3(1, 0.5, 0.25), Vec3::Zero(), 1);
  t.AddForce(std::make_shared<AntiSpring>(1e4));
  EXPECT_OK(t.Step(1e-3, Integrator::kImplicitEuler));
}

// A force whose Jacobian is broken one way at particle index `at`: a
// diagonal that h^2 df/dx turns negative, a NaN diagonal, a NaN in the
// right-hand side's product (cv = 0) or in the conjugate gradients' (cv != 0).
class BrokenJacobian : public Force {
 public:
  enum Kind { kNegativeDiagonal, kNaNDiagonal, kNaNRightHandSide, kNaNProduct };
  BrokenJacobian(Kind kind, size_t at) : kind_(kind), at_(at) {}
  void Accumulate(const ParticleState&, const Vec3*, const Vec3*, Vec3* f) const override {
    f[at_] += Vec3(0, 1, 0);  // a right-hand side that is not zero
  }
  void AddJacobianProduct(const ParticleState&, const Vec3*, const Vec3*, double, double cv,
                          const Vec3*, Vec3* y) const override {
    if ((kind_ == kNaNRightHandSide && cv == 0) || (kind_ == kNaNProduct && cv != 0))
      y[at_].z() = std::numeric_limits<double>::quiet_NaN();
  }
  void AddJacobianDiagonal(const ParticleState&, const Vec3*, const Vec3*, double cx, double,
                           Vec3* diag) const override {
    if (kind_ == kNegativeDiagonal) diag[at_].y() += cx * 1e4;  // 1 - 0.01 * 1e4 < 0
    if (kind_ == kNaNDiagonal) diag[at_].x() = std::numeric_limits<double>::quiet_NaN();
  }

 private:
  Kind kind_;
  size_t at_;
};

// Each way the implicit solve can fail is reported with the particle, and
// nothing moves; a solve that met a number that is not finite faults the
// system (its next step reports the same), an indefinite one does not (a
// smaller step may work).
TEST(Faults, ImplicitSolveReportsABadDiagonalAndABadProductAtTheirParticle) {
  struct Case {
    BrokenJacobian::Kind kind;
    std::vector<const char*> parts;
    bool latched;
  };
  const Case cases[] = {
      {BrokenJacobian::kNegativeDiagonal,
       {"step 0", "not positive definite", "diagonal at particle id 2"},
       false},
      {BrokenJacobian::kNaNDiagonal, {"step 0", "diagonal is not finite", "particle id 2"}, true},
      {BrokenJacobian::kNaNRightHandSide,
       {"step 0", "right-hand side h (f + h df/dx v) is not finite", "particle id 2"},
       true},
      {BrokenJacobian::kNaNProduct, {"step 0", "product A p is not finite", "particle id 2"}, true},
  };
  for (const Case& c : cases) {
    System s;
    for (int i = 0; i < 4; ++i) s.state.Add(Vec3(i, 1, 0), Vec3::Zero(), 1);
    s.AddForce(std::make_shared<BrokenJacobian>(c.kind, 2));
    const std::vector<Vec3> before = s.state.position;
    const Status st = s.Step(0.1, Integrator::kImplicitEuler);
    ASSERT_FALSE(st.ok()) << "kind " << c.kind << ": the broken solve was accepted";
    for (const char* part : c.parts)
      EXPECT_NE(st.error().message.find(part), std::string::npos)
          << "kind " << c.kind << ": no \"" << part << "\" in: " << st.error().message;
    EXPECT_EQ(s.state.position, before) << "kind " << c.kind << ": a failed solve moved particles";
    EXPECT_EQ(s.steps, 0u) << "kind " << c.kind << ": a failed solve counted as a step";
    const Status next = s.Step(0.1, Integrator::kSymplecticEuler);
    EXPECT_EQ(!next.ok(), c.latched)
        << "kind " << c.kind << ": the next step " << (next.ok() ? "ran" : next.error().message);
  }
}

TEST(Faults, BulkReportsNonFiniteInAnyComponent) {
  for (int a = 0; a < 6; ++a) {
    for (float bad : {std::nanf(""), std::numeric_limits<float>::infinity()}) {
      const std::string ctx = "array " + std::to_string(a) + ", " + std::to_string(bad);
      BulkSystem b;
      for (int i = 0; i < 20; ++i) b.state.Add(Vec3(i, 1, 0), Vec3::Zero());
      b.fields.gravity = Vec3(0, -9.81, 0);
      ASSERT_OK(b.AddCollider(Collider::Plane(Vec3::Zero(), Vec3(0, 1, 0))));
      for (int i = 0; i < 2; ++i) ASSERT_OK(b.Step(0.01));
      (*b.state.FloatArrays()[size_t(a)])[13] = bad;
      ExpectError(b.Step(0.01), {"step 2", "particle id 13", "not finite"}, ctx);
      EXPECT_FALSE(b.Step(0.01).ok()) << ctx << ": a faulted system steps again";
    }
  }
}

// BulkSystem checks its float state against maxMagnitude in float: the limit
// is rounded toward zero, so a component just above maxMagnitude, which the
// limit rounded to nearest would let through, is still reported.
TEST(Faults, BulkReportsAComponentJustBeyondALimitThatFloatRoundsUp) {
  const double limit = 1.0000001;  // float(limit) is 1 + 2^-23, above it
  ASSERT_GT(double(float(limit)), limit);
  const float beyond = 1.0f + 0x1p-23f;
  ASSERT_GT(double(beyond), limit);
  for (int a = 0; a < 6; ++a) {
    BulkSystem b;
    b.maxMagnitude = limit;
    for (int i = 0; i < 20; ++i) b.state.Add(Vec3::Zero(), Vec3::Zero());
    ASSERT_OK(b.Step(0.01));
    (*b.state.FloatArrays()[size_t(a)])[13] = beyond;
    ExpectError(b.Step(0.01), {"step 1", "particle id 13", "beyond the limit"},
                "array " + std::to_string(a));
  }
  // A component at the limit rounded down passes.
  BulkSystem b;
  b.maxMagnitude = limit;
  b.state.Add(Vec3(1, 1, 1), Vec3(1, 1, 1));
  ASSERT_OK(b.Step(1e-9));
}

// A particle's radius is what every collider and particle collisions see:
// a negative one let a ball sink through a mesh and a NaN one moved it
// anywhere, without a word. In a step with colliders (or particle
// collisions) a radius that is negative, not finite or beyond maxMagnitude
// is reported with the step and the particle id, by both systems and on
// every contact path (a lone plane's vector path on the widest lanes and on
// four, the general one); a system without colliders reads no radius and
// steps on.
TEST(Faults, ABadRadiusIsReportedWhereContactsWouldReadIt) {
  const float bads[] = {-1.0f, -1e-30f, std::nanf(""), std::numeric_limits<float>::infinity(),
                        2e12f};
  std::vector<int> widths = {0};  // the widest this processor runs
  if (kernels::RestLanes() == 8) widths.push_back(4);
  for (int lanes : widths)
    for (float bad : bads) {
      for (int colliders = 1; colliders <= 2; ++colliders) {
        const std::string ctx = "radius " + std::to_string(bad) + ", " + std::to_string(colliders) +
                                " collider(s), lanes " + std::to_string(lanes);
        BulkSystem b;
        if (lanes) b.SetKernel(kernels::Kernel::kAvx, lanes);
        for (int i = 0; i < 40; ++i) b.state.Add(Vec3(i, 0.2, 0), Vec3::Zero());
        for (float& r : b.state.radius) r = 0.1f;
        b.fields.gravity = Vec3(0, -9.81, 0);
        ASSERT_OK(b.AddCollider(Collider::Plane(Vec3::Zero(), Vec3(0, 1, 0))));
        if (colliders == 2) ASSERT_OK(b.AddCollider(Collider::Sphere(Vec3(0, -5, 0), 1)));
        for (int i = 0; i < 2; ++i) ASSERT_OK(b.Step(0.01));
        b.state.radius[13] = bad;
        b.state.radius[29] = bad;  // the lowest index is named
        ExpectError(b.Step(0.01), {"step 2", "particle id 13", "radius"}, "BulkSystem, " + ctx);
        EXPECT_FALSE(b.Step(0.01).ok()) << ctx << ": a faulted system steps again";

        System s(2);
        for (int i = 0; i < 40; ++i) s.state.Add(Vec3(i, 0.2, 0), Vec3::Zero());
        for (float& r : s.state.radius) r = 0.1f;
        s.AddForce(std::make_shared<Gravity>(Vec3(0, -9.81, 0)));
        if (colliders == 1) {
          ASSERT_OK(s.AddCollider(Collider::Plane(Vec3::Zero(), Vec3(0, 1, 0))));
        } else {
          ASSERT_OK(s.EnableParticleCollisions(0.1, 0.5));  // particle collisions alone
        }
        for (int i = 0; i < 2; ++i) ASSERT_OK(s.Step(0.01, Integrator::kSymplecticEuler));
        s.state.radius[13] = bad;
        s.state.radius[29] = bad;
        ExpectError(s.Step(0.01, Integrator::kSymplecticEuler),
                    {"step 2", "particle id 13", "radius"}, "System, " + ctx);
        EXPECT_FALSE(s.Step(0.01, Integrator::kSymplecticEuler).ok())
            << ctx << ": a faulted system steps again";
      }
    }
  // Without colliders no radius is read: the step is taken.
  BulkSystem b;
  b.state.Add(Vec3::Zero(), Vec3::Zero());
  b.state.radius[0] = -1;
  EXPECT_OK(b.Step(0.01));
  System s;
  s.state.Add(Vec3::Zero(), Vec3::Zero());
  s.state.radius[0] = std::nanf("");
  EXPECT_OK(s.Step(0.01, Integrator::kSymplecticEuler));
  // A radius of 0 (a point) and one at the limit are fine.
  BulkSystem z;
  z.maxMagnitude = 1e3;
  z.state.Add(Vec3(0, 1, 0), Vec3::Zero());
  z.state.Add(Vec3(5, 1, 0), Vec3::Zero());
  z.state.radius[1] = 1e3f;
  ASSERT_OK(z.AddCollider(Collider::Plane(Vec3::Zero(), Vec3(0, 1, 0))));
  EXPECT_OK(z.Step(0.01));
}

ClothDef SmallCloth(ClothSolver solver) {
  ClothDef def;
  def.columns = def.rows = 6;
  def.pinned = {0, 5};
  def.solver = solver;
  return def;
}

TEST(Cloth, StepReportsBadStepsBadFieldsAndNonFiniteParticles) {
  for (ClothSolver solver : {ClothSolver::kXPBD, ClothSolver::kImplicit}) {
    const std::string ctx = solver == ClothSolver::kXPBD ? "XPBD" : "implicit";
    auto cloth = testing::Made(Cloth::Create(SmallCloth(solver)));
    const Vec3 g(0, -9.81, 0);
    ExpectError(cloth->Step(0, g), {"Cloth.Step dt", "0"}, ctx);
    ExpectError(cloth->Step(-1, g), {"Cloth.Step dt", "-1"}, ctx);
    ExpectError(cloth->Step(kNaN, g), {"Cloth.Step dt", "nan"}, ctx);
    ExpectError(cloth->Step(1.0 / 60, Vec3(0, 0, kNaN)), {"Cloth.Step gravity", "nan"}, ctx);
    ExpectError(cloth->Step(1.0 / 60, g, Vec3(0, kInf, 0)), {"Cloth.Step wind", "inf"}, ctx);
    for (int i = 0; i < 3; ++i) ASSERT_OK(cloth->Step(1.0 / 60, g));
    cloth->mutablePositions()[20].z() = kNaN;
    ExpectError(cloth->Step(1.0 / 60, g), {"frame 3", "particle 20", "not finite"}, ctx);
    EXPECT_FALSE(cloth->Step(1.0 / 60, g).ok()) << ctx << ": a faulted cloth steps again";
  }
}

// A failure inside the implicit solve (here a wind field that is not
// finite, which makes the right-hand side NaN) comes back from Cloth::Step
// with the frame and the substep, and the cloth refuses further frames; XPBD
// reports the same field as a non-finite particle.
TEST(Cloth, ImplicitSolveFailuresAreReportedWithTheFrame) {
  for (ClothSolver solver : {ClothSolver::kXPBD, ClothSolver::kImplicit}) {
    const bool implicit = solver == ClothSolver::kImplicit;
    const std::string ctx = implicit ? "implicit" : "XPBD";
    auto cloth = testing::Made(Cloth::Create(SmallCloth(solver)));
    const Vec3 g(0, -9.81, 0);
    for (int i = 0; i < 2; ++i) ASSERT_OK(cloth->Step(1.0 / 60, g));
    const Status st = cloth->StepInWindField(
        1.0 / 60, g, [](const Vec3& x) { return x.x() > 0.5 ? Vec3(0, 0, kNaN) : Vec3::Zero(); });
    if (implicit) {
      ExpectError(st, {"cloth: frame 2, implicit substep 0", "not finite"}, ctx);
    } else {
      ExpectError(st, {"frame 2", "not finite"}, ctx);
    }
    EXPECT_FALSE(cloth->Step(1.0 / 60, g).ok()) << ctx << ": a faulted cloth steps again";
  }
}

TEST(Emitter, EmitReportsBadStepsAndCountsThatOverflow) {
  EmitterDef def;
  def.rate = 1e9;  // the largest rate: 1e10 particles in 10 s would overflow the count
  Emitter e = testing::Made(Emitter::Create(def));
  ParticleState s;
  ExpectError(e.Emit(s, 10), {"Emitter.Emit", "1e+10"}, "rate 1e9 for 10 s");
  ExpectError(e.Emit(s, kInf), {"Emitter.Emit h", "inf"}, "h inf");
  ExpectError(e.Emit(s, kNaN), {"Emitter.Emit h", "nan"}, "h nan");
  ExpectError(e.Emit(s, -1), {"Emitter.Emit h", "-1"}, "h -1");
  EXPECT_EQ(s.size(), 0u) << "a rejected Emit emitted";
  EXPECT_OK(e.Emit(s, 1e-6));
  EXPECT_EQ(s.size(), 1000u);
}

}  // namespace
}  // namespace sylva::particles
