// Particles against closed forms and invariants, with the measured values in
// the failure messages.
#include "particles/system.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "particles/helpers.h"

namespace sylva::particles {
namespace {

// x'' = -x (unit mass on a zero-length spring to an immovable anchor):
// x(t) = cos t. Returns |x(T) - cos T| after integrating with step h.
double OscillatorError(Integrator in, double h, double T = 2.0) {
  System s;
  testing::AddAnchoredSpring(s, 1, 0, 1);
  const int steps = int(std::lround(T / h));
  for (int i = 0; i < steps; ++i) {
    if (Status st = s.Step(h, in); !st.ok()) {
      ADD_FAILURE() << st.error().message;
      return NAN;
    }
  }
  return std::abs(s.state.position[1].x() - std::cos(T));
}

TEST(Integrators, HalvingTheStepDividesTheErrorByTheOrder) {
  struct Case {
    Integrator in;
    const char* name;
    double ratio, lo, hi;
  } cases[] = {{Integrator::kExplicitEuler, "explicit Euler", 2, 1.8, 2.3},
               {Integrator::kSymplecticEuler, "symplectic Euler", 2, 1.8, 2.3},
               {Integrator::kMidpoint, "RK2", 4, 3.6, 4.5},
               {Integrator::kRK4, "RK4", 16, 14, 18}};
  for (const Case& c : cases) {
    const double h = c.in == Integrator::kRK4 ? 0.05 : 0.01;
    const double e1 = OscillatorError(c.in, h), e2 = OscillatorError(c.in, h / 2);
    const double r = e1 / e2;
    EXPECT_GT(r, c.lo) << c.name << ": error " << e1 << " -> " << e2 << ", ratio " << r
                       << " (want ~" << c.ratio << ")";
    EXPECT_LT(r, c.hi) << c.name << ": error " << e1 << " -> " << e2 << ", ratio " << r
                       << " (want ~" << c.ratio << ")";
  }
}

double Energy(const System& s, double ks) {
  const double x = (s.state.position[1] - s.state.position[0]).norm();
  return s.KineticEnergy() + 0.5 * ks * x * x;
}

TEST(Integrators, SymplecticEulerKeepsEnergyWhereExplicitEulerDiverges) {
  for (Integrator in : {Integrator::kSymplecticEuler, Integrator::kExplicitEuler}) {
    System s;
    s.state.AddPinned(Vec3(0, 0, 0));
    s.state.Add(Vec3(1, 0, 0), Vec3::Zero(), 1);
    auto springs = std::make_shared<Springs>();
    EXPECT_OK(springs->Add(1, 0, 0.0, 1.0, 0.0));
    s.AddForce(springs);
    const double e0 = Energy(s, 1);
    double worst = 0;
    for (int i = 0; i < 100000; ++i) {
      ASSERT_TRUE(s.Step(0.01, in).ok());
      worst = std::max(worst, std::abs(Energy(s, 1) / e0 - 1));
    }
    if (in == Integrator::kSymplecticEuler) {
      EXPECT_LT(worst, 0.05) << "symplectic Euler: worst |E/E0 - 1| = " << worst;
    } else {
      EXPECT_GT(Energy(s, 1) / e0, 2.0)
          << "explicit Euler should gain energy; E/E0 = " << Energy(s, 1) / e0;
    }
  }
}

TEST(Forces, LinearDragDecaysExponentially) {
  System s;
  s.state.Add(Vec3::Zero(), Vec3(3, 0, 0), 2.0);
  s.AddForce(std::make_shared<Drag>(0.8));  // v(t) = v0 exp(-k t / m)
  for (int i = 0; i < 1000; ++i) ASSERT_TRUE(s.Step(1e-3, Integrator::kRK4).ok());
  const double want = 3 * std::exp(-0.8 * 1.0 / 2.0);
  EXPECT_NEAR(s.state.velocity[0].x(), want, 1e-9 * want) << "v(1) = " << s.state.velocity[0].x();
}

TEST(Forces, DampedSpringOscillatesAtItsDampedFrequency) {
  // m x'' = -ks x - kd x': omega_d = sqrt(ks/m - (kd / 2m)^2).
  const double ks = 100, kd = 2, m = 1;
  System s;
  s.state.AddPinned(Vec3(0, 0, 0));
  s.state.Add(Vec3(1, 0, 0), Vec3::Zero(), m);
  auto springs = std::make_shared<Springs>();
  EXPECT_OK(springs->Add(1, 0, 0.0, ks, kd));
  s.AddForce(springs);
  std::vector<double> crossings;
  double prev = 1;
  const double h = 1e-4;
  for (int i = 0; i < 40000; ++i) {
    ASSERT_TRUE(s.Step(h, Integrator::kRK4).ok());
    const double x = s.state.position[1].x();
    if ((prev > 0) != (x > 0)) crossings.push_back(s.time - h * x / (x - prev));
    prev = x;
  }
  ASSERT_GE(crossings.size(), 6u);
  const double period = 2 * (crossings[5] - crossings[1]) / 4;
  const double want = 2 * kPi / std::sqrt(ks / m - (kd / (2 * m)) * (kd / (2 * m)));
  EXPECT_NEAR(period, want, 0.01 * want) << "period " << period << " want " << want;
}

TEST(Forces, SpringsConserveMomentum) {
  System s;
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 20; ++i)
    s.state.Add(Vec3(u(rng), u(rng), u(rng)), Vec3(u(rng), u(rng), u(rng)), 1 + u(rng) * 0.5);
  auto springs = std::make_shared<Springs>();
  for (uint32_t i = 0; i < 20; ++i) EXPECT_OK(springs->Add(i, (i * 7 + 3) % 20, 0.5, 50, 0.3));
  s.AddForce(springs);
  auto momentum = [&] {
    Vec3 p = Vec3::Zero();
    for (size_t i = 0; i < s.state.size(); ++i) p += s.state.mass[i] * s.state.velocity[i];
    return p;
  };
  const Vec3 p0 = momentum();
  for (int i = 0; i < 1000; ++i) ASSERT_TRUE(s.Step(1e-3, Integrator::kRK4).ok());
  EXPECT_LT((momentum() - p0).norm(), 1e-6) << "momentum drifted by " << (momentum() - p0).norm();
}

// Drops a ball from height 1 on the plane y = 0 and returns its apex heights.
std::vector<double> Apexes(double restitution, int bounces) {
  System s;
  s.state.Add(Vec3(0, 1, 0), Vec3::Zero(), 1);
  s.AddForce(std::make_shared<Gravity>(Vec3(0, -9.81, 0)));
  Plane floor;
  floor.restitution = restitution;
  EXPECT_OK(s.AddPlane(floor));
  std::vector<double> apex;
  double prevVy = 0;
  for (int i = 0; i < 2000000 && int(apex.size()) < bounces; ++i) {
    if (Status st = s.Step(1e-4, Integrator::kRK4); !st.ok()) {
      ADD_FAILURE() << st.error().message;
      return apex;
    }
    const double vy = s.state.velocity[0].y();
    if (prevVy > 0 && vy <= 0) apex.push_back(s.state.position[0].y() + vy * vy / (2 * 9.81));
    prevVy = vy;
  }
  return apex;
}

TEST(Collisions, ElasticBallReturnsToItsHeight) {
  auto apex = Apexes(1.0, 3);
  ASSERT_EQ(apex.size(), 3u);
  for (double a : apex) EXPECT_NEAR(a, 1.0, 1e-4) << "apex " << a;
}

TEST(Collisions, SuccessiveApexesShrinkByRestitutionSquared) {
  const double e = 0.7;
  auto apex = Apexes(e, 4);
  ASSERT_EQ(apex.size(), 4u);
  EXPECT_NEAR(apex[0], e * e, 2e-4) << "first apex " << apex[0];
  for (size_t k = 1; k < apex.size(); ++k) {
    EXPECT_NEAR(apex[k] / apex[k - 1], e * e, 2e-3)
        << "ratio " << apex[k] / apex[k - 1] << " at bounce " << k;
  }
}

TEST(Collisions, FastParticlesNeverPassThroughAWall) {
  // 10 units a step against the plane x = 0, back and forth between two walls.
  System s;
  s.state.Add(Vec3(5, 0, 0), Vec3(-1000, 0, 0), 1);
  Plane left{Vec3(0, 0, 0), Vec3(1, 0, 0), 1, 0};
  Plane right{Vec3(37, 0, 0), Vec3(-1, 0, 0), 1, 0};
  EXPECT_OK(s.AddPlane(left));
  EXPECT_OK(s.AddPlane(right));
  for (int i = 0; i < 10000; ++i) {
    ASSERT_TRUE(s.Step(0.01, Integrator::kSymplecticEuler).ok());
    const double x = s.state.position[0].x();
    ASSERT_GE(x, 0) << "step " << i;
    ASSERT_LE(x, 37) << "step " << i;
  }
  EXPECT_NEAR(std::abs(s.state.velocity[0].x()), 1000, 1e-9);
}

TEST(Collisions, FrictionKeepsTheNormalBounceAndSlowsTheTangent) {
  System s;
  s.state.Add(Vec3(0, 0.05, 0), Vec3(2, -1, 0), 1);
  EXPECT_OK(s.AddPlane(Plane{Vec3::Zero(), Vec3(0, 1, 0), 0.5, 0.25}));
  ASSERT_TRUE(s.Step(0.1, Integrator::kExplicitEuler).ok());
  // Coulomb: the normal impulse is (1 + e) * 1 = 1.5, so friction takes 0.25 * 1.5.
  EXPECT_NEAR(s.state.velocity[0].x(), 2 - 0.25 * 1.5, 1e-12);
  EXPECT_NEAR(s.state.velocity[0].y(), 0.5, 1e-12);
  EXPECT_GE(s.state.position[0].y(), 0);
}

TEST(State, ImmovableParticlesStayPut) {
  System s;
  s.state.Add(Vec3(1, 2, 3), Vec3(5, 5, 5));
  s.state.Pin(0);
  s.AddForce(std::make_shared<Gravity>(Vec3(0, -9.81, 0)));
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(s.Step(0.1, Integrator::kRK4).ok());
  EXPECT_EQ(s.state.position[0], Vec3(1, 2, 3));
  EXPECT_EQ(s.state.age[0], s.time);
}

}  // namespace
}  // namespace sylva::particles
