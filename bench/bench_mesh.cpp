// Tessellation and export throughput (issue 3 targets, one core):
//   tessellation >= 50 M triangles/s; .glb writing >= 500 MB/s; OBJ >= 100 MB/s;
//   Fig. 2.6 grown to about a million segments, end to end (derive,
//   interpret, tessellate at 8 sides, write .glb) in under 2 s.
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "mesh/export.h"
#include "mesh/tessellator.h"
#include "plant/plant.h"

namespace {

using namespace sylva;

std::string Grammar(const char* name) {
  return std::string(SYLVA_SOURCE_DIR) + "/grammars/abop/" + name + ".lsys";
}

plant::PlantSpec Spec(const char* name, int steps, plant::Stage until) {
  plant::PlantSpec spec;
  spec.path = Grammar(name);
  spec.steps = steps;
  spec.threads = 1;
  spec.until = until;
  return spec;
}

mesh::PlantGeometry Geometry(const char* name, int steps) {
  return std::move(plant::BuildPlant(Spec(name, steps, plant::Stage::kGeometry)).plant->geometry);
}

void BM_Tessellate(benchmark::State& state, const char* name, int steps) {
  mesh::PlantGeometry g = Geometry(name, steps);
  mesh::TessellateOptions opt;
  opt.detail.sides = int(state.range(0));
  mesh::TriangleMesh m;
  for (auto _ : state) {
    m.Clear();
    (void)mesh::Tessellate(g, opt, m);
    benchmark::DoNotOptimize(m.indices.data());
  }
  state.SetItemsProcessed(int64_t(m.triangleCount()) * state.iterations());
  state.counters["triangles"] = double(m.triangleCount());
}
BENCHMARK_CAPTURE(BM_Tessellate, monopodial_2_6a_n16, "fig2_06a_monopodial", 16)
    ->Arg(8)
    ->Arg(16)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Tessellate, bracketed_1_24c_n5, "fig1_24c_bracketed_plant", 5)
    ->Arg(8)
    ->Unit(benchmark::kMillisecond);

void BM_Write(benchmark::State& state, const char* ext) {
  mesh::PlantGeometry g = Geometry("fig2_06a_monopodial", 15);
  mesh::TriangleMesh m;
  mesh::TessellateOptions opt;
  (void)mesh::Tessellate(g, opt, m);
  const std::string path =
      (std::filesystem::temp_directory_path() / (std::string("sylva_bench.") + ext)).string();
  size_t bytes = 0;
  for (auto _ : state) {
    if (!mesh::WriteMesh(m, mesh::DefaultPalette(), path).ok()) state.SkipWithError("write failed");
    bytes = std::filesystem::file_size(path);
  }
  state.SetBytesProcessed(int64_t(bytes) * state.iterations());
  state.counters["MB"] = double(bytes) / 1e6;
  std::filesystem::remove(path);
}
BENCHMARK_CAPTURE(BM_Write, glb, "glb")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Write, gltf, "gltf")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Write, obj, "obj")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Write, ply, "ply")->Unit(benchmark::kMillisecond);

// End to end, as `sylva mesh fig2_06a -n 20 --sides 8 -o tree.glb` does on one core.
void BM_EndToEndMillionSegments(benchmark::State& state) {
  const std::string path =
      (std::filesystem::temp_directory_path() / "sylva_bench_e2e.glb").string();
  size_t segments = 0, triangles = 0;
  plant::PlantSpec spec = Spec("fig2_06a_monopodial", 20, plant::Stage::kMesh);
  spec.detail.sides = 8;
  for (auto _ : state) {
    plant::PlantResult r = plant::BuildPlant(spec);
    if (!r.plant) {
      state.SkipWithError("the plant failed");
      break;
    }
    if (!mesh::WriteMesh(r.plant->mesh, r.plant->palette, path).ok())
      state.SkipWithError("write failed");
    segments = r.plant->geometry.segments.size();
    triangles = r.plant->mesh.triangleCount();
  }
  state.counters["segments"] = double(segments);
  state.counters["triangles"] = double(triangles);
  std::filesystem::remove(path);
}
BENCHMARK(BM_EndToEndMillionSegments)->Unit(benchmark::kMillisecond)->Iterations(3);

// Ear clipping of concave outlines (issue 14: a 130,000-vertex polygon took
// over two minutes). Spirals: a band along an Archimedean spiral, nearly
// every inner vertex reflex. Items: vertices.
std::vector<Vec3> SpiralOutline(size_t n) {
  const size_t m = n / 2;
  const double turns = 3, pi = 3.14159265358979323846;
  std::vector<Vec3> v;
  for (size_t i = 0; i < m; ++i) {
    const double t = turns * 2 * pi * double(i) / double(m - 1);
    v.emplace_back((3 + t) * std::cos(t), (3 + t) * std::sin(t), 0);
  }
  for (size_t i = m; i-- > 0;) {
    const double t = turns * 2 * pi * double(i) / double(m - 1);
    v.emplace_back((0.5 + t) * std::cos(t), (0.5 + t) * std::sin(t), 0);
  }
  return v;
}

void BM_TriangulateSpiral(benchmark::State& state) {
  const std::vector<Vec3> v = SpiralOutline(size_t(state.range(0)));
  size_t tris = 0;
  for (auto _ : state) {
    Vec3 n;
    tris = mesh::TriangulatePolygon(v, &n).size() / 3;
    benchmark::DoNotOptimize(tris);
  }
  if (tris != v.size() - 2) state.SkipWithError("wrong triangle count");
  state.SetItemsProcessed(int64_t(v.size()) * state.iterations());
}
BENCHMARK(BM_TriangulateSpiral)->Arg(1000)->Arg(10000)->Arg(130000)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
