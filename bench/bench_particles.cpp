// Particle benchmarks. items_per_second = particle steps/s (or points/s).
// Arguments: particle count, threads.
#include <benchmark/benchmark.h>

#include <random>

#include "ball_scenes.h"
#include "core/parallel.h"
#include "particles/bulk.h"
#include "particles/cloth.h"
#include "particles/flocking.h"
#include "particles/grid.h"
#include "particles/system.h"

namespace {

using namespace sylva;

// The case: gravity + linear/quadratic drag + one plane collider.
// Every timed step starts from the same state: a given percentage of the
// particles resting on the plane (sliding on it; third argument, 0 or 50)
// and the rest in the air above it, so the work
// per step does not drift with the number of iterations the library picks
// (particles falling onto the plane would make later steps dearer). The
// state is restored outside the timing.
void BM_Step(benchmark::State& state, particles::Integrator in) {
  particles::System sys(int(state.range(1)));
  const int n = int(state.range(0));
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-1, 1);
  auto& s = sys.state;
  s.position.reserve(size_t(n));
  for (int i = 0; i < n; ++i) {
    if (i % 100 < state.range(2)) {
      s.Add(Vec3(u(rng), -1, u(rng)), Vec3(u(rng), 0, u(rng)));
    } else {
      s.Add(Vec3(u(rng), u(rng), u(rng)), Vec3(u(rng), u(rng), u(rng)));
    }
  }
  sys.AddForce(std::make_shared<particles::Gravity>(Vec3(0, -9.81, 0)));
  sys.AddForce(std::make_shared<particles::Drag>(0.1, 0.01));
  if (!sys.AddPlane(particles::Plane{Vec3(0, -1, 0), Vec3(0, 1, 0), 0.8, 0.1}).ok()) {
    state.SkipWithError("bad plane");
    return;
  }
  const std::vector<Vec3> x0 = s.position, v0 = s.velocity;
  for (auto _ : state) {
    state.PauseTiming();
    std::copy(x0.begin(), x0.end(), s.position.begin());
    std::copy(v0.begin(), v0.end(), s.velocity.begin());
    state.ResumeTiming();
    if (!sys.Step(1.0 / 240, in).ok()) state.SkipWithError("step failed");
  }
  state.SetItemsProcessed(state.range(0) * state.iterations());
}
BENCHMARK_CAPTURE(BM_Step, symplectic_euler, particles::Integrator::kSymplecticEuler)
    ->ArgsProduct({{1000000, 10000000}, {1, 2}, {0, 50}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Step, rk4, particles::Integrator::kRK4)
    ->ArgsProduct({{1000000}, {1, 2}, {50}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The same scene for BulkSystem (single precision, structure of arrays).
// restLanes: the resting-floor path's lanes (0: the widest this processor
// runs; see BulkSystem::SetKernel). radius: every particle's (m); the
// resting ones lie on the floor at it, and with settle, the timed step
// starts from the state two steps on (a ball's height on the floor has no
// float: the first step pushes it a few ulps off, where it then rests).
// tilted: the floor through (0, -1, 0) has the normal (0.1, 1, -0.05),
// normalized (a point's height on it has no float either), the resting
// particles lie on it sliding along it, those in the air start at heights
// in [-0.8, 1] (above it).
void BulkStep(benchmark::State& state, int restLanes, float radius = 0, bool settle = false,
              bool tilted = false) {
  particles::BulkSystem sys(int(state.range(1)));
  sys.SetKernel(particles::kernels::Kernel::kAvx, restLanes);
  const int n = int(state.range(0));
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-1, 1);
  auto& s = sys.state;
  s.Reserve(size_t(n));
  const Vec3 normal = tilted ? Vec3(0.1, 1, -0.05).normalized() : Vec3(0, 1, 0);
  const Vec3 point(0, -1, 0);
  for (int i = 0; i < n; ++i) {
    if (tilted && i % 100 < state.range(2)) {
      Vec3 x(u(rng), 0, u(rng));
      x -= (normal.dot(x - point) - double(radius)) * normal;
      const Vec3 v(u(rng), 0, u(rng));
      s.Add(x, v - normal.dot(v) * normal);
    } else if (tilted) {
      s.Add(Vec3(u(rng), 0.1 + 0.9 * u(rng), u(rng)), Vec3(u(rng), u(rng), u(rng)));
    } else if (i % 100 < state.range(2)) {
      s.Add(Vec3(u(rng), -1 + double(radius), u(rng)), Vec3(u(rng), 0, u(rng)));
    } else {
      s.Add(Vec3(u(rng), u(rng), u(rng)), Vec3(u(rng), u(rng), u(rng)));
    }
    s.radius.back() = radius;
  }
  sys.fields.gravity = Vec3(0, -9.81, 0);
  sys.fields.linearDrag = 0.1;
  sys.fields.quadraticDrag = 0.01;
  if (!sys.AddCollider(particles::Collider::Plane(point, normal).Restitution(0.8).Friction(0.1))
           .ok()) {
    state.SkipWithError("bad plane");
    return;
  }
  for (int k = 0; settle && k < 2; ++k) {
    if (!sys.Step(1.0 / 240).ok()) state.SkipWithError("step failed");
  }
  const particles::BulkState s0 = s;
  for (auto _ : state) {
    state.PauseTiming();
    for (auto [to, from] : {std::pair{&s.px, &s0.px},
                            {&s.py, &s0.py},
                            {&s.pz, &s0.pz},
                            {&s.vx, &s0.vx},
                            {&s.vy, &s0.vy},
                            {&s.vz, &s0.vz}}) {
      std::copy(from->begin(), from->end(), to->begin());
    }
    state.ResumeTiming();
    if (!sys.Step(1.0 / 240).ok()) state.SkipWithError("step failed");
  }
  state.SetItemsProcessed(state.range(0) * state.iterations());
}
void BM_BulkStep(benchmark::State& state) {
  BulkStep(state, 0);
}
BENCHMARK(BM_BulkStep)
    ->ArgsProduct({{1000000, 10000000}, {1, 2}, {0, 50}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
// The same on the 4-lane AVX resting path, what a processor without
// AVX-512 runs (the advance is the same AVX kernel).
void BM_BulkStepFourLanes(benchmark::State& state) {
  BulkStep(state, 4);
}
BENCHMARK(BM_BulkStepFourLanes)
    ->ArgsProduct({{1000000}, {1, 2}, {0, 50}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
// Balls of radius 10 mm: their resting height, -0.99, has no float. From
// the state two steps on (settled a few ulps above the floor), and from
// the start (argument 3 = 0: inside by the rounding, each pushed off).
void BM_BulkStepBalls(benchmark::State& state) {
  BulkStep(state, 0, 0.01f, state.range(3) != 0);
}
BENCHMARK(BM_BulkStepBalls)
    ->ArgsProduct({{1000000}, {2}, {0, 50}, {1, 0}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
// The same balls on the four-lane path (a processor without AVX-512).
void BM_BulkStepBallsFourLanes(benchmark::State& state) {
  BulkStep(state, 4, 0.01f, state.range(3) != 0);
}
BENCHMARK(BM_BulkStepBallsFourLanes)
    ->ArgsProduct({{1000000}, {2}, {0, 50}, {1, 0}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
// Points (argument 3 = 0) and balls of 10 mm (10) on a tilted floor,
// settled two steps, on the widest path (argument 4 = 0) and four lanes (4).
void BM_BulkStepTilted(benchmark::State& state) {
  BulkStep(state, int(state.range(4)), float(state.range(3)) * 1e-3f, true, true);
}
BENCHMARK(BM_BulkStepTilted)
    ->ArgsProduct({{1000000}, {2}, {0, 50}, {0, 10}, {0, 4}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Issue 17's snow on terrain: 100,000 flakes (radius argument 2 in mm: 0, a
// point, or 10; builds before particles had a radius see points; friction 0.8,
// no bounce, drag to about 5 m/s) over a 40 m square, each starting 0-12 m
// above the ground, BulkSystem at 60 Hz. Argument 0: the ground, 0 = the
// plane y = 0, 1 = a height field of 128 x 128 cells (32,768 triangles, 0 to
// 2 m of sines) as a mesh collider; argument 1: threads. One simulated
// second runs before the timing, so about a third of the flakes lie on the
// ground and the rest fall; the state runs on between iterations. Counter
// `asleep`: the flakes that slept in the last step (BulkSystem::sleepers;
// 0 on the plane, whose kernel runs instead).
float GroundHeight(double x, double z) {
  return float(1 + 0.6 * std::sin(0.35 * x) * std::cos(0.27 * z) +
               0.4 * std::sin(0.9 * x + 0.5 * z));
}
void BM_SnowOnGround(benchmark::State& state) {
  const bool terrain = state.range(0) == 1;
  particles::BulkSystem sys(int(state.range(1)));
  particles::Collider ground = particles::Collider::Plane(Vec3::Zero(), Vec3::UnitY());
  if (terrain) {
    const int n = 128;
    std::vector<Vec3> v;
    std::vector<std::array<uint32_t, 3>> t;
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        const double x = -20 + 40.0 * i / n, z = -20 + 40.0 * j / n;
        v.emplace_back(x, GroundHeight(x, z), z);
      }
    auto at = [&](int i, int j) { return uint32_t(j * (n + 1) + i); };
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        t.push_back({at(i, j), at(i, j + 1), at(i + 1, j)});
        t.push_back({at(i + 1, j), at(i, j + 1), at(i + 1, j + 1)});
      }
    ground = particles::Collider::Mesh(std::make_shared<particles::TriangleBvh>(v, t));
  }
  if (!sys.AddCollider(ground.Restitution(0).Friction(0.8)).ok())
    return state.SkipWithError("bad ground");
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-19.5, 19.5), up(0.05, 12);
  for (int i = 0; i < 100000; ++i) {
    const double x = u(rng), z = u(rng);
    sys.state.Add(Vec3(x, (terrain ? GroundHeight(x, z) : 0) + up(rng), z), Vec3(0, -1, 0));
    sys.state.radius.back() = float(state.range(2)) * 1e-3f;
  }
  sys.fields.gravity = Vec3(0, -9.81, 0);
  sys.fields.linearDrag = 2;
  sys.fields.wind = Vec3(0.5, 0, 0.2);
  for (int s = 0; s < 60; ++s) {
    if (Status st = sys.Step(1.0 / 60); !st.ok())
      return state.SkipWithError(st.error().message.c_str());
  }
  for (auto _ : state) {
    if (Status st = sys.Step(1.0 / 60); !st.ok())
      return state.SkipWithError(st.error().message.c_str());
  }
  state.SetItemsProcessed(100000 * state.iterations());
  state.counters["asleep"] = double(sys.sleepers());  // in the last step
}
BENCHMARK(BM_SnowOnGround)
    ->ArgsProduct({{0, 1}, {1, 2}, {0, 10}})
    ->Iterations(30)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Issue 17's self-colliding balls: 10,000 balls of radius 0.05 m
// (restitution 0.3) in a box 2 m wide, under gravity, System with
// symplectic Euler at 60 Hz; argument: threads. One simulated second runs
// before the timing (the balls fall and pile up); the state runs on.
void BM_SelfCollidingBalls(benchmark::State& state) {
  particles::System sys(int(state.range(0)));
  if (Status st = bench::AddSelfCollidingBalls(sys); !st.ok())
    return state.SkipWithError(st.error().message.c_str());
  for (int s = 0; s < 60; ++s) {
    if (Status st = sys.Step(1.0 / 60, particles::Integrator::kSymplecticEuler); !st.ok())
      return state.SkipWithError(st.error().message.c_str());
  }
  for (auto _ : state) {
    if (Status st = sys.Step(1.0 / 60, particles::Integrator::kSymplecticEuler); !st.ok())
      return state.SkipWithError(st.error().message.c_str());
  }
  state.SetItemsProcessed(10000 * state.iterations());
}
BENCHMARK(BM_SelfCollidingBalls)
    ->Arg(1)
    ->Arg(2)
    ->Iterations(30)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Issue 17's cube: 2,000 particles at 150 m/s in random directions inside a
// closed cube of six polygon colliders, 1 m wide, restitution 1, no forces,
// at 60 Hz: about 2.5 crossings of the cube a step, so most particles meet
// several panels a step. The scene is steady (speeds never change), so the
// state runs on between iterations. Argument: 0 = System, 1 = BulkSystem.
// The counter `outside` is the number of particles outside the cube at the
// end (0 when every contact held).
void BM_CubeOfPanels(benchmark::State& state) {
  std::vector<particles::Collider> faces;
  for (int axis = 0; axis < 3; ++axis) {
    for (double side : {-0.5, 0.5}) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      std::vector<Vec3> quad;
      for (auto [a, b] : {std::pair{-0.5, -0.5}, {0.5, -0.5}, {0.5, 0.5}, {-0.5, 0.5}}) {
        Vec3 p;
        p[axis] = side;
        p[u] = a;
        p[v] = b;
        quad.push_back(p);
      }
      faces.push_back(particles::Collider::Polygon(quad).Restitution(1));
    }
  }
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.495, 0.495);
  std::normal_distribution<double> g;
  std::vector<Vec3> x, v;
  for (int i = 0; i < 2000; ++i) {
    x.emplace_back(u(rng), u(rng), u(rng));
    v.push_back(150 * Vec3(g(rng), g(rng), g(rng)).normalized());
  }
  auto outside = [](const Vec3& p) { return !((p.array().abs() <= 0.5).all()); };
  int out = 0;
  if (state.range(0) == 0) {
    particles::System sys(1);
    for (size_t i = 0; i < x.size(); ++i) sys.state.Add(x[i], v[i]);
    for (const auto& f : faces) {
      if (!sys.AddCollider(f).ok()) return state.SkipWithError("bad panel");
    }
    for (auto _ : state) {
      if (Status st = sys.Step(1.0 / 60, particles::Integrator::kSymplecticEuler); !st.ok())
        return state.SkipWithError(st.error().message.c_str());
    }
    for (const Vec3& p : sys.state.position) out += outside(p);
  } else {
    particles::BulkSystem sys(1);
    for (size_t i = 0; i < x.size(); ++i) sys.state.Add(x[i], v[i]);
    for (const auto& f : faces) {
      if (!sys.AddCollider(f).ok()) return state.SkipWithError("bad panel");
    }
    for (auto _ : state) {
      if (Status st = sys.Step(1.0 / 60); !st.ok())
        return state.SkipWithError(st.error().message.c_str());
    }
    for (size_t i = 0; i < sys.state.size(); ++i) out += outside(sys.state.position(i));
  }
  state.counters["outside"] = out;
  state.SetItemsProcessed(2000 * state.iterations());
}
BENCHMARK(BM_CubeOfPanels)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond)->UseRealTime();

// Counting-sort grid over n random points in a cube (density ~8 a cell).
void BM_GridBuild(benchmark::State& state) {
  const int n = int(state.range(0));
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Vec3> x(n);
  for (auto& p : x) p = Vec3(u(rng), u(rng), u(rng));
  const double cell = std::cbrt(8.0 / n);
  particles::NeighbourGrid grid;
  std::unique_ptr<ThreadPool> pool;
  if (state.range(1) > 1) pool = std::make_unique<ThreadPool>(int(state.range(1)));
  for (auto _ : state) {
    grid.Build(x.data(), x.size(), cell, pool.get());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(int64_t(n) * state.iterations());
}
BENCHMARK(BM_GridBuild)
    ->ArgsProduct({{1000000}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Flocking: n boids, about 20 neighbours each, symplectic Euler steps.
void BM_Flocking(benchmark::State& state) {
  const int n = int(state.range(0));
  particles::System sys(int(state.range(1)));
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  const double side = std::cbrt(n / 20.0);  // ~20 boids per unit cube
  for (int i = 0; i < n; ++i)
    sys.state.Add(Vec3(u(rng), u(rng), u(rng)) * side, Vec3(u(rng), u(rng), u(rng)));
  particles::FlockingDef def;
  def.radius = 0.6;
  def.separationRadius = 0.2;
  auto flock = particles::Flocking::Create(def);
  if (!flock) {
    state.SkipWithError(flock.error().message.c_str());
    return;
  }
  sys.AddForce(*flock);
  sys.AddForce(std::make_shared<particles::Drag>(0.1));
  for (auto _ : state) {
    if (!sys.Step(1.0 / 60, particles::Integrator::kSymplecticEuler).ok())
      state.SkipWithError("step failed");
  }
  state.SetItemsProcessed(int64_t(n) * state.iterations());
}
BENCHMARK(BM_Flocking)
    ->ArgsProduct({{100000}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Cloth: one 1/60 s frame of a k x k cloth pinned at two corners, in wind.
void BM_Cloth(benchmark::State& state, particles::ClothSolver solver) {
  const int k = int(state.range(0));
  particles::ClothDef def;
  def.columns = k;
  def.rows = k;
  def.solver = solver;
  def.substeps = 20;
  def.iterations = 1;
  def.cgIterations = 20;
  def.pinned = {0, k - 1};
  def.threads = int(state.range(1));
  auto made = particles::Cloth::Create(def);
  if (!made) {
    state.SkipWithError(made.error().message.c_str());
    return;
  }
  particles::Cloth& cloth = **made;
  for (int i = 0; i < 30; ++i) {
    if (Status st = cloth.Step(1.0 / 60, Vec3(0, -9.81, 0), Vec3(0, 0, 2)); !st.ok()) {
      state.SkipWithError(st.error().message.c_str());  // settle a little
      return;
    }
  }
  for (auto _ : state) {
    if (Status st = cloth.Step(1.0 / 60, Vec3(0, -9.81, 0), Vec3(0, 0, 2)); !st.ok()) {
      state.SkipWithError(st.error().message.c_str());
      return;
    }
  }
  state.counters["stretch"] = cloth.MaxStretch();
  state.SetItemsProcessed(int64_t(k) * k * state.iterations());
}
BENCHMARK_CAPTURE(BM_Cloth, xpbd_20_substeps, particles::ClothSolver::kXPBD)
    ->ArgsProduct({{100, 256}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Cloth, implicit_20_cg, particles::ClothSolver::kImplicit)
    ->ArgsProduct({{100}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Implicit cloth at large steps: one 1/10 s frame of a k x k cloth hanging
// from two corners in a 2 m/s wind, from the state after 4 frames (where
// the strain limiter works hardest; rebuilt outside the timing); stretch =
// the largest structural strain after the frame, cycles = the limiter's.
void BM_ClothImplicitTenthOfASecond(benchmark::State& state) {
  const int k = int(state.range(0));
  particles::ClothDef def;
  def.columns = k;
  def.rows = k;
  def.solver = particles::ClothSolver::kImplicit;
  def.pinned = {0, k - 1};
  auto made = particles::Cloth::Create(def);
  if (!made) {
    state.SkipWithError(made.error().message.c_str());
    return;
  }
  const Vec3 g(0, -9.81, 0), wind(0, 0, 2);
  std::unique_ptr<particles::Cloth> run = std::move(*made);
  double stretch = 0;
  int cycles = 0;
  for (auto _ : state) {
    state.PauseTiming();  // a fresh cloth stepped to the same state
    auto next = particles::Cloth::Create(def);
    run = std::move(*next);
    for (int i = 0; i < 4; ++i) {
      if (Status st = run->Step(0.1, g, wind); !st.ok()) {
        state.SkipWithError(st.error().message.c_str());
        return;
      }
    }
    state.ResumeTiming();
    if (Status st = run->Step(0.1, g, wind); !st.ok()) {
      state.SkipWithError(st.error().message.c_str());
      return;
    }
    stretch = run->MaxStretch();
    cycles = run->lastStrainCycles();
  }
  state.counters["stretch"] = stretch;
  state.counters["cycles"] = cycles;
  state.SetItemsProcessed(int64_t(k) * k * state.iterations());
}
BENCHMARK(BM_ClothImplicitTenthOfASecond)
    ->Arg(32)
    ->Arg(64)
    ->Arg(100)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Cloth with contacts: one 1/60 s frame (20 substeps) of a k x k, 1 m
// cloth draped over a ball on the ground (after 1 s of fall), with the
// colliders only (self = 0) or with self-collision too (thickness 0.8 of
// the spacing).
void BM_ClothContacts(benchmark::State& state) {
  const int k = int(state.range(0));
  particles::ClothDef def;
  def.columns = k;
  def.rows = k;
  def.origin = Vec3(-0.5, 0.5, -0.5);
  def.u = Vec3(1, 0, 0);
  def.v = Vec3(0, 0, 1);
  def.substeps = 20;
  def.thickness = state.range(1) ? 0.8 / (k - 1) : 0;
  def.threads = int(state.range(2));
  auto made = particles::Cloth::Create(def);
  if (!made) {
    state.SkipWithError(made.error().message.c_str());
    return;
  }
  particles::Cloth& cloth = **made;
  const Status a = cloth.AddCollider(particles::Collider::Sphere(Vec3(0, 0, 0), 0.3).Friction(0.4));
  const Status b =
      cloth.AddCollider(particles::Collider::Plane(Vec3(0, -0.3, 0), Vec3(0, 1, 0)).Friction(0.4));
  if (!a.ok() || !b.ok()) {
    state.SkipWithError("collider");
    return;
  }
  for (int i = 0; i < 60; ++i) {
    if (Status st = cloth.Step(1.0 / 60, Vec3(0, -9.81, 0)); !st.ok()) {
      state.SkipWithError(st.error().message.c_str());
      return;
    }
  }
  for (auto _ : state) {
    if (Status st = cloth.Step(1.0 / 60, Vec3(0, -9.81, 0)); !st.ok()) {
      state.SkipWithError(st.error().message.c_str());
      return;
    }
  }
  state.counters["contacts"] = double(cloth.lastContacts());
  state.SetItemsProcessed(int64_t(k) * k * state.iterations());
}
BENCHMARK(BM_ClothContacts)
    ->ArgsProduct({{100}, {0, 1}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
