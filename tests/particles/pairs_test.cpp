// Particle-particle contacts (pairs.cpp): swept, stable in a pile, the same
// on any thread count.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "helpers.h"
#include "particles/kernels.h"
#include "particles/system.h"

namespace sylva::particles {
namespace {

// Two balls of radius 0.05 meet head on at 10, 20 and 40 m/s each (a
// relative step at 60 Hz of 0.33 to 1.3 m, many times their size): they
// bounce (e = 1: velocities swapped) and never pass through each other.
TEST(PairContacts, FastBallsDoNotPassThroughEachOther) {
  for (double speed : {10.0, 20.0, 40.0}) {
    System s(1);
    s.state.Add(Vec3(-1, 0, 0), Vec3(speed, 0, 0));
    s.state.Add(Vec3(1, 0.03, 0), Vec3(-speed, 0, 0));
    for (int i = 0; i < 2; ++i) s.state.radius[size_t(i)] = 0.05f;
    ASSERT_OK(s.EnableParticleCollisions(0.05, 1.0));
    double closest = HUGE_VAL;
    for (int k = 0; k < 30; ++k) {
      STEP_OK(s, 1.0 / 60, Integrator::kSymplecticEuler);
      const Vec3 d = s.state.position[1] - s.state.position[0];
      closest = std::min(closest, d.norm());
      ASSERT_GT(d.x(), 0) << speed << " m/s: the balls passed through each other at step " << k;
    }
    EXPECT_GE(closest, 0.1 - 1e-9) << speed << " m/s: centres came " << closest << " m apart";
    EXPECT_LT(s.state.velocity[0].x(), 0) << speed << " m/s: ball 0 did not bounce back";
    EXPECT_GT(s.state.velocity[1].x(), 0) << speed << " m/s: ball 1 did not bounce back";
  }
}

// The pile: 2,880 balls (radius 0.05 m, restitution 0.3) dropped into a
// box 1.2 m wide in a loose 12 x 20 x 12 lattice, added to s.
void AddPile(System& s) {
  s.AddForce(std::make_shared<Gravity>(Vec3(0, -9.81, 0)));
  EXPECT_OK(s.AddCollider(
      Collider::Box(Vec3(-0.6, 0, -0.6), Vec3(0.6, 10, 0.6), true).Restitution(0.3).Friction(0.5)));
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> jitter(-0.005, 0.005);
  for (int y = 0; y < 20; ++y)
    for (int z = 0; z < 12; ++z)
      for (int x = 0; x < 12; ++x) {
        s.state.Add(
            Vec3(-0.55 + 0.1 * x + jitter(rng), 0.1 + 0.11 * y, -0.55 + 0.1 * z + jitter(rng)),
            Vec3::Zero());
        s.state.radius.back() = 0.05f;
      }
  EXPECT_OK(s.EnableParticleCollisions(0.05, 0.3));
}

// The pile at 60 Hz: after 5 s it rests (every speed under 0.05 m/s) and
// no centre is closer to the floor than its radius, at any step.
uint64_t Pile(int threads, double* maxSpeed, double* lowest, double* drift = nullptr) {
  System s(threads);
  AddPile(s);
  *lowest = HUGE_VAL;
  std::vector<Vec3> before;
  for (int k = 0; k < 300; ++k) {
    if (k == 240) before = s.state.position;  // 4 s
    if (Status st = s.Step(1.0 / 60, Integrator::kSymplecticEuler); !st.ok()) {
      ADD_FAILURE() << st.error().message;
      return 0;
    }
    for (const Vec3& p : s.state.position) *lowest = std::min(*lowest, p.y());
  }
  *maxSpeed = 0;
  for (const Vec3& v : s.state.velocity) *maxSpeed = std::max(*maxSpeed, v.norm());
  // The largest mean speed over the last second, from the positions.
  if (drift) {
    *drift = 0;
    for (size_t i = 0; i < before.size(); ++i)
      *drift = std::max(*drift, (s.state.position[i] - before[i]).norm());
  }
  return s.Hash();
}

TEST(PairContacts, APileOf2880BallsStaysAboveTheFloorTheSameOnAnyThreadCount) {
  double speed, lowest;
  const uint64_t one = Pile(1, &speed, &lowest);
  EXPECT_GE(lowest, 0.05 - 1e-9) << "a centre came down to y = " << lowest
                                 << " (radius 0.05 above the floor)";
  double speed2, lowest2;
  const uint64_t two = Pile(2, &speed2, &lowest2);
  EXPECT_EQ(one, two) << "1 thread " << std::hex << one << ", 2 threads " << two;
}

// The support sweeps run as a pipeline over the pool's threads (pairs.cpp):
// 2,880 balls falling into a pile for 1.5 s, the sweep on in the steps
// where they land, give the same bits on 1, 3 and 4 threads (four sweeps
// at once on 4).
TEST(PairContacts, PipelinedSweepsGiveTheSameBitsOnOneThreeAndFourThreads) {
  auto run = [](int threads) {
    System s(threads);
    AddPile(s);
    for (int k = 0; k < 90; ++k) EXPECT_OK(s.Step(1.0 / 60, Integrator::kSymplecticEuler));
    return s.Hash();
  };
  const uint64_t one = run(1), three = run(3), four = run(4);
  EXPECT_EQ(one, three) << "1 thread " << std::hex << one << ", 3 threads " << three;
  EXPECT_EQ(one, four) << "1 thread " << std::hex << one << ", 4 threads " << four;
}

// Issue 17's target: after 5 s every ball's velocity is under 0.05 m/s (a
// ball in resting contact that moves at less than 0.9 of what its forces
// gave it in a step is at rest: kRestFraction, pairs.cpp), and the
// positions agree: no ball moved more than 0.05 m over the last second (a
// mean speed under 0.05 m/s), so the pile is still, not only its
// velocities zeroed.
TEST(PairContacts, APileOf2880BallsComesToRest) {
  double speed, lowest, drift;
  Pile(1, &speed, &lowest, &drift);
  EXPECT_LT(speed, 0.05) << "the fastest ball still moves at " << speed << " m/s after 5 s";
  EXPECT_LT(drift, 0.05) << "a ball moved " << drift << " m between 4 s and 5 s";
  EXPECT_GE(lowest, 0.05 - 1e-9) << "a centre came down to y = " << lowest;
}

// A pile 20 balls deep (720 balls of radius 0.05 m dropped in a loose 6 x
// 20 x 6 lattice into a box 0.64 m wide, restitution 0.3, 60 Hz) stands on
// its floor after 3 s: no two balls overlap by more than 15 % of a radius
// and its mean centre is at least 0.8 m high (0.93 m at a packing of 0.64).
// Measured 7.8 % and 0.86 m. The Jacobi passes alone could not hold it up
// (each carries a correction one contact further): 20 layers pressed into
// one another, 200 % (coincident centres) and 0.18 m before the support
// sweep (pairs.cpp).
TEST(PairContacts, ADeepPileHoldsItsBallsApart) {
  System s(1);
  s.AddForce(std::make_shared<Gravity>(Vec3(0, -9.81, 0)));
  ASSERT_OK(s.AddCollider(
      Collider::Box(Vec3(-0.32, 0, -0.32), Vec3(0.32, 10, 0.32), true).Restitution(0.3)));
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> jitter(-0.005, 0.005);
  for (int y = 0; y < 20; ++y)
    for (int z = 0; z < 6; ++z)
      for (int x = 0; x < 6; ++x) {
        s.state.Add(
            Vec3(-0.25 + 0.1 * x + jitter(rng), 0.06 + 0.11 * y, -0.25 + 0.1 * z + jitter(rng)),
            Vec3::Zero());
        s.state.radius.back() = 0.05f;
      }
  ASSERT_OK(s.EnableParticleCollisions(0.05, 0.3));
  for (int k = 0; k < 180; ++k) STEP_OK(s, 1.0 / 60, Integrator::kSymplecticEuler);
  const auto& x = s.state.position;
  double deepest = 0, meanY = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    meanY += x[i].y() / double(x.size());
    for (size_t j = i + 1; j < x.size(); ++j)
      deepest = std::max(deepest, (0.1 - (x[i] - x[j]).norm()) / 0.05);
  }
  EXPECT_LT(deepest, 0.15) << "two balls overlap by " << 100 * deepest << " % of a radius";
  EXPECT_GT(meanY, 0.8) << "the pile's mean centre is at y = " << meanY << " m";
}

// The pair screen's vector path (kernels::ScreenCandidates, AVX-512) keeps
// the same points as the scalar loop, in the same order: ranges of every
// length 0..40 from every start 0..8 (ragged tails), points exactly at the
// reach, points with a NaN coordinate (never within); and it writes
// nothing past the to - from places its contract gives it (its full blocks
// store 8 lanes at once).
TEST(PairContacts, VectorScreenKeepsTheScalarScreensPoints) {
  if (kernels::ScreenLanes() != 8) GTEST_SKIP() << "no AVX-512 on this processor";
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  const double p[3] = {0.1, -0.2, 0.3};
  std::vector<double> x;
  for (int k = 0; k < 64; ++k) {
    if (k % 7 == 3) {  // at the reach 0.5: 0.25 exactly
      x.insert(x.end(), {p[0] + (k % 2 ? 0.5 : -0.5), p[1], p[2]});
    } else if (k % 11 == 5) {
      x.insert(x.end(), {p[0], std::nan(""), p[2]});
    } else {
      x.insert(x.end(), {u(rng), u(rng), u(rng)});
    }
  }
  int kept = 0;
  for (uint32_t from = 0; from <= 8; ++from) {
    for (uint32_t len = 0; len <= 40; ++len) {
      uint32_t a[64], b[64];
      std::fill(b, b + 64, 0xdeadbeefu);
      const uint32_t na = kernels::ScreenCandidates(kernels::Kernel::kScalar, x.data(), from,
                                                    from + len, p, 0.25, a);
      const uint32_t nb =
          kernels::ScreenCandidates(kernels::Kernel::kAvx, x.data(), from, from + len, p, 0.25, b);
      ASSERT_EQ(na, nb) << "points [" << from << ", " << from + len << "): " << na
                        << " kept by the scalar screen, " << nb << " by the vector one";
      for (uint32_t k = 0; k < na; ++k)
        ASSERT_EQ(a[k], b[k]) << "points [" << from << ", " << from + len << "), place " << k;
      for (uint32_t k = len; k < 64; ++k)
        ASSERT_EQ(b[k], 0xdeadbeefu) << "points [" << from << ", " << from + len
                                     << "): the vector screen wrote place " << k << " of out";
      kept += int(na);
    }
  }
  EXPECT_GT(kept, 1000) << "too few points within reach to compare";
}

// A falling pile stepped with the vector kernels and with their scalar
// twins (System::SetKernel) gives the same bits at every step.
TEST(PairContacts, VectorKernelsGiveTheScalarKernelsBits) {
  if (kernels::ScreenLanes() != 8) GTEST_SKIP() << "no AVX-512 on this processor";
  System avx(1), scalar(1);
  scalar.SetKernel(kernels::Kernel::kScalar);
  for (System* s : {&avx, &scalar}) {
    s->AddForce(std::make_shared<Gravity>(Vec3(0, -9.81, 0)));
    EXPECT_OK(s->AddCollider(Collider::Box(Vec3(-0.4, 0, -0.4), Vec3(0.4, 10, 0.4), true)
                                 .Restitution(0.3)
                                 .Friction(0.5)));
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> jitter(-0.005, 0.005);
    for (int k = 0; k < 600; ++k) {
      const int x = k % 8, z = (k / 8) % 8, y = k / 64;
      s->state.Add(
          Vec3(-0.35 + 0.1 * x + jitter(rng), 0.1 + 0.11 * y, -0.35 + 0.1 * z + jitter(rng)),
          Vec3(jitter(rng), 0, jitter(rng)));
      s->state.radius.back() = k % 5 == 0 ? 0.04f : 0.05f;
    }
    EXPECT_OK(s->EnableParticleCollisions(0.05, 0.3));
  }
  for (int k = 0; k < 120; ++k) {
    STEP_OK(avx, 1.0 / 60, Integrator::kSymplecticEuler);
    STEP_OK(scalar, 1.0 / 60, Integrator::kSymplecticEuler);
    ASSERT_EQ(avx.Hash(), scalar.Hash()) << "states differ after step " << k;
  }
}

// A step with no resting contact (a gas) runs its velocity passes until
// every collision meets its target speed, up to System::pairMaxPasses. The
// 2,000-ball gas of ParticleCollisions.GasConservesMomentumAndElasticEnergy
// needs more than 16 in some steps: with the limit at 16 those steps return
// a warning naming the step (the step is taken, the system steps on), and
// with the default limit none does.
TEST(PairContacts, AGasStepThatReachesThePassLimitIsReported) {
  auto gas = [](System& s) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1, 1);
    while (s.state.size() < 2000) {
      const Vec3 p(u(rng), u(rng), u(rng));
      bool apart = true;
      for (const Vec3& q : s.state.position) apart &= (p - q).norm() > 0.06;
      if (apart) s.state.Add(p, Vec3(u(rng), u(rng), u(rng)), 1 + 0.5 * u(rng));
    }
    EXPECT_OK(s.EnableParticleCollisions(0.03, 1.0));
  };
  System limited;
  gas(limited);
  limited.pairMaxPasses = 16;
  int warnings = 0, errors = 0;
  std::string first;
  for (int i = 0; i < 50; ++i) {
    Status st = limited.Step(0.005, Integrator::kSymplecticEuler);
    if (st.ok()) continue;
    if (st.error().severity != Severity::kWarning) {
      ++errors;
      ADD_FAILURE() << st.error().message;
      continue;
    }
    if (warnings++ == 0) {
      first = st.error().message;
      EXPECT_NE(first.find("in step " + std::to_string(i) + " "), std::string::npos) << first;
    }
  }
  EXPECT_GT(warnings, 0) << "no step of the gas reached 16 passes";
  EXPECT_EQ(errors, 0);
  EXPECT_EQ(limited.steps, 50u) << "every step is taken, warning or not";
  EXPECT_NE(first.find("did not converge in 16 velocity passes"), std::string::npos) << first;

  System full;
  gas(full);
  for (int i = 0; i < 50; ++i) {
    Status st = full.Step(0.005, Integrator::kSymplecticEuler);
    ASSERT_TRUE(st.ok()) << "step " << i << ": " << st.error().message;
  }

  System bad;
  gas(bad);
  bad.pairMaxPasses = 15;
  Status st = bad.Step(0.005, Integrator::kSymplecticEuler);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("System.pairMaxPasses 15"), std::string::npos)
      << st.error().message;
}

}  // namespace
}  // namespace sylva::particles
