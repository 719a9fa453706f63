// Determinism across thread counts, and faults reported rather than
// propagated.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "particles/flocking.h"
#include "particles/grid.h"
#include "particles/helpers.h"
#include "particles/kernels.h"
#include "particles/system.h"

namespace sylva::particles {
namespace {

// 9000 particles (three chunks) in a box with a sphere inside, under local
// forces, springs, a grid force and particle-particle collisions.
uint64_t Simulate(int threads, Integrator in, int steps) {
  System s(threads);
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 9000; ++i)
    s.state.Add(Vec3(u(rng), u(rng), u(rng)), Vec3(u(rng), u(rng), u(rng)), 1 + 0.1 * u(rng));
  s.AddForce(std::make_shared<Gravity>(Vec3(0, -9.81, 0)));
  s.AddForce(std::make_shared<Drag>(0.1, 0.02));
  auto springs = std::make_shared<Springs>();
  for (uint32_t i = 0; i + 1 < 2000; i += 2) EXPECT_OK(springs->Add(i, i + 1, 0.05, 50, 0.5));
  s.AddForce(springs);
  s.AddForce(std::make_shared<InverseSquare>(0.001, 0.1, 0.01));
  FlockingDef flock;
  flock.radius = 0.1;
  flock.separationRadius = 0.03;
  flock.cohesion = 0;  // no clumping: keeps neighbour counts small
  s.AddForce(testing::Made(Flocking::Create(flock)));
  EXPECT_OK(s.AddCollider(Collider::Box(Vec3(-1.2, -1.2, -1.2), Vec3(1.2, 1.2, 1.2), true)
                              .Restitution(0.7)
                              .Friction(0.3)));
  EXPECT_OK(s.AddCollider(Collider::Sphere(Vec3(0, -0.8, 0), 0.4).Restitution(0.5).Friction(0.2)));
  EXPECT_OK(s.EnableParticleCollisions(0.01, 0.8));
  for (int i = 0; i < steps; ++i) {
    if (Status st = s.Step(1.0 / 240, in); !st.ok()) {
      ADD_FAILURE() << st.error().message;
      return 0;
    }
  }
  return s.Hash();
}

TEST(Determinism, OneAndTwoThreadsAreBitIdentical) {
  for (Integrator in :
       {Integrator::kSymplecticEuler, Integrator::kRK4, Integrator::kImplicitEuler}) {
    const uint64_t one = Simulate(1, in, 24), two = Simulate(2, in, 24),
                   three = Simulate(3, in, 24);
    EXPECT_EQ(one, two) << "integrator " << int(in) << ": 1 thread " << std::hex << one
                        << ", 2 threads " << two;
    EXPECT_EQ(one, three) << "integrator " << int(in) << ": 1 thread " << std::hex << one
                          << ", 3 threads " << three;
    EXPECT_NE(one, Simulate(1, in, 25)) << "the hash must see one more step";
  }
}

TEST(Faults, NonFiniteForceIsReportedWithStepAndId) {
  System s;
  for (int i = 0; i < 10; ++i) s.state.Add(Vec3(i, 0, 0), Vec3::Zero());
  s.AddForce(std::make_shared<ForceFunction>(
      [](const ParticleState& st, const Vec3*, const Vec3*, Vec3* f) {
        if (st.step == 3) f[7] = Vec3(std::nan(""), 0, 0);
      }));
  for (int i = 0; i < 3; ++i)
    ASSERT_TRUE(s.Step(0.01, Integrator::kSymplecticEuler).ok()) << "step " << i;
  Status st = s.Step(0.01, Integrator::kSymplecticEuler);
  ASSERT_FALSE(st.ok()) << "a NaN force must not pass silently";
  const std::string& m = st.error().message;
  EXPECT_NE(m.find("step 3"), std::string::npos) << m;
  EXPECT_NE(m.find("particle id 7"), std::string::npos) << m;
  EXPECT_NE(m.find("not finite"), std::string::npos) << m;
  EXPECT_EQ(st.error().kind, ErrorKind::kRuntime);
  Status again = s.Step(0.01, Integrator::kSymplecticEuler);
  EXPECT_FALSE(again.ok()) << "a faulted system must refuse to step";
  EXPECT_EQ(s.steps, 4u) << "no step after the fault";
}

TEST(Faults, ExplodingStiffSpringIsReported) {
  // Explicit Euler on a stiff spring gains energy every step until it blows up.
  System s;
  testing::AddAnchoredSpring(s, 1.5, 1, 1e4);
  Status st;
  int i = 0;
  for (; i < 100000 && st.ok(); ++i) st = s.Step(0.05, Integrator::kExplicitEuler);
  ASSERT_FALSE(st.ok()) << "no explosion reported after " << i
                        << " steps, x = " << s.state.position[1].x();
  EXPECT_NE(st.error().message.find("particle id 1"), std::string::npos) << st.error().message;
  EXPECT_NE(st.error().message.find("exploded"), std::string::npos) << st.error().message;
}

TEST(Faults, ImplicitEulerIsStableWhereExplicitExplodes) {
  System s;
  testing::AddAnchoredSpring(s, 1.5, 1, 1e4);
  for (int i = 0; i < 1000; ++i)
    ASSERT_TRUE(s.Step(0.05, Integrator::kImplicitEuler).ok()) << "step " << i;
  // Backward Euler damps: the spring settles at its rest length.
  EXPECT_NEAR(s.state.position[1].x(), 1.0, 1e-6) << "x " << s.state.position[1].x();
  EXPECT_LT(s.lastSolve().residual, 1e-9) << "CG residual " << s.lastSolve().residual;
}

}  // namespace
}  // namespace sylva::particles

namespace sylva::particles {
namespace {

// A hub tied to 100 rim particles (more springs on one particle than the 64
// colours, so the serial group is used) and a ring around the rim.
struct HubNetwork {
  ParticleState state;
  std::shared_ptr<Springs> springs = std::make_shared<Springs>();
  HubNetwork() {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1, 1);
    state.Add(Vec3::Zero(), Vec3::Zero());
    for (int i = 0; i < 100; ++i)
      state.Add(Vec3(u(rng), u(rng), u(rng)), Vec3(u(rng), u(rng), u(rng)));
    for (uint32_t i = 1; i <= 100; ++i) {
      EXPECT_OK(springs->Add(0, i, 0.5, 10 + i, 0.1 * i));
      EXPECT_OK(springs->Add(i, i % 100 + 1, 0.2, 30, 0.3));
    }
  }
  std::vector<Vec3> Forces(ThreadPool* pool) {
    springs->set_pool(pool);
    std::vector<Vec3> f(state.size(), Vec3::Zero());
    springs->Accumulate(state, state.position.data(), state.velocity.data(), f.data());
    return f;
  }
};

TEST(Springs, ColouredPassesEqualTheSerialSumAndIgnoreTheThreadCount) {
  HubNetwork net;
  ThreadPool pool(2);
  const std::vector<Vec3> one = net.Forces(nullptr), two = net.Forces(&pool);
  EXPECT_GT(net.springs->colourCount(), 2u);
  const Vec3* x = net.state.position.data();
  const Vec3* v = net.state.velocity.data();
  std::vector<Vec3> ref(net.state.size(), Vec3::Zero());
  for (const auto& sp : net.springs->springs()) {
    const Vec3 d = x[sp.a] - x[sp.b];
    const double len = d.norm();
    const Vec3 fa = -(sp.ks * (len - sp.rest) + sp.kd * (v[sp.a] - v[sp.b]).dot(d / len)) * d / len;
    ref[sp.a] += fa;
    ref[sp.b] -= fa;
  }
  for (size_t i = 0; i < ref.size(); ++i) {
    ASSERT_EQ(one[i], two[i]) << "particle " << i << ": 1 thread " << one[i].transpose()
                              << ", 2 threads " << two[i].transpose();
    ASSERT_LT((one[i] - ref[i]).norm(), 1e-12 * (1 + ref[i].norm()))
        << "particle " << i << ": coloured " << one[i].transpose() << ", serial "
        << ref[i].transpose();
  }
}

TEST(Springs, CachedJacobianProductEqualsTheDirectOne) {
  HubNetwork net;
  ThreadPool pool(2);
  net.springs->set_pool(&pool);
  const Vec3* x = net.state.position.data();
  const Vec3* v = net.state.velocity.data();
  std::vector<Vec3> p(net.state.size()), direct(net.state.size(), Vec3::Zero()), cached = direct;
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1, 1);
  for (Vec3& q : p) q = Vec3(u(rng), u(rng), u(rng));
  net.springs->AddJacobianProduct(net.state, x, v, -0.01, -0.1, p.data(), direct.data());
  net.springs->PrepareJacobian(net.state, x, v);
  net.springs->AddJacobianProduct(net.state, x, v, -0.01, -0.1, p.data(), cached.data());
  for (size_t i = 0; i < p.size(); ++i) {
    ASSERT_LT((cached[i] - direct[i]).norm(), 1e-12 * (1 + direct[i].norm()))
        << "particle " << i << ": cached " << cached[i].transpose() << ", direct "
        << direct[i].transpose();
  }
}

// The AVX spring product gives the scalar kernel's bits (kernels.h), on
// disjoint springs with a ragged tail and a degenerate (zero) direction.
TEST(Springs, AvxProductKernelMatchesTheScalarKernelBitForBit) {
  if (kernels::Best() != kernels::Kernel::kAvx) GTEST_SKIP() << "this processor has no AVX";
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u(-1, 1);
  const size_t m = 1003;
  std::vector<kernels::Point4> p(2 * m), y0(2 * m);
  for (size_t i = 0; i < 2 * m; ++i) {
    p[i] = {{u(rng), u(rng), u(rng), 0}};
    y0[i] = {{u(rng), u(rng), u(rng), 0}};
  }
  std::vector<kernels::SpringLinear> lin(m);
  for (size_t k = 0; k < m; ++k) {
    const Vec3 dir = k == 5 ? Vec3::Zero() : Vec3(u(rng), u(rng), u(rng)).normalized();
    lin[k] = {{dir.x(), dir.y(), dir.z(), 0},
              uint32_t(2 * k + 1),
              uint32_t(2 * k),
              10 * (1 + u(rng)),
              20 * (1 + u(rng)),
              0.5 * (1 + u(rng))};
  }
  std::vector<kernels::Point4> ys = y0, ya = y0;
  kernels::SpringProductRange(kernels::Kernel::kScalar, lin.data(), 0, m, -1e-4, -1e-2, p.data(),
                              ys.data());
  kernels::SpringProductRange(kernels::Kernel::kAvx, lin.data(), 0, m, -1e-4, -1e-2, p.data(),
                              ya.data());
  EXPECT_EQ(0, std::memcmp(ys.data(), ya.data(), ys.size() * sizeof(kernels::Point4)))
      << "y[1] scalar " << ys[1].p[0] << " avx " << ya[1].p[0];
  EXPECT_NE(0, std::memcmp(ys.data(), y0.data(), ys.size() * sizeof(kernels::Point4)))
      << "the product added nothing";
}

// The conjugate-gradient reductions: AVX and scalar kernels give the same
// bits (four interleaved sums either way), and the sums are right. Short
// arrays (a few terms a lane, ragged tails) so that any other order of
// operations would show in the last bits.
TEST(ImplicitEuler, AvxReductionKernelsMatchTheScalarKernelsBitForBit) {
  if (kernels::Best() != kernels::Kernel::kAvx) GTEST_SKIP() << "this processor has no AVX";
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 300; ++trial) {
    const size_t begin = trial % 2 ? 4 : 0, n = begin + 5 + size_t(trial) % 11;
    std::vector<double> p(n), q(n), z(n), dv0(n), r0(n);
    for (size_t i = 0; i < n; ++i) {
      p[i] = u(rng);
      q[i] = u(rng);
      z[i] = 1 + u(rng);
      dv0[i] = u(rng);
      r0[i] = u(rng);
    }
    const double ds = kernels::Dot(kernels::Kernel::kScalar, p.data(), q.data(), begin, n);
    const double da = kernels::Dot(kernels::Kernel::kAvx, p.data(), q.data(), begin, n);
    ASSERT_EQ(ds, da) << "trial " << trial << ": dot";
    double ref = 0;
    for (size_t i = begin; i < n; ++i) ref += p[i] * q[i];
    ASSERT_NEAR(ds, ref, 1e-14) << "trial " << trial << ": dot";
    std::vector<double> dvs = dv0, rs = r0, dva = dv0, ra = r0;
    const auto cs = kernels::CgStep(kernels::Kernel::kScalar, 0.3, p.data(), q.data(), z.data(),
                                    dvs.data(), rs.data(), begin, n);
    const auto ca = kernels::CgStep(kernels::Kernel::kAvx, 0.3, p.data(), q.data(), z.data(),
                                    dva.data(), ra.data(), begin, n);
    ASSERT_EQ(cs.rz, ca.rz) << "trial " << trial << ": r.z";
    ASSERT_EQ(cs.rr, ca.rr) << "trial " << trial << ": r.r";
    ASSERT_EQ(dvs, dva) << "trial " << trial;
    ASSERT_EQ(rs, ra) << "trial " << trial;
    double rz = 0;
    for (size_t i = begin; i < n; ++i) rz += (r0[i] - 0.3 * q[i]) * (r0[i] - 0.3 * q[i]) * z[i];
    ASSERT_NEAR(cs.rz, rz, 1e-14) << "trial " << trial;
    ASSERT_EQ(dvs[begin], dv0[begin] + 0.3 * p[begin]) << "trial " << trial;
  }
}

}  // namespace
}  // namespace sylva::particles
