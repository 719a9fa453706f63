#include "particles/cloth.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "particles/xpbd.h"

#include "particles/helpers.h"

namespace sylva::particles {
namespace {

// A 2x2 "cloth": the top row pinned, the bottom row hanging on structural
// constraints only. With compliance alpha, the hanging particles settle at
// the extension of a spring of stiffness 1/alpha under their weight.
TEST(Cloth, HangingMassSettlesAtTheExtensionOfItsCompliance) {
  const double alpha = 1e-3, g = 9.81;
  const int settings[][2] = {{1, 20}, {5, 20}, {50, 20}, {5, 7}};  // iterations, substeps
  for (const auto& [iterations, substeps] : settings) {
    ClothDef def;
    def.columns = 2;
    def.rows = 2;
    def.u = Vec3(1, 0, 0);
    def.v = Vec3(0, -1, 0);
    def.mass = 4;  // 1 kg a particle
    def.stretchCompliance = alpha;
    def.shearCompliance = 1e9;  // effectively absent
    def.bendCompliance = 1e9;
    def.windDrag = 0;
    def.substeps = substeps;
    def.iterations = iterations;
    def.damping = 2.0;
    def.longRangeAttachments = false;  // tethers would cap the extension at rest
    def.pinned = {0, 1};
    auto clothOwner = testing::Made(Cloth::Create(def));
    Cloth& cloth = *clothOwner;
    for (int i = 0; i < 2000; ++i) ASSERT_OK(cloth.Step(1.0 / 60, Vec3(0, -g, 0)));
    // Each hanging particle carries its own weight on its vertical link; the
    // horizontal link between them is slack-free and carries nothing.
    const double extension = -cloth.positions()[2].y() - 1.0;
    const double want = 1.0 * g * alpha;
    EXPECT_NEAR(extension, want, 0.01 * want)
        << iterations << " iterations, " << substeps << " substeps: extension " << extension
        << ", want m g alpha = " << want;
  }
}

TEST(Cloth, UnpinnedClothInFreeFallDoesNotDeform) {
  ClothDef def;
  def.columns = 12;
  def.rows = 9;
  def.windDrag = 0;
  auto clothOwner = testing::Made(Cloth::Create(def));
  Cloth& cloth = *clothOwner;
  const std::vector<Vec3> start = cloth.positions();
  const double t = 1.0;
  for (int i = 0; i < 60; ++i) ASSERT_OK(cloth.Step(t / 60, Vec3(0, -9.81, 0)));
  double worst = 0;
  for (const auto& c : cloth.constraints())
    worst = std::max(worst,
                     std::abs((cloth.positions()[c.a] - cloth.positions()[c.b]).norm() - c.rest));
  EXPECT_LT(worst, 1e-9) << "largest change of a constraint length: " << worst;
  // And it falls as a rigid body: 1/2 g t^2 (symplectic substeps: within h g t).
  const double drop = start[0].y() - cloth.positions()[0].y();
  EXPECT_NEAR(drop, 0.5 * 9.81 * t * t, 9.81 * t * (t / 600) + 1e-9) << "drop " << drop;
}

TEST(Cloth, PinsDoNotMoveUnderGravityAndWind) {
  ClothDef def;
  def.columns = 10;
  def.rows = 8;
  def.pinned = {0, 9};
  auto clothOwner = testing::Made(Cloth::Create(def));
  Cloth& cloth = *clothOwner;
  const Vec3 a = cloth.positions()[0], b = cloth.positions()[9];
  for (int i = 0; i < 120; ++i) ASSERT_OK(cloth.Step(1.0 / 60, Vec3(0, -9.81, 0), Vec3(0, 0, 6)));
  EXPECT_EQ(cloth.positions()[0], a);
  EXPECT_EQ(cloth.positions()[9], b);
  // The wind pushed the free cloth along +z.
  EXPECT_GT(cloth.positions()[cloth.Index(5, 7)].z(), 0.05)
      << cloth.positions()[cloth.Index(5, 7)].transpose();
  EXPECT_EQ(cloth.triangles().size(), size_t(2 * 9 * 7));
}

TEST(ClothImplicit, HangingMassSettlesAtTheExtensionOfItsCompliance) {
  // Backward Euler's rest state is the exact static equilibrium f = 0.
  const double alpha = 1e-3, g = 9.81;
  ClothDef def;
  def.columns = 2;
  def.rows = 2;
  def.mass = 4;
  def.stretchCompliance = alpha;
  def.shearCompliance = 1e9;
  def.bendCompliance = 1e9;
  def.windDrag = 0;
  def.solver = ClothSolver::kImplicit;
  def.cgIterations = 50;
  def.pinned = {0, 1};
  auto clothOwner = testing::Made(Cloth::Create(def));
  Cloth& cloth = *clothOwner;
  for (int i = 0; i < 600; ++i) ASSERT_OK(cloth.Step(1.0 / 60, Vec3(0, -g, 0)));
  const double extension = -cloth.positions()[2].y() - 1.0;
  EXPECT_NEAR(extension, g * alpha, 0.001 * g * alpha) << "extension " << extension;
}

TEST(ClothImplicit, LargeStepsStayStableWithPinsFixed) {
  ClothDef def;
  def.columns = 40;
  def.rows = 40;
  def.solver = ClothSolver::kImplicit;
  def.pinned = {0, 39};
  auto clothOwner = testing::Made(Cloth::Create(def));
  Cloth& cloth = *clothOwner;
  const Vec3 pin0 = cloth.positions()[0], pin1 = cloth.positions()[39];
  for (int i = 0; i < 120; ++i) {
    ASSERT_OK(cloth.Step(1.0 / 30, Vec3(0, -9.81, 0), Vec3(0, 0, 1)));
    for (const Vec3& p : cloth.positions()) ASSERT_TRUE(p.allFinite()) << "frame " << i;
  }
  EXPECT_EQ(cloth.positions()[0], pin0);
  EXPECT_EQ(cloth.positions()[39], pin1);
  EXPECT_LT(cloth.MaxStretch(), 0.2) << "stretch " << cloth.MaxStretch();
  EXPECT_EQ(cloth.lastSolve().iterations, 20) << "the default CG budget";
  double lowest = 0;
  for (const Vec3& p : cloth.positions()) lowest = std::min(lowest, p.y());
  // It hangs: a 1 m cloth from its top corners reaches about 1 m down
  // (-0.949 with the default strain limiting, -0.95 or lower without).
  EXPECT_LT(lowest, -0.9) << "the cloth hangs";
}

// A k x k, 1 kg, 1 m cloth hanging from its top corners in a 2 m/s wind,
// 30 implicit steps of 1/10 s: the largest structural stretch after any
// step, and the most strain-limiter cycles a step took.
struct Peak {
  double stretch = 0;
  int cycles = 0;
};
Peak HangAtATenthOfASecond(int k, double strainLimit) {
  ClothDef def;
  def.columns = def.rows = k;
  def.solver = ClothSolver::kImplicit;
  def.pinned = {0, k - 1};
  def.implicitStrainLimit = strainLimit;
  auto cloth = testing::Made(Cloth::Create(def));
  Peak peak;
  for (int i = 0; i < 30; ++i) {
    EXPECT_OK(cloth->Step(0.1, Vec3(0, -9.81, 0), Vec3(0, 0, 2)));
    peak.stretch = std::max(peak.stretch, cloth->MaxStretch());
    peak.cycles = std::max(peak.cycles, cloth->lastStrainCycles());
  }
  return peak;
}

// Steps of 1/10 s: one linearised backward-Euler step is far from the
// nonlinear solution and the springs stretch (a 32 x 32 cloth falling from
// two corners peaks at 23 %, a 100 x 100 one at 880 %); strain limiting on
// coarser grids and then the cloth's own holds each to 10 %.
TEST(ClothImplicit, StrainLimitingHoldsTenPercentAtATenthOfASecond) {
  const Peak free = HangAtATenthOfASecond(32, 0);
  EXPECT_GT(free.stretch, 0.2) << "32 x 32 without strain limiting: peak " << free.stretch;
  EXPECT_EQ(free.cycles, 0);
  for (int k : {32, 64}) {
    const Peak held = HangAtATenthOfASecond(k, 0.1);
    EXPECT_LE(held.stretch, 0.1 + 1e-9) << k << " x " << k << ": peak stretch " << held.stretch
                                        << " (" << held.cycles << " cycles at most)";
    EXPECT_LT(held.cycles, ClothDef().implicitStrainIterations) << k << " x " << k;
  }
}

// The same for 100 x 100 (about 2.5 s of a Release build): before the
// coarse grids, Gauss-Seidel passes on the links alone let it peak at 33 %
// with 20 passes and 18 % with 1,000.
TEST(ClothImplicit, StrainLimitingHoldsTenPercentOnA100x100SheetAtATenthOfASecond) {
  const Peak held = HangAtATenthOfASecond(100, 0.1);
  EXPECT_LE(held.stretch, 0.1 + 1e-9)
      << "100 x 100: peak stretch " << held.stretch << " (" << held.cycles << " cycles at most)";
  EXPECT_LT(held.cycles, ClothDef().implicitStrainIterations);
}

// A ribbon two particles wide and 100 long, hanging from its top two:
// the coarse grids coarsen its rows alone.
TEST(ClothImplicit, StrainLimitingHoldsANarrowRibbonAtATenthOfASecond) {
  ClothDef def;
  def.columns = 2;
  def.rows = 100;
  def.u = Vec3(0.02, 0, 0);
  def.v = Vec3(0, -1, 0);
  def.mass = 0.04;
  def.solver = ClothSolver::kImplicit;
  def.pinned = {0, 1};
  auto cloth = testing::Made(Cloth::Create(def));
  double peak = 0;
  for (int i = 0; i < 30; ++i) {
    ASSERT_OK(cloth->Step(0.1, Vec3(0, -9.81, 0), Vec3(0, 0, 2)));
    peak = std::max(peak, cloth->MaxStretch());
  }
  EXPECT_LE(peak, 0.1 + 1e-9) << "2 x 100 ribbon: peak stretch " << peak;
}

// XPBD at the same frame step with 60 substeps of 1/600 s holds even the
// 100 x 100 cloth to 5 %.
TEST(Cloth, SixtySubstepsHoldA100x100SheetToFivePercentAtATenthOfASecond) {
  ClothDef def;
  def.columns = def.rows = 100;
  def.pinned = {0, 99};
  def.substeps = 60;
  auto cloth = testing::Made(Cloth::Create(def));
  double xpbd = 0;
  for (int i = 0; i < 30; ++i) {
    ASSERT_OK(cloth->Step(0.1, Vec3(0, -9.81, 0), Vec3(0, 0, 2)));
    xpbd = std::max(xpbd, cloth->MaxStretch());
  }
  EXPECT_LT(xpbd, 0.05) << "XPBD, 100 x 100, 60 substeps of 1/600 s: peak " << xpbd;
}

TEST(ClothImplicit, ConjugateGradientsConvergeWhenGivenTheIterations) {
  ClothDef def;
  def.columns = 30;
  def.rows = 30;
  def.solver = ClothSolver::kImplicit;
  def.pinned = {0, 29};
  def.cgIterations = 1000;
  auto clothOwner = testing::Made(Cloth::Create(def));
  Cloth& cloth = *clothOwner;
  ASSERT_OK(
      cloth.Step(1.0 / 30, Vec3(0, -9.81, 0)));  // the first frame has the largest right-hand side
  EXPECT_LT(cloth.lastSolve().residual, 1e-9)
      << "after " << cloth.lastSolve().iterations << " iterations";
  EXPECT_LT(cloth.lastSolve().iterations, 1000);
}

// The AVX projection kernel must give the scalar kernel's bits: the same
// operations in the same order, four constraints at a time. Random disjoint
// constraints (one colour), both iteration kinds, with and without stored
// multipliers, a degenerate constraint (coincident ends), a pinned end and a
// ragged tail.
TEST(Xpbd, AvxKernelMatchesTheScalarKernelBitForBit) {
  if (kernels::Best() != xpbd::Kernel::kAvx) GTEST_SKIP() << "this processor has no AVX";
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  const size_t m = 1003;
  std::vector<xpbd::Point4> x0(2 * m);
  for (xpbd::Point4& p : x0) p = {{u(rng), u(rng), u(rng), 0}};
  x0[11] = x0[10];  // constraint 5 has no direction
  std::vector<xpbd::Projection> ps(m);
  for (size_t k = 0; k < m; ++k) {
    const double wa = k == 17 ? 0 : 1 + 0.5 * u(rng), wb = 1 + 0.5 * u(rng),
                 alphaT = k % 3 ? 0 : 0.01 * (1 + u(rng));
    const double scale = 1 / (wa + wb + alphaT);
    ps[k] = {uint32_t(2 * k), uint32_t(2 * k + 1), 0.5 + 0.2 * u(rng),
             scale,           wa * scale,          wb * scale,
             alphaT};
  }
  std::vector<double> lambda0(m);
  for (double& l : lambda0) l = 0.1 * u(rng);
  for (bool first : {true, false}) {
    for (bool keep : {true, false}) {
      std::vector<xpbd::Point4> xs = x0, xa = x0;
      std::vector<double> ls = lambda0, la = lambda0;
      for (int pass = 0; pass < 3; ++pass) {
        xpbd::ProjectRange(xpbd::Kernel::kScalar, first, keep, ps.data(), ls.data(), xs.data(), 0,
                           m);
        xpbd::ProjectRange(xpbd::Kernel::kAvx, first, keep, ps.data(), la.data(), xa.data(), 0, m);
      }
      EXPECT_EQ(0, std::memcmp(xs.data(), xa.data(), xs.size() * sizeof(xpbd::Point4)))
          << "first " << first << " keep " << keep << ": x[0] scalar " << xs[0].p[0] << " avx "
          << xa[0].p[0];
      EXPECT_EQ(0, std::memcmp(ls.data(), la.data(), ls.size() * sizeof(double)))
          << "first " << first << " keep " << keep << ": lambda[0] scalar " << ls[0] << " avx "
          << la[0];
      // The projection did something: the pass moved the positions.
      EXPECT_NE(0, std::memcmp(xs.data(), x0.data(), xs.size() * sizeof(xpbd::Point4)));
      EXPECT_EQ(x0[34].p[0], xa[34].p[0]) << "the pinned end moved";
    }
  }
}

// The same for the per-particle pass: tethers (taut, slack and absent),
// velocities and the next prediction, four particles a lane; blocks with a
// pin go through the scalar code.
TEST(Xpbd, AvxParticlePassMatchesTheScalarPassBitForBit) {
  if (kernels::Best() != xpbd::Kernel::kAvx) GTEST_SKIP() << "this processor has no AVX";
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  const size_t n = 1001;
  auto random = [&] { return xpbd::Point4{{u(rng), u(rng), u(rng), 0}}; };
  std::vector<xpbd::Point4> x0(n), v0(n), prev0(n), fext(n);
  std::vector<double> w(n);
  std::vector<xpbd::Tether> tethers(n * xpbd::kTethers);
  for (size_t i = 0; i < n; ++i) {
    x0[i] = random();
    v0[i] = random();
    prev0[i] = random();
    fext[i] = random();
    w[i] = i % 97 == 3 ? 0 : 1 + 0.5 * u(rng);
  }
  for (size_t i = 0; i < n; ++i) {
    for (int t = 0; t < xpbd::kTethers; ++t) {
      const bool none = (i + size_t(t)) % 7 == 0;
      // Rest lengths around the current distances: about half are taut.
      tethers[i * xpbd::kTethers + size_t(t)] = {none ? UINT32_MAX : uint32_t(3 + 97 * t),
                                                 0.8 + 0.6 * (u(rng) + 1) / 2};
    }
  }
  int taut = 0;
  for (size_t i = 0; i < n; ++i) {
    const xpbd::Tether& th = tethers[i * xpbd::kTethers];
    if (th.pin == UINT32_MAX) continue;
    double d2 = 0;
    for (int k = 0; k < 3; ++k) d2 += std::pow(x0[i].p[k] - x0[th.pin].p[k], 2);
    taut += d2 > th.rest * th.rest;
  }
  EXPECT_GT(taut, 100) << "too few taut tethers to test the clamp";
  for (bool predictNext : {true, false}) {
    std::vector<xpbd::Point4> xs = x0, vs = v0, ps = prev0, xa = x0, va = v0, pa = prev0;
    const xpbd::Particles s{xs.data(),      vs.data(),         ps.data(), fext.data(), w.data(),
                            tethers.data(), {0.1, -9.81, 0.3}, 1e-3,      1e3,         0.999};
    xpbd::Particles a = s;
    a.x = xa.data();
    a.v = va.data();
    a.prev = pa.data();
    xpbd::FinishRange(xpbd::Kernel::kScalar, s, predictNext, 0, n);
    xpbd::FinishRange(xpbd::Kernel::kAvx, a, predictNext, 0, n);
    EXPECT_EQ(0, std::memcmp(xs.data(), xa.data(), n * sizeof(xpbd::Point4)))
        << "predictNext " << predictNext << ": x[1] scalar " << xs[1].p[0] << " avx " << xa[1].p[0];
    EXPECT_EQ(0, std::memcmp(vs.data(), va.data(), n * sizeof(xpbd::Point4)))
        << "predictNext " << predictNext << ": v[1] scalar " << vs[1].p[0] << " avx " << va[1].p[0];
    EXPECT_EQ(0, std::memcmp(ps.data(), pa.data(), n * sizeof(xpbd::Point4)))
        << "predictNext " << predictNext << ": prev[1] scalar " << ps[1].p[0] << " avx "
        << pa[1].p[0];
    EXPECT_EQ(0, std::memcmp(&x0[3], &xa[3], sizeof(xpbd::Point4))) << "a pin moved";
  }
}

TEST(Cloth, OneAndTwoThreadsAreBitIdentical) {
  for (ClothSolver solver : {ClothSolver::kXPBD, ClothSolver::kImplicit}) {
    auto run = [solver](int threads) {
      ClothDef def;
      def.columns = 64;
      def.rows = 64;
      def.substeps = 8;
      def.threads = threads;
      def.pinned = {0, 63};
      def.windLift = 0.6;
      def.windFriction = 0.1;
      def.solver = solver;
      auto clothOwner = testing::Made(Cloth::Create(def));
      Cloth& cloth = *clothOwner;
      for (int i = 0; i < 20; ++i)
        EXPECT_OK(cloth.Step(1.0 / 60, Vec3(0, -9.81, 0), Vec3(1, 0, 3)));
      return cloth.positions();
    };
    const auto one = run(1), two = run(2);
    size_t differ = 0;
    for (size_t i = 0; i < one.size(); ++i) differ += one[i] != two[i];
    EXPECT_EQ(differ, 0u) << "particles that differ between 1 and 2 threads, solver "
                          << (solver == ClothSolver::kXPBD ? "XPBD" : "implicit");
  }
}

// A flat 1 m^2 square (two triangles) at rest in the xy plane, its normal
// along z, in a wind of speed U at angle th to the normal. Internal
// constraints conserve momentum, so after one frame of length dt the
// cloth's momentum is dt times the air force, which has closed forms:
// drag c_d A U cos^2 th along the wind, lift c_l A U cos th sin th across it
// (toward the normal), friction c_f A U sin th along the cloth.
TEST(Cloth, WindDragLiftAndFrictionMatchTheirClosedForms) {
  const double U = 5, dt = 1.0 / 60;
  for (ClothSolver solver : {ClothSolver::kXPBD, ClothSolver::kImplicit}) {
    for (double deg : {0.0, 30.0, 60.0, 85.0}) {
      const double th = deg * M_PI / 180, c = std::cos(th), s = std::sin(th);
      const Vec3 along(s, 0, c);          // the wind's direction
      const Vec3 across(c, 0, -s);        // perpendicular to it, in the plane of n and the wind
      const Vec3 n(0, 0, 1), t(1, 0, 0);  // normal and the tangential direction of the wind
      struct Case {
        double cd, cl, cf;
        Vec3 want;
      };
      // Lift points toward the normal side: -across has a positive z.
      const Case cases[] = {
          {1, 0, 0, U * c * c * along},
          {0, 1, 0, -U * c * s * across},
          {0, 0, 1, U * s * t},
          {2, 2, 0, 2 * U * c * n},  // equal drag and lift: the flat-plate pressure
          {1.5, 0.4, 0.3, 1.5 * U * c * c * along - 0.4 * U * c * s * across + 0.3 * U * s * t},
      };
      for (const Case& k : cases) {
        ClothDef def;
        def.columns = 2;
        def.rows = 2;
        def.u = Vec3(1, 0, 0);
        def.v = Vec3(0, 1, 0);
        def.mass = 0.4;
        def.windDrag = k.cd;
        def.windLift = k.cl;
        def.windFriction = k.cf;
        def.solver = solver;
        def.substeps = 5;
        auto clothOwner = testing::Made(Cloth::Create(def));
        Cloth& cloth = *clothOwner;
        ASSERT_OK(cloth.Step(dt, Vec3::Zero(), U * along));
        Vec3 momentum = Vec3::Zero();
        for (const Vec3& v : cloth.velocities()) momentum += (def.mass / 4) * v;
        const Vec3 force = momentum / dt;
        EXPECT_LT((force - k.want).norm(), 1e-9 * (1 + k.want.norm()))
            << (solver == ClothSolver::kXPBD ? "XPBD" : "implicit") << ", th = " << deg
            << " deg, c_d " << k.cd << " c_l " << k.cl << " c_f " << k.cf << ": force "
            << force.transpose() << ", want " << k.want.transpose();
      }
    }
  }
}

// Compliance 0 is inextensible only in the limit: more substeps and more
// iterations stiffen it. A 30 x 30 cloth hanging from two corners without
// tethers, after 2 s of 1/60 s frames.
TEST(Cloth, MoreSubstepsAndIterationsStretchLess) {
  const int settings[][2] = {{10, 1}, {20, 4}, {40, 4}};
  double stretch[3];
  for (int k = 0; k < 3; ++k) {
    ClothDef def;
    def.columns = def.rows = 30;
    def.pinned = {0, 29};
    def.longRangeAttachments = false;
    def.substeps = settings[k][0];
    def.iterations = settings[k][1];
    auto cloth = testing::Made(Cloth::Create(def));
    for (int i = 0; i < 120; ++i) ASSERT_OK(cloth->Step(1.0 / 60, Vec3(0, -9.81, 0)));
    stretch[k] = cloth->MaxStretch();
  }
  EXPECT_GT(stretch[0], 2 * stretch[1]) << "10 x 1: " << stretch[0] << ", 20 x 4: " << stretch[1];
  EXPECT_GT(stretch[1], 1.5 * stretch[2]) << "20 x 4: " << stretch[1] << ", 40 x 4: " << stretch[2];
}

TEST(Cloth, TethersKeepAHangingClothFromStretching) {
  double stretch[2];
  for (bool tethers : {false, true}) {
    ClothDef def;
    def.columns = 60;
    def.rows = 60;
    def.substeps = 10;
    def.longRangeAttachments = tethers;
    def.pinned = {0, 59};
    auto clothOwner = testing::Made(Cloth::Create(def));
    Cloth& cloth = *clothOwner;
    for (int i = 0; i < 60; ++i) ASSERT_OK(cloth.Step(1.0 / 60, Vec3(0, -9.81, 0)));
    stretch[tethers] = cloth.MaxStretch();
  }
  EXPECT_LT(stretch[1], 0.05) << "with tethers";
  EXPECT_GT(stretch[0], 4 * stretch[1])
      << "without tethers " << stretch[0] << ", with " << stretch[1];
}

}  // namespace
}  // namespace sylva::particles
