#include "particles/emitter.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "particles/helpers.h"

namespace sylva::particles {
namespace {

TEST(Emitter, CountIsRateTimesTimeWithinOne) {
  for (double rate : {1.0, 37.0, 123.4, 999.9}) {
    EmitterDef def;
    def.rate = rate;
    def.lifetime = 1e9;
    Emitter e = testing::Made(Emitter::Create(def));
    ParticleState s;
    const double h = 1.0 / 60;
    const int steps = 150;  // 2.5 s
    for (int i = 0; i < steps; ++i) ASSERT_OK(e.Emit(s, h));
    EXPECT_NEAR(double(s.size()), rate * steps * h, 1.0)
        << "rate " << rate << ": emitted " << s.size();
  }
}

TEST(Emitter, EveryAgeStaysWithinItsLifetime) {
  EmitterDef def;
  def.rate = 500;
  def.lifetime = 0.5;
  def.lifetimeJitter = 0.3;
  def.velocitySpread = 2;
  Emitter e = testing::Made(Emitter::Create(def));
  System sys;
  size_t removed = 0;
  for (int i = 0; i < 240; ++i) {
    ASSERT_OK(e.Emit(sys.state, 1.0 / 120));
    ASSERT_TRUE(sys.Step(1.0 / 120, Integrator::kSymplecticEuler).ok());
    removed += RemoveDead(sys.state);
    for (size_t k = 0; k < sys.state.size(); ++k) {
      ASSERT_LT(sys.state.age[k], sys.state.lifetime[k]) << "particle " << sys.state.id[k];
      ASSERT_GE(sys.state.lifetime[k], 0.2 - 1e-12);
      ASSERT_LE(sys.state.lifetime[k], 0.8 + 1e-12);
    }
  }
  EXPECT_GT(removed, 500u) << "particles should die and be removed";
}

TEST(Emitter, ColourOverAgeIsExactAtBothEnds) {
  EmitterDef def;
  def.colorStart = Vec3f(1, 0.5f, 0);
  def.colorEnd = Vec3f(0.2f, 0.1f, 0.9f);
  Emitter e = testing::Made(Emitter::Create(def));
  EXPECT_EQ(e.ColorAt(0, 2), def.colorStart);
  EXPECT_EQ(e.ColorAt(2, 2), def.colorEnd);
  EXPECT_EQ(e.ColorAt(5, 2), def.colorEnd);  // clamped
  const Vec3f mid = e.ColorAt(1, 2);
  EXPECT_NEAR(mid.x(), 0.6f, 1e-6f);
  ParticleState s;
  e.Burst(s, 3);
  EXPECT_EQ(s.color[2], def.colorStart);
}

TEST(Emitter, RemovingTheDeadKeepsTheLivingInOrderWithTheirIds) {
  ParticleState s;
  for (int i = 0; i < 10; ++i) s.Add(Vec3(i, 0, 0), Vec3::Zero(), 1, i % 3 == 0 ? 0.5 : 10);
  for (double& a : s.age) a = 1;
  EXPECT_EQ(RemoveDead(s), 4u);
  ASSERT_EQ(s.size(), 6u);
  const uint32_t want[6] = {1, 2, 4, 5, 7, 8};
  for (size_t i = 0; i < 6; ++i) {
    EXPECT_EQ(s.id[i], want[i]);
    EXPECT_EQ(s.position[i].x(), double(want[i]));
  }
}

TEST(Emitter, SameSeedSameParticlesAndPositionsInTheirBall) {
  EmitterDef def;
  def.positionRadius = 0.5;
  def.position = Vec3(1, 2, 3);
  def.seed = 9;
  ParticleState a, b;
  testing::Made(Emitter::Create(def)).Burst(a, 200);
  testing::Made(Emitter::Create(def)).Burst(b, 200);
  for (size_t i = 0; i < 200; ++i) {
    EXPECT_EQ(a.position[i], b.position[i]);
    EXPECT_LE((a.position[i] - def.position).norm(), 0.5 + 1e-12);
  }
}

TEST(Emitter, AFastStreamIsEvenlySpacedAcrossSteps) {
  // 1000 particles/s at 100 m/s: one every 0.1 m. Births come 1/rate apart
  // in time, each moved on by its age, so the gaps are equal within and
  // across steps (born in one clump a step, they were 0 and 1.67 m).
  EmitterDef def;
  def.rate = 1000;
  def.velocity = Vec3(0, 100, 0);
  def.lifetime = 1e9;
  Emitter e = testing::Made(Emitter::Create(def));
  System sys;
  const double h = 1.0 / 60;
  for (int i = 0; i < 30; ++i) {
    ASSERT_OK(e.Emit(sys.state, h));
    STEP_OK(sys, h, Integrator::kSymplecticEuler);
  }
  ASSERT_EQ(sys.state.size(), 500u);
  std::vector<double> y;
  for (const Vec3& p : sys.state.position) y.push_back(p.y());
  std::sort(y.begin(), y.end());
  double worst = 0;
  for (size_t i = 1; i < y.size(); ++i) worst = std::max(worst, std::abs(y[i] - y[i - 1] - 0.1));
  EXPECT_LT(worst, 1e-9) << "gaps should all be 0.1 m; the worst is off by " << worst << " m";
  // Ages agree with the positions: age times speed is the distance travelled.
  for (size_t i = 0; i < sys.state.size(); ++i)
    ASSERT_NEAR(sys.state.age[i] * 100, sys.state.position[i].y(), 1e-9) << "particle " << i;
}

TEST(Emitter, EveryParticleIsDrawnIndependentlyAndTheSeedReproducesThem) {
  EmitterDef def;
  def.shape = EmitterShape::kBox;
  def.size = Vec3(1, 1, 1);
  def.velocitySpread = 1;
  Emitter one = testing::Made(Emitter::Create(def));
  ParticleState a, b;  // two fresh states: ids start at 0 in both
  one.Burst(a, 50);
  one.Burst(b, 50);
  int same = 0;
  for (size_t i = 0; i < 50; ++i) same += a.position[i] == b.position[i];
  EXPECT_EQ(same, 0) << "one emitter into two fresh states repeated " << same << " of 50";
  // Another emitter of another stream differs; one of the same definition
  // reproduces the first.
  EmitterDef other = def;
  other.stream = 1;
  ParticleState c, d;
  testing::Made(Emitter::Create(other)).Burst(c, 50);
  testing::Made(Emitter::Create(def)).Burst(d, 50);
  same = 0;
  for (size_t i = 0; i < 50; ++i) same += a.position[i] == c.position[i];
  EXPECT_EQ(same, 0) << "two streams repeated " << same << " of 50";
  for (size_t i = 0; i < 50; ++i) {
    EXPECT_EQ(a.position[i], d.position[i]) << "particle " << i;
    EXPECT_EQ(a.velocity[i], d.velocity[i]) << "particle " << i;
  }
  // Within one state the particles differ too.
  EXPECT_NE(a.position[0], a.position[1]);
}

// Mean and variance of each axis of n births of `def`.
struct Moments {
  Vec3 mean = Vec3::Zero(), var = Vec3::Zero();
};
Moments Sample(const EmitterDef& def, int n, ParticleState* out = nullptr) {
  ParticleState s;
  testing::Made(Emitter::Create(def)).Burst(s, uint64_t(n));
  Moments m;
  for (const Vec3& p : s.position) m.mean += p / n;
  for (const Vec3& p : s.position) m.var += (p - m.mean).cwiseAbs2() / n;
  if (out) *out = std::move(s);
  return m;
}

TEST(Emitter, ShapesAreUniformInTheirVolumes) {
  const int n = 40000;  // standard error of a mean about 0.5% of the spread
  EmitterDef def;
  def.position = Vec3(1, 2, 3);
  def.size = Vec3(2, 4, 6);
  // Box: each axis uniform over its edge, variance L^2 / 12.
  def.shape = EmitterShape::kBox;
  ParticleState s;
  Moments m = Sample(def, n, &s);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(m.mean[k], def.position[k], 0.02 * def.size[k]) << "box mean axis " << k;
    EXPECT_NEAR(m.var[k], def.size[k] * def.size[k] / 12, 0.03 * def.size[k] * def.size[k] / 12)
        << "box variance axis " << k;
  }
  for (const Vec3& p : s.position)
    ASSERT_TRUE(((p - def.position).cwiseAbs().array() <= 0.5 * def.size.array()).all());
  // Ellipsoid of semi-axes a: variance a^2 / 5 on each axis.
  def.shape = EmitterShape::kSphere;
  m = Sample(def, n, &s);
  for (int k = 0; k < 3; ++k) {
    const double a = def.size[k] / 2;
    EXPECT_NEAR(m.mean[k], def.position[k], 0.02 * a) << "sphere mean axis " << k;
    EXPECT_NEAR(m.var[k], a * a / 5, 0.03 * a * a / 5) << "sphere variance axis " << k;
  }
  for (const Vec3& p : s.position)
    ASSERT_LE((p - def.position).cwiseQuotient(def.size / 2).norm(), 1 + 1e-12);
  // Disc (XZ) of radius R: y fixed, x and z variance R^2 / 4.
  def.shape = EmitterShape::kDisc;
  m = Sample(def, n, &s);
  const double r = def.size.x() / 2;
  EXPECT_NEAR(m.var.x(), r * r / 4, 0.03 * r * r / 4);
  EXPECT_NEAR(m.var.z(), r * r / 4, 0.03 * r * r / 4);
  for (const Vec3& p : s.position) {
    ASSERT_EQ(p.y(), 2) << "the disc is flat";
    ASSERT_LE(Vec3(p.x() - 1, 0, p.z() - 3).norm(), r + 1e-12);
  }
}

TEST(Emitter, MeshSurfaceIsUniformByArea) {
  // Two triangles of areas 1 and 3 in the plane z = 0 (a 1 x 2 and a 3 x 2
  // right triangle): a quarter of the births on the first.
  auto mesh = std::make_shared<EmitterMesh>();
  mesh->positions = {Vec3(0, 0, 0),  Vec3(1, 0, 0),  Vec3(0, 2, 0),
                     Vec3(10, 0, 0), Vec3(13, 0, 0), Vec3(10, 2, 0)};
  mesh->triangles = {{0, 1, 2}, {3, 4, 5}};
  EmitterDef def;
  def.shape = EmitterShape::kMesh;
  def.mesh = mesh;
  const int n = 40000;
  ParticleState s;
  Sample(def, n, &s);
  int onFirst = 0;
  Vec3 meanSecond = Vec3::Zero();
  for (const Vec3& p : s.position) {
    ASSERT_EQ(p.z(), 0) << "on the surface";
    if (p.x() < 5) {
      ++onFirst;
      ASSERT_LE(p.x() + p.y() / 2, 1 + 1e-12) << "inside the first triangle";
    } else {
      meanSecond += p;
      ASSERT_LE((p.x() - 10) / 3 + p.y() / 2, 1 + 1e-12) << "inside the second triangle";
    }
  }
  const double fraction = double(onFirst) / n;  // standard error 0.0022
  EXPECT_NEAR(fraction, 0.25, 0.01) << "the first triangle has a quarter of the area";
  // A uniform point of a triangle has the centroid as its mean.
  meanSecond /= double(n - onFirst);
  EXPECT_NEAR(meanSecond.x(), 11, 0.02) << "centroid x of the second triangle";
  EXPECT_NEAR(meanSecond.y(), 2.0 / 3, 0.01) << "centroid y of the second triangle";
}

TEST(Emitter, EveryTriangleGetsItsShareOfTheArea) {
  // 64 triangles of areas 1, 2, ..., 64 (base i + 1, height 2), 100 m
  // apart: each gets (i + 1) / 2080 of the births, within 5 standard errors.
  auto mesh = std::make_shared<EmitterMesh>();
  for (uint32_t i = 0; i < 64; ++i) {
    const double x = 100.0 * i;
    mesh->positions.insert(mesh->positions.end(),
                           {Vec3(x, 0, 0), Vec3(x + i + 1, 0, 0), Vec3(x, 2, 0)});
    mesh->triangles.push_back({3 * i, 3 * i + 1, 3 * i + 2});
  }
  EmitterDef def;
  def.shape = EmitterShape::kMesh;
  def.mesh = mesh;
  const int n = 200000;
  ParticleState s;
  testing::Made(Emitter::Create(def)).Burst(s, n);
  std::vector<int> count(64, 0);
  for (const Vec3& p : s.position) ++count[size_t(std::floor(p.x() / 100))];
  double worst = 0;  // in standard errors
  for (int i = 0; i < 64; ++i) {
    const double want = (i + 1) / 2080.0, got = double(count[size_t(i)]) / n;
    worst = std::max(worst, std::abs(got - want) / std::sqrt(want * (1 - want) / n));
  }
  EXPECT_LT(worst, 5) << "the worst triangle's share is off by " << worst << " standard errors";
}

TEST(Emitter, VelocitiesStayInTheirCone) {
  EmitterDef def;
  def.velocity = Vec3(0, 0, 5);
  def.spreadDegrees = 30;
  ParticleState s;
  testing::Made(Emitter::Create(def)).Burst(s, 5000);
  double minCos = 1, meanCos = 0;
  for (const Vec3& v : s.velocity) {
    ASSERT_NEAR(v.norm(), 5, 1e-12);
    minCos = std::min(minCos, v.z() / 5);
    meanCos += v.z() / 5 / 5000;
  }
  EXPECT_GE(minCos, std::cos(30 * kDegToRad) - 1e-12);
  // Uniform over the cap: the mean cosine is (1 + cos 30) / 2 = 0.933.
  EXPECT_NEAR(meanCos, (1 + std::cos(30 * kDegToRad)) / 2, 0.002);
}

TEST(Emitter, LimitsCapTheLivingAndTheBirths) {
  EmitterDef def;
  def.rate = 1000;
  def.lifetime = 1e9;
  def.maxAlive = 120;
  Emitter e = testing::Made(Emitter::Create(def));
  ParticleState s;
  for (int i = 0; i < 20; ++i) ASSERT_OK(e.Emit(s, 0.01));  // 200 due
  EXPECT_EQ(s.size(), 120u);
  EXPECT_EQ(e.dropped(), 80u);
  EXPECT_EQ(e.Burst(s, 10), 0u) << "full";
  def.maxAlive = std::numeric_limits<uint64_t>::max();
  def.maxBirths = 50;
  Emitter f = testing::Made(Emitter::Create(def));
  ParticleState t;
  EXPECT_EQ(f.Burst(t, 30), 30u);
  ASSERT_OK(f.Emit(t, 0.1));  // 100 due, 20 left
  EXPECT_EQ(t.size(), 50u);
  EXPECT_EQ(f.dropped(), 80u);
}

TEST(Emitter, TheMoveIntoTheStepDoesNotCrossACollider) {
  // Born 0.5 m over a floor at 100 m/s downward: the advance of up to
  // 1.67 m would pass through it, so those particles start at the emitter.
  EmitterDef def;
  def.rate = 600;
  def.position = Vec3(0, 0.5, 0);
  def.velocity = Vec3(0, -100, 0);
  def.radiusStart = 0.01f;
  Emitter e = testing::Made(Emitter::Create(def));
  ParticleState s;
  const Collider floor = Collider::Plane(Vec3::Zero(), Vec3::UnitY());
  ASSERT_OK(e.Emit(s, 1.0 / 60, std::span<const Collider>(&floor, 1)));
  ASSERT_EQ(s.size(), 10u);
  int atEmitter = 0;
  for (const Vec3& p : s.position) {
    EXPECT_GE(p.y(), 0.01) << "a particle was born below the floor";
    atEmitter += p.y() == 0.5;
  }
  EXPECT_GT(atEmitter, 0);
}

}  // namespace
}  // namespace sylva::particles
