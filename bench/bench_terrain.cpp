// Terrain benchmarks. items_per_second = noise samples/s (a fractal sample
// counts once, whatever its octaves) or height-field vertices/s.
// Kernel argument: 0 scalar, 1 AVX2 (skipped where the processor lacks it).
#include <benchmark/benchmark.h>

#include <vector>

#include "core/parallel.h"
#include "core/rng.h"
#include "terrain/diamond_square.h"
#include "terrain/fractal.h"
#include "terrain/height_field.h"
#include "terrain/noise.h"

namespace {

using namespace sylva;
using namespace sylva::terrain;

bool PickKernel(benchmark::State& state, Kernel* kernel) {
  *kernel = state.range(0) ? Kernel::kAvx2 : Kernel::kScalar;
  if (*kernel == Kernel::kAvx2 && BestKernel() != Kernel::kAvx2) {
    state.SkipWithError("no AVX2 on this processor");
    return false;
  }
  state.SetLabel(state.range(0) ? "avx2" : "scalar");
  return true;
}

// The hot path: one octave of 2D gradient noise over a grid, 1 thread.
// 512 x 512 samples (1 MiB of output, in cache).
void BM_Noise2Grid(benchmark::State& state) {
  Kernel kernel;
  if (!PickKernel(state, &kernel)) return;
  const Grid2 grid{-37.3f, 11.9f, 0.0173f, 0.0191f, 512, 512};
  std::vector<float> out(grid.nx * grid.ny);
  for (auto _ : state) {
    GradientNoise2Grid(1, grid, out.data(), kernel);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(out.size()));
}
BENCHMARK(BM_Noise2Grid)->Arg(0)->Arg(1);

std::vector<float> Coordinates(size_t n, uint64_t seed) {
  std::vector<float> v(n);
  for (size_t i = 0; i < n; ++i) v[i] = -500.0f + 1000.0f * float(ToUnit(CounterHash(seed, i)));
  return v;
}

// Arrays of x, y (and z): 2^18 random points.
void BM_Noise2Points(benchmark::State& state) {
  Kernel kernel;
  if (!PickKernel(state, &kernel)) return;
  const size_t n = size_t(1) << 18;
  const std::vector<float> x = Coordinates(n, 1), y = Coordinates(n, 2);
  std::vector<float> out(n);
  for (auto _ : state) {
    GradientNoise2(1, x.data(), y.data(), n, out.data(), kernel);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(n));
}
BENCHMARK(BM_Noise2Points)->Arg(0)->Arg(1);

void BM_Noise3Points(benchmark::State& state) {
  Kernel kernel;
  if (!PickKernel(state, &kernel)) return;
  const size_t n = size_t(1) << 18;
  const std::vector<float> x = Coordinates(n, 1), y = Coordinates(n, 2), z = Coordinates(n, 3);
  std::vector<float> out(n);
  for (auto _ : state) {
    GradientNoise3(1, x.data(), y.data(), z.data(), n, out.data(), kernel);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(n));
}
BENCHMARK(BM_Noise3Points)->Arg(0)->Arg(1);

// The single-sample call in a loop (what a caller without the batch API pays).
void BM_Noise2Single(benchmark::State& state) {
  const size_t n = size_t(1) << 16;
  const std::vector<float> x = Coordinates(n, 1), y = Coordinates(n, 2);
  for (auto _ : state) {
    float sum = 0;
    for (size_t i = 0; i < n; ++i) sum += GradientNoise2(1, x[i], y[i]);
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(n));
}
BENCHMARK(BM_Noise2Single);

// Six octaves of fBm and ridged over a 512 x 512 grid, 1 thread.
void BM_Fbm2Grid(benchmark::State& state) {
  Kernel kernel;
  if (!PickKernel(state, &kernel)) return;
  const Grid2 grid{-37.3f, 11.9f, 0.0173f, 0.0191f, 512, 512};
  std::vector<float> out(grid.nx * grid.ny);
  for (auto _ : state) {
    if (state.range(1)) {
      Ridged2Grid(1, FractalDef{}, grid, out.data(), kernel);
    } else {
      Fbm2Grid(1, FractalDef{}, grid, out.data(), kernel);
    }
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  state.SetLabel(std::string(state.range(0) ? "avx2" : "scalar") +
                 (state.range(1) ? " ridged" : " fbm"));
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(out.size()));
}
BENCHMARK(BM_Fbm2Grid)->Args({0, 0})->Args({1, 0})->Args({1, 1});

// Six octaves of 3D fBm at arrays of points (wind, gusts, clouds), 1 thread.
void BM_Fbm3Points(benchmark::State& state) {
  Kernel kernel;
  if (!PickKernel(state, &kernel)) return;
  const size_t n = size_t(1) << 16;
  const std::vector<float> x = Coordinates(n, 1), y = Coordinates(n, 2), z = Coordinates(n, 3);
  std::vector<float> out(n);
  for (auto _ : state) {
    Fbm3(1, FractalDef{}, x.data(), y.data(), z.data(), n, out.data(), kernel);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(n));
}
BENCHMARK(BM_Fbm3Points)->Arg(0)->Arg(1);

// Diamond-square on a (2^k + 1)^2 grid; argument: size, threads.
void BM_DiamondSquare(benchmark::State& state) {
  DiamondSquareDef def;
  def.size = int(state.range(0));
  ThreadPool pool(int(state.range(1)));
  for (auto _ : state) {
    Expected<std::vector<float>> v = DiamondSquare(def, &pool);
    benchmark::DoNotOptimize(v->data());
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * def.size * def.size);
}
BENCHMARK(BM_DiamondSquare)->Args({1025, 1})->Args({1025, 2})->Unit(benchmark::kMillisecond);

// A scene's terrain: SCENE.md's defaults (fbm, 6 octaves) at a resolution;
// arguments: resolution, threads.
void BM_HeightFieldCreate(benchmark::State& state) {
  TerrainDef def;
  def.resolution = int(state.range(0));
  ThreadPool pool(int(state.range(1)));
  for (auto _ : state) {
    Expected<HeightField> f = HeightField::Create(def, &pool);
    benchmark::DoNotOptimize(f->heights().data());
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * def.resolution * def.resolution);
}
BENCHMARK(BM_HeightFieldCreate)
    ->Args({257, 1})
    ->Args({1025, 1})
    ->Args({1025, 2})
    ->Unit(benchmark::kMillisecond);

// Height and normal queries at random points (a collider's inner loop).
void BM_HeightFieldQuery(benchmark::State& state) {
  const HeightField f = *HeightField::Create(TerrainDef{});
  const size_t n = 4096;
  const std::vector<float> x = Coordinates(n, 1), z = Coordinates(n, 2);
  for (auto _ : state) {
    double sum = 0;
    for (size_t i = 0; i < n; ++i) {
      sum += f.Height(x[i] * 0.1, z[i] * 0.1) + f.Normal(x[i] * 0.1, z[i] * 0.1).y();
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(n));
}
BENCHMARK(BM_HeightFieldQuery);

}  // namespace

BENCHMARK_MAIN();
