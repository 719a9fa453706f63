// Particle benchmarks. items_per_second = particle steps/s (or points/s).
// Arguments: particle count, threads.
#include <benchmark/benchmark.h>

#include <random>

#include "particles/system.h"

namespace {

using namespace sylva;

void Fill(particles::System& sys, int n) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-1, 1);
  auto& s = sys.state;
  s.position.reserve(n);
  for (int i = 0; i < n; ++i) s.Add(Vec3(u(rng), u(rng), u(rng)), Vec3(u(rng), u(rng), u(rng)));
}

// The case: gravity + linear/quadratic drag + one plane collider.
void BM_Step(benchmark::State& state, particles::Integrator in) {
  particles::System sys(int(state.range(1)));
  Fill(sys, int(state.range(0)));
  sys.AddForce(std::make_shared<particles::Gravity>(Vec3(0, -9.81, 0)));
  sys.AddForce(std::make_shared<particles::Drag>(0.1, 0.01));
  sys.AddPlane(particles::Plane{Vec3(0, -1, 0), Vec3(0, 1, 0), 0.8, 0.1});
  for (auto _ : state) {
    if (!sys.Step(1.0 / 240, in).ok()) state.SkipWithError("step failed");
  }
  state.SetItemsProcessed(state.range(0) * state.iterations());
}
BENCHMARK_CAPTURE(BM_Step, symplectic_euler, particles::Integrator::kSymplecticEuler)
    ->ArgsProduct({{1000000, 10000000}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Step, rk4, particles::Integrator::kRK4)
    ->ArgsProduct({{1000000}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
