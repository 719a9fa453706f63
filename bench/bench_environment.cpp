// The light environment (plant/light_grid.h): one Update() of the shadow
// grid from N buds and N exposure queries, as a growing plant asks after
// every derivation step; and a whole open L-system grown with it. Then
// cpfg's environment programs built in (plant/density_environment.h,
// plant/chiba_environment.h): one step's answers to N ?E modules.
// Buds are spread in a crown: uniform in a sphere of radius 4 centred 5
// above the ground, so that density, not only count, grows with N.
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "plant/chiba_environment.h"
#include "plant/density_environment.h"
#include "plant/light_grid.h"
#include "plant/plant.h"

namespace {

using namespace sylva;

std::vector<Vec3> Crown(size_t n) {
  std::vector<Vec3> buds;
  buds.reserve(n);
  uint64_t k = 0;
  auto u = [&k]() {  // a deterministic hash to [0, 1)
    uint64_t z = (k++ + 1) * 0x9E3779B97F4A7C15ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return double((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
  };
  while (buds.size() < n) {
    const Vec3 p(u() * 2 - 1, u() * 2 - 1, u() * 2 - 1);
    if (p.squaredNorm() <= 1) buds.push_back(Vec3(0, 5, 0) + 4 * p);
  }
  return buds;
}

// Arguments: buds, depth. Cell 0.25: a 32-voxel-wide crown.
void BM_LightGridUpdateAndQuery(benchmark::State& state) {
  const std::vector<Vec3> buds = Crown(size_t(state.range(0)));
  plant::LightDef def;
  def.cell = 0.25;
  def.depth = int(state.range(1));
  plant::LightGrid grid(def);
  double sum = 0;
  for (auto _ : state) {
    if (!grid.Update(buds).ok()) state.SkipWithError("update failed");
    for (const Vec3& p : buds) sum += grid.Exposure(p);
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * state.range(0));
  state.counters["voxels"] = double(grid.cellCount());
  state.counters["mean_light"] = sum / double(state.iterations() * buds.size());
}
BENCHMARK(BM_LightGridUpdateAndQuery)
    ->Args({1000, 5})
    ->Args({10000, 5})
    ->Args({100000, 5})
    ->Args({10000, 2})
    ->Args({10000, 8})
    ->Unit(benchmark::kMillisecond);

// A whole open L-system: grammars/environment/two_trees_light.lsys to its
// word (derivation, the turtle after every step, the light grid).
void BM_GrowTwoTreesInLight(benchmark::State& state) {
  plant::PlantSpec spec;
  spec.path = std::string(SYLVA_SOURCE_DIR) + "/grammars/environment/two_trees_light.lsys";
  spec.until = plant::Stage::kWord;
  spec.threads = 1;
  size_t modules = 0;
  for (auto _ : state) {
    plant::PlantResult r = plant::BuildPlant(spec);
    if (!r.plant) state.SkipWithError("build failed");
    modules = r.plant->word.size();
  }
  state.counters["modules"] = double(modules);
}
BENCHMARK(BM_GrowTwoTreesInLight)->Unit(benchmark::kMillisecond);

// honda81 in 3D, radius 0.25, N points in the crown: one step's answers.
void BM_Honda81Answers(benchmark::State& state) {
  const std::vector<Vec3> pts = Crown(size_t(state.range(0)));
  const double vigor = 1;
  std::vector<plant::DensityQuery> q;
  for (const Vec3& p : pts) q.push_back(plant::DensityQuery{p, {&vigor, 1}});
  const plant::Honda81Def def{0.25, true};
  double free = 0;
  for (auto _ : state) {
    const std::vector<double> a = plant::Honda81Answers(def, q);
    free = 0;
    for (double x : a) free += x;
    benchmark::DoNotOptimize(free);
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * state.range(0));
  state.counters["free"] = free / double(pts.size());
}
BENCHMARK(BM_Honda81Answers)->Arg(1000)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond);

// chiba with two-trees' light.spec (9 sources, transmittance 0.25,
// intersection areas), N clusters of radius 0.3 in the crown.
void BM_ChibaAnswer(benchmark::State& state) {
  const std::vector<Vec3> pts = Crown(size_t(state.range(0)));
  plant::ChibaDef def;
  def.transmittance = 0.25f;
  def.estimateArea = true;
  def.sources = {{{0, 100, 0}, 4},   {{40, 100, 0}, 3}, {{-40, 100, 0}, 3},
                 {{0, 100, -40}, 3}, {{0, 100, 40}, 3}, {{80, 75, 0}, 2},
                 {{-80, 75, 0}, 2},  {{0, 75, 80}, 2},  {{0, 75, -80}, 2}};
  plant::ChibaEnvironment env(def, 3);
  std::vector<double> params(pts.size());
  double light = 0;
  for (auto _ : state) {
    std::vector<plant::EnvQuery> q;
    for (size_t i = 0; i < pts.size(); ++i) {
      params[i] = 0.3;
      q.push_back(plant::EnvQuery{pts[i], {}, {&params[i], 1}});
    }
    if (!env.Answer(q).ok()) state.SkipWithError("answer failed");
    light = 0;
    for (double x : params) light += x;
    benchmark::DoNotOptimize(light);
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * state.range(0));
  state.counters["mean_light"] = light / double(pts.size());
}
BENCHMARK(BM_ChibaAnswer)->Arg(1000)->Arg(10000)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
