// Sylva's cloth against Bullet's btSoftBody cloth (Debian libbullet-dev,
// built only when pkg-config finds it).
//
// The same scene for both: a k x k cloth of 1 kg total, 1 m square, lying
// flat (in the xz plane) and pinned at two adjacent corners, falls and swings
// under gravity alone. Frames of 1/60 s, each 20 substeps of 1/1200 s with one
// constraint iteration a substep; structural, shear and bend (distance 2)
// links, all inextensible (Sylva: compliance 0 on the structural links and the
// defaults on shear and bend; Bullet: linear stiffness 1). Bullet's soft
// body runs in a btSoftRigidDynamicsWorld, as its users run it (aerodynamics
// off, damping 0); its second argument is the position iterations a substep
// (1 is the same work as Sylva's; more buys Bullet stiffness). Each benchmark
// first simulates 3 s (180 frames) and records, at that moment:
//   sag      how far the free corners hang below the pins (m), mean of two
//            (an inextensible 1 m cloth hangs them 1 m below when at rest)
//   stretch  largest relative stretch of a structural link
//   peak     the largest stretch seen at the end of any of those frames
// then times further frames. Sylva runs in double precision, Bullet's
// default build in single.
#include <benchmark/benchmark.h>

#include <BulletSoftBody/btSoftBodyHelpers.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>
#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "particles/cloth.h"

namespace {

using namespace sylva;

constexpr double kFrame = 1.0 / 60;
constexpr int kSubsteps = 20;
constexpr int kSettleFrames = 180;
constexpr double kG = 9.81;

void BM_SylvaCloth(benchmark::State& state) {
  const int k = int(state.range(0));
  particles::ClothDef def;
  def.columns = k;
  def.rows = k;
  def.origin = Vec3(0, 0, 0);
  def.u = Vec3(1, 0, 0);
  def.v = Vec3(0, 0, 1);
  def.mass = 1;
  def.substeps = kSubsteps;
  def.iterations = 1;
  def.pinned = {0, k - 1};  // corners (0, 0) and (k-1, 0)
  def.windDrag = 0;
  def.threads = int(state.range(1));
  auto made = particles::Cloth::Create(def);
  if (!made) {
    state.SkipWithError(made.error().message.c_str());
    return;
  }
  particles::Cloth& cloth = **made;
  const Vec3 g(0, -kG, 0);
  double peak = 0;
  for (int i = 0; i < kSettleFrames; ++i) {
    if (Status st = cloth.Step(kFrame, g); !st.ok()) {
      state.SkipWithError(st.error().message.c_str());
      return;
    }
    peak = std::max(peak, cloth.MaxStretch());
  }
  const auto& x = cloth.positions();
  state.counters["sag"] =
      -0.5 * (x[size_t(cloth.Index(0, k - 1))].y() + x[size_t(cloth.Index(k - 1, k - 1))].y());
  state.counters["stretch"] = cloth.MaxStretch();
  state.counters["peak"] = peak;
  for (auto _ : state) {
    if (Status st = cloth.Step(kFrame, g); !st.ok()) {
      state.SkipWithError(st.error().message.c_str());
      return;
    }
  }
  state.SetItemsProcessed(int64_t(k) * k * state.iterations());
}
BENCHMARK(BM_SylvaCloth)
    ->ArgsProduct({{32, 64, 100}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

struct BulletWorld {
  btSoftBodyRigidBodyCollisionConfiguration config;
  btCollisionDispatcher dispatcher{&config};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btSoftRigidDynamicsWorld world{&dispatcher, &broadphase, &solver, &config};
  btSoftBody* cloth = nullptr;
  int k = 0;

  BulletWorld(int res, int iterations) : k(res) {
    world.setGravity(btVector3(0, btScalar(-kG), 0));
    btSoftBodyWorldInfo& info = world.getWorldInfo();
    info.m_gravity = btVector3(0, btScalar(-kG), 0);
    info.m_sparsesdf.Initialize();
    // Corners 00 and 10 fixed (flags 1 + 2); diagonals generated (shear).
    cloth =
        btSoftBodyHelpers::CreatePatch(info, btVector3(0, 0, 0), btVector3(1, 0, 0),
                                       btVector3(0, 0, 1), btVector3(1, 0, 1), k, k, 1 + 2, true);
    cloth->m_materials[0]->m_kLST = 1;
    cloth->generateBendingConstraints(2, cloth->m_materials[0]);
    cloth->m_cfg.piterations = iterations;
    cloth->m_cfg.kDP = 0;
    cloth->m_cfg.kDG = 0;
    cloth->m_cfg.kLF = 0;
    cloth->setTotalMass(1);
    // setTotalMass gives the fixed corners mass again; pin them.
    cloth->setMass(0, 0);
    cloth->setMass(k - 1, 0);
    world.addSoftBody(cloth);
  }
  ~BulletWorld() {
    world.removeSoftBody(cloth);
    delete cloth;
  }
  void Frame() { world.stepSimulation(btScalar(kFrame), kSubsteps, btScalar(kFrame / kSubsteps)); }
  double Sag() const {
    // Node (c, r) is r * k + c, with r along corner01 (z).
    const auto& nodes = cloth->m_nodes;
    return -0.5 * double(nodes[(k - 1) * k].m_x.y() + nodes[(k - 1) * k + k - 1].m_x.y());
  }
  double Stretch() const {
    // The first links CreatePatch appends are the structural ones (rest =
    // 1 / (k - 1)); measure those.
    const double rest = 1.0 / (k - 1);
    double worst = 0;
    for (int i = 0; i < cloth->m_links.size(); ++i) {
      const btSoftBody::Link& l = cloth->m_links[i];
      if (std::abs(double(l.m_rl) - rest) > 1e-4 * rest) continue;
      worst = std::max(worst, (double((l.m_n[0]->m_x - l.m_n[1]->m_x).length()) - rest) / rest);
    }
    return worst;
  }
};

void BM_BulletSoftBodyCloth(benchmark::State& state) {
  const int k = int(state.range(0));
  BulletWorld w(k, int(state.range(1)));
  double peak = 0;
  for (int i = 0; i < kSettleFrames; ++i) {
    w.Frame();
    peak = std::max(peak, w.Stretch());
  }
  state.counters["sag"] = w.Sag();
  state.counters["stretch"] = w.Stretch();
  state.counters["peak"] = peak;
  for (auto _ : state) w.Frame();
  state.SetItemsProcessed(int64_t(k) * k * state.iterations());
}
BENCHMARK(BM_BulletSoftBodyCloth)
    ->ArgsProduct({{32, 64, 100}, {1, 4}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
