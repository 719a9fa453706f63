// The light environment (plant/light_grid.h): one Update() of the shadow
// grid from N buds and N exposure queries, as a growing plant asks after
// every derivation step; and a whole open L-system grown with it.
// Buds are spread in a crown: uniform in a sphere of radius 4 centred 5
// above the ground, so that density, not only count, grows with N.
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

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

}  // namespace

BENCHMARK_MAIN();
