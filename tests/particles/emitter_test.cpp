#include "particles/emitter.h"

#include <gtest/gtest.h>

#include <cmath>

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

}  // namespace
}  // namespace sylva::particles
