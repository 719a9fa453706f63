// Particle steps per second: particles x steps / time, one thread.
#include <benchmark/benchmark.h>

#include <random>

#include "particles/system.h"

namespace {

using namespace sylva;

void BM_Step(benchmark::State& state, particles::Integrator in) {
  particles::System sys;
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-1, 1);
  const int n = int(state.range(0));
  for (int i = 0; i < n; ++i) sys.state.Add(Vec3(u(rng), u(rng), u(rng)), Vec3(u(rng), u(rng), u(rng)));
  sys.AddForce(std::make_shared<particles::Gravity>(Vec3(0, -9.81, 0)));
  sys.AddForce(std::make_shared<particles::Drag>(0.1, 0.01));
  sys.AddPlane(particles::Plane{Vec3(0, -1, 0), Vec3(0, 1, 0), 0.8, 0.1});
  for (auto _ : state) sys.Step(1.0 / 240, in);
  state.SetItemsProcessed(int64_t(n) * state.iterations());
}
BENCHMARK_CAPTURE(BM_Step, symplectic_euler, particles::Integrator::kSymplecticEuler)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Step, rk4, particles::Integrator::kRK4)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
