// Contacts that hold: an elastic bounce keeps the energy of the integrator,
// any number of contacts a step (a closed box of panels, a narrow wedge),
// and a bound on them that is reported, never silently exceeded.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <string>

#include "particles/bulk.h"
#include "particles/helpers.h"
#include "particles/system.h"

namespace sylva::particles {
namespace {

constexpr double kG = 9.81;
constexpr double kPi = 3.14159265358979323846;

// The energy symplectic Euler conserves exactly in free flight under
// gravity (0, -g, 0), per unit mass: g y + (vy - g h / 2)^2 / 2, with vy the
// stored velocity (vy - g h / 2 is the velocity of the step's path at its
// start). Any change of it comes from the contacts alone; the textbook
// g y + vy^2 / 2 swings by g h |vy| within a step (7 % for a 1 m drop at
// 60 Hz) and would hide them.
double StepEnergy(double y, double vy, double h) {
  const double w = vy - 0.5 * h * kG;
  return kG * y + 0.5 * w * w;
}

// Drops a ball from `height` onto a floor of restitution 1 and returns the
// energy after `bounces` bounces over the energy before, stepping with
// `step` and reading the state with `y` and `vy`.
double EnergyKeptAfterBounces(double height, double h, int bounces,
                              const std::function<bool()>& step, const std::function<double()>& y,
                              const std::function<double()>& vy) {
  const double before = StepEnergy(y(), vy(), h);
  int seen = 0;
  double prev = vy();
  for (int i = 0; i < 100000 && seen < bounces; ++i) {
    if (!step()) return 0;
    if (prev < 0 && vy() > 0) ++seen;
    prev = vy();
  }
  EXPECT_EQ(seen, bounces) << "height " << height;
  return StepEnergy(y(), vy(), h) / before;
}

TEST(Contact, ElasticBounceKeepsTheEnergyAt60Hz) {
  const double h = 1.0 / 60;
  for (double height : {1.0, 2.345, 0.777, 5.0}) {
    System s;
    s.state.Add(Vec3(0, height, 0), Vec3(0.3, 0, 0), 1);
    s.AddForce(std::make_shared<Gravity>(Vec3(0, -kG, 0)));
    ASSERT_OK(s.AddCollider(Collider::Plane(Vec3::Zero(), Vec3(0, 1, 0)).Restitution(1)));
    const double kept = EnergyKeptAfterBounces(
        height, h, 10, [&] { return s.Step(h, Integrator::kSymplecticEuler).ok(); },
        [&] { return s.state.position[0].y(); }, [&] { return s.state.velocity[0].y(); });
    EXPECT_GE(kept, 0.999) << "System, dropped from " << height << " m: kept " << kept
                           << " of the energy after 10 bounces";
    EXPECT_LE(kept, 1.001) << "System, dropped from " << height << " m: gained energy";
  }
}

TEST(Bulk, ElasticBounceKeepsTheEnergyAt60Hz) {
  const double h = 1.0 / 60;
  for (double height : {1.0, 2.345, 0.777, 5.0}) {
    BulkSystem b;
    b.state.Add(Vec3(0, height, 0), Vec3(0.3, 0, 0));
    b.fields.gravity = Vec3(0, -kG, 0);
    ASSERT_OK(b.AddCollider(Collider::Plane(Vec3::Zero(), Vec3(0, 1, 0)).Restitution(1)));
    const double hf = double(float(h));  // the step the kernel takes
    const double kept = EnergyKeptAfterBounces(
        height, hf, 10, [&] { return b.Step(h).ok(); }, [&] { return double(b.state.py[0]); },
        [&] { return double(b.state.vy[0]); });
    EXPECT_GE(kept, 0.999) << "BulkSystem, dropped from " << height << " m: kept " << kept
                           << " of the energy after 10 bounces";
    EXPECT_LE(kept, 1.001) << "BulkSystem, dropped from " << height << " m: gained energy";
  }
}

// A closed cube [-0.5, 0.5]^3 of six square panels (Collider::Polygon): at
// 150 m/s a particle crosses it 2.5 times a step at 60 Hz, so most steps
// hold several contacts, and three at a corner.
constexpr double kHalf = 0.5;
std::vector<Collider> CubeOfPanels() {
  std::vector<Collider> faces;
  for (int axis = 0; axis < 3; ++axis) {
    for (double side : {-1.0, 1.0}) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      std::vector<Vec3> quad;
      for (auto [a, b] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
        Vec3 p;
        p[axis] = side * kHalf;
        p[u] = a * kHalf;
        p[v] = b * kHalf;
        quad.push_back(p);
      }
      faces.push_back(Collider::Polygon(quad).Restitution(1));
    }
  }
  return faces;
}

// 2,000 particles at 150 m/s in random directions from random points inside.
template <typename AddFn>
void AddFastParticles(AddFn add) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.99 * kHalf, 0.99 * kHalf);
  std::normal_distribution<double> n;
  for (int i = 0; i < 2000; ++i) {
    Vec3 d(n(rng), n(rng), n(rng));
    add(Vec3(u(rng), u(rng), u(rng)), 150 * d.normalized());
  }
}

int OutsideCube(const std::vector<Vec3>& xs) {
  int out = 0;
  for (const Vec3& x : xs) out += !((x.array().abs() <= kHalf).all());
  return out;
}

TEST(Contact, FastParticlesStayInsideAClosedCubeOfPanels) {
  System s;
  for (const Collider& c : CubeOfPanels()) ASSERT_OK(s.AddCollider(c));
  AddFastParticles([&](const Vec3& p, const Vec3& v) { s.state.Add(p, v, 1); });
  int worst = 0;
  for (int i = 0; i < 300; ++i) {
    STEP_OK(s, 1.0 / 60, Integrator::kSymplecticEuler);
    worst = std::max(worst, OutsideCube(s.state.position));
  }
  EXPECT_EQ(worst, 0) << "particles outside the cube after some step (of 2000)";
  EXPECT_NEAR(s.KineticEnergy(), 2000 * 0.5 * 150 * 150, 1e-6 * 2000 * 0.5 * 150 * 150)
      << "restitution 1 keeps every speed";
}

TEST(Bulk, FastParticlesStayInsideAClosedCubeOfPanels) {
  BulkSystem b;
  for (const Collider& c : CubeOfPanels()) ASSERT_OK(b.AddCollider(c));
  AddFastParticles([&](const Vec3& p, const Vec3& v) { b.state.Add(p, v); });
  int worst = 0;
  std::vector<Vec3> xs(b.state.size());
  for (int i = 0; i < 1200; ++i) {  // 20 s: rounding onto a panel happened after 55 steps
    ASSERT_OK(b.Step(1.0 / 60));
    for (size_t k = 0; k < xs.size(); ++k) xs[k] = b.state.position(k);
    worst = std::max(worst, OutsideCube(xs));
  }
  EXPECT_EQ(worst, 0) << "particles outside the cube after some step (of 2000)";
}

// A wedge of two planes through the z axis, opening upward, `degrees` wide.
std::array<Collider, 2> Wedge(double degrees, double restitution, double friction) {
  const double half = 0.5 * degrees * kPi / 180;
  return {Collider::Plane(Vec3::Zero(), Vec3(std::cos(half), std::sin(half), 0))
              .Restitution(restitution)
              .Friction(friction),
          Collider::Plane(Vec3::Zero(), Vec3(-std::cos(half), std::sin(half), 0))
              .Restitution(restitution)
              .Friction(friction)};
}

TEST(Contact, AParticlePushedIntoANarrowWedgeNeverEndsBehindAPlane) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  int cases = 0;
  for (double e : {0.0, 0.5, 1.0}) {
    for (double mu : {0.0, 0.3}) {
      for (int trial = 0; trial < 20; ++trial, ++cases) {
        const auto wedge = Wedge(20, e, mu);
        System s;
        for (const Collider& c : wedge) ASSERT_OK(s.AddCollider(c));
        // Inside the wedge, thrown down into it, pushed down by a strong field.
        const double y = 0.5 + 0.5 * std::abs(u(rng));
        s.state.Add(Vec3(0.1 * y * u(rng), y, 0), Vec3(10 * u(rng), -40 - 20 * std::abs(u(rng)), 0),
                    1);
        s.AddForce(std::make_shared<Gravity>(Vec3(0, -200, 0)));
        for (int i = 0; i < 120; ++i) {
          STEP_OK(s, 1.0 / 60, Integrator::kSymplecticEuler);
          const Vec3& x = s.state.position[0];
          for (const Collider& c : wedge) {
            ASSERT_GE(c.normal.dot(x), -1e-12)
                << "e " << e << ", mu " << mu << ", trial " << trial << ", step " << i
                << ": behind a plane at (" << x.x() << ", " << x.y() << ")";
          }
        }
      }
    }
  }
  EXPECT_EQ(cases, 120);
}

TEST(Contact, ContactsBeyondTheBoundAreReportedNotIgnored) {
  // A floor (y >= 0) and a ceiling below it (y <= -0.1) leave no room: each
  // contact puts the particle inside the other solid, without end.
  const std::array<Collider, 2> noRoom = {Collider::Plane(Vec3::Zero(), Vec3(0, 1, 0)),
                                          Collider::Plane(Vec3(0, -0.1, 0), Vec3(0, -1, 0))};
  System s;
  for (const Collider& c : noRoom) ASSERT_OK(s.AddCollider(c));
  s.state.AddPinned(Vec3(0, 1, 0));  // immovable: never collides
  s.state.Add(Vec3(0, 0.5, 0), Vec3(0, -1, 0), 1);
  const Status st = s.Step(1.0 / 60, Integrator::kSymplecticEuler);
  ASSERT_FALSE(st.ok()) << "the bound of " << kMaxContacts << " contacts was exceeded silently";
  EXPECT_NE(st.error().message.find("particle id 1"), std::string::npos) << st.error().message;
  EXPECT_NE(st.error().message.find("contacts"), std::string::npos) << st.error().message;
  EXPECT_FALSE(s.Step(1.0 / 60, Integrator::kSymplecticEuler).ok()) << "stepped again";
  BulkSystem b;
  for (const Collider& c : noRoom) ASSERT_OK(b.AddCollider(c));
  b.state.AddPinned(Vec3(0, 1, 0));
  b.state.Add(Vec3(0, 0.5, 0), Vec3(0, -1, 0));
  const Status bs = b.Step(1.0 / 60);
  ASSERT_FALSE(bs.ok()) << "BulkSystem: the bound was exceeded silently";
  EXPECT_NE(bs.error().message.find("particle id 1"), std::string::npos) << bs.error().message;
}

}  // namespace
}  // namespace sylva::particles
