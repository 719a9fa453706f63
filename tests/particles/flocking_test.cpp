#include "particles/flocking.h"

#include <gtest/gtest.h>

#include <random>

#include "particles/helpers.h"

namespace sylva::particles {
namespace {

ParticleState RandomFlock(int n, double spread, double speed, uint32_t seed) {
  ParticleState s;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < n; ++i) {
    Vec3 v(u(rng), u(rng), u(rng));
    s.Add(Vec3(u(rng), u(rng), u(rng)) * spread, v.normalized() * speed, 1);
  }
  return s;
}

TEST(Flocking, AlignmentAloneOrdersTheFlock) {
  System s;
  s.state = RandomFlock(400, 1.0, 1.0, 3);
  const double before = OrderParameter(s.state);
  FlockingDef def;
  def.radius = 1.0;
  def.cohesion = 0;
  def.separation = 0;
  def.alignment = 3;
  s.AddForce(testing::Made(Flocking::Create(def)));
  for (int i = 0; i < 600; ++i) ASSERT_TRUE(s.Step(1.0 / 120, Integrator::kSymplecticEuler).ok());
  const double after = OrderParameter(s.state);
  EXPECT_LT(before, 0.2) << "random start";
  EXPECT_GT(after, 0.9) << "order parameter " << before << " -> " << after;
}

double MinDistance(const ParticleState& s) {
  double best = 1e300;
  for (size_t i = 0; i < s.size(); ++i)
    for (size_t j = i + 1; j < s.size(); ++j)
      best = std::min(best, (s.position[i] - s.position[j]).squaredNorm());
  return std::sqrt(best);
}

// Particles packed in a small ball with cohesion pulling them together:
// with separation they keep their distance, without it they collapse.
double MinDistanceAfter(bool separation) {
  System s;
  s.state = RandomFlock(150, 0.6, 0.2, 5);
  FlockingDef def;
  def.radius = 2.0;
  def.cohesion = 4;
  def.alignment = 0;
  def.separation = separation ? 1.0 : 0;
  def.separationRadius = 0.15;
  s.AddForce(testing::Made(Flocking::Create(def)));
  s.AddForce(std::make_shared<Drag>(2.0));
  double worst = 1e300;
  for (int i = 0; i < 600; ++i) {
    if (Status st = s.Step(1.0 / 240, Integrator::kSymplecticEuler); !st.ok()) {
      ADD_FAILURE() << st.error().message;
      return 0;
    }
    if (i > 300) worst = std::min(worst, MinDistance(s.state));
  }
  return worst;
}

TEST(Flocking, SeparationAloneKeepsTheMinimumDistance) {
  const double with = MinDistanceAfter(true), without = MinDistanceAfter(false);
  EXPECT_GT(with, 0.05) << "minimum distance with separation " << with;
  RecordProperty("min_distance_with_separation", std::to_string(with));
  RecordProperty("min_distance_without_separation", std::to_string(without));
  EXPECT_LT(without, 0.02) << "minimum distance without separation " << without;
}

TEST(Flocking, SeekGoesToTheTarget) {
  System s;
  s.state = RandomFlock(50, 0.5, 0.0, 9);
  FlockingDef def;
  def.cohesion = def.separation = def.alignment = 0;
  def.seek = 4;
  def.target = Vec3(3, 1, 0);
  s.AddForce(testing::Made(Flocking::Create(def)));
  s.AddForce(std::make_shared<Drag>(4.0));  // critically damped: no overshoot
  for (int i = 0; i < 2400; ++i) ASSERT_TRUE(s.Step(1.0 / 240, Integrator::kSymplecticEuler).ok());
  for (const Vec3& p : s.state.position) EXPECT_LT((p - def.target).norm(), 1e-3) << p.transpose();
}

}  // namespace
}  // namespace sylva::particles
