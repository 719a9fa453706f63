// Frame times at 1920x1080 (issue 4): a plant of about a million triangles
// and a batch of a million points, drawn through the headless context
// (Mesa llvmpipe on machines with no GPU). One iteration = Draw + Finish.
#include <benchmark/benchmark.h>

#include <random>
#include <string>

#include "plant/plant.h"
#include "render/headless_context.h"
#include "render/renderer.h"

namespace {

using namespace sylva;

struct Gl {
  std::unique_ptr<render::HeadlessContext> context;
  std::unique_ptr<render::Renderer> renderer;
};

Gl& Context() {
  static Gl gl = [] {
    Gl g;
    g.context = render::HeadlessContext::Create().value();
    g.renderer = render::Renderer::Create(std::string(SYLVA_SOURCE_DIR) + "/shaders").value();
    (void)g.renderer->Resize(1920, 1080);
    return g;
  }();
  return gl;
}

void BM_FrameMillionTrianglePlant(benchmark::State& state) {
  plant::PlantSpec spec;
  spec.path = std::string(SYLVA_SOURCE_DIR) + "/grammars/abop/fig2_08b_ternary.lsys";
  spec.steps = 8;
  spec.detail.sides = 22;  // about 1.01 M triangles
  plant::PlantResult r = plant::BuildPlant(spec);
  if (!r.plant) {
    state.SkipWithError(r.diagnostics.FormatAll().c_str());
    return;
  }
  const mesh::TriangleMesh& m = r.plant->mesh;
  Vec3 lo = m.positions[0].cast<double>(), hi = lo;
  for (const auto& p : m.positions) {
    lo = lo.cwiseMin(p.cast<double>());
    hi = hi.cwiseMax(p.cast<double>());
  }
  Gl& gl = Context();
  (void)gl.renderer->SetPoints({});  // an empty batch is always valid
  (void)gl.renderer->SetLines({});   // an empty batch is always valid
  gl.renderer->SetMesh(m, mesh::DefaultPalette());
  const render::Camera cam = render::Camera::Frame(lo, hi, 16.0 / 9, 30, 12, false);
  for (auto _ : state) {
    gl.renderer->Draw(cam);
    gl.renderer->Finish();
  }
  gl.renderer->SetMesh({}, {});
  state.counters["triangles"] = double(m.triangleCount());
  state.counters["fps"] =
      benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_FrameMillionTrianglePlant)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

void BM_FrameMillionPoints(benchmark::State& state) {
  render::PointBatch pts;
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(-1, 1);
  for (int i = 0; i < 1000000; ++i) {
    pts.positions.push_back(mesh::Vec3f(u(rng), u(rng), u(rng)));
    pts.sizes.push_back(0.004f);
    pts.colors.push_back(mesh::Vec3f(0.9f, 0.6f + 0.3f * u(rng), 0.2f));
  }
  Gl& gl = Context();
  gl.renderer->SetMesh({}, {});
  if (Status st = gl.renderer->SetPoints(pts); !st.ok()) {
    state.SkipWithError(st.error().message.c_str());
    return;
  }
  const render::Camera cam =
      render::Camera::Frame(Vec3(-1, -1, -1), Vec3(1, 1, 1), 16.0 / 9, 30, 20, false);
  for (auto _ : state) {
    gl.renderer->Draw(cam);
    gl.renderer->Finish();
  }
  (void)gl.renderer->SetPoints({});
  state.counters["points"] = 1e6;
  state.counters["fps"] =
      benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_FrameMillionPoints)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

}  // namespace

BENCHMARK_MAIN();
