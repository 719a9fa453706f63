// Frame times at 1920x1080 (issue 4): a plant of about a million triangles
// and a batch of a million points, drawn through the headless context
// (Mesa llvmpipe on machines with no GPU). One iteration = Draw + Finish.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <random>
#include <string>

#include "core/parallel.h"
#include "draw/draw_list.h"
#include "mesh/export.h"
#include "mesh/tessellator.h"
#include "plant/plant.h"
#include "render/camera.h"
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
  state.SetLabel(gl.context->Renderer());
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
  state.SetLabel(gl.context->Renderer());
  state.counters["points"] = 1e6;
  state.counters["fps"] =
      benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_FrameMillionPoints)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

// Screen-space tessellation (docs/lod.md) of ABOP 2.6a at n = 20 (about a
// million segments) for the default 1920x1080 framing, on 1 and 2 threads
// (issue 15: 2 threads at least 1.7 times one). Items: triangles.
void BM_TessellateScreenSpace(benchmark::State& state) {
  static const mesh::PlantGeometry geometry = [] {
    plant::PlantSpec spec;
    spec.path = std::string(SYLVA_SOURCE_DIR) + "/grammars/abop/fig2_06a_monopodial.lsys";
    spec.steps = 20;
    spec.until = plant::Stage::kGeometry;
    return std::move(plant::BuildPlant(spec).plant->geometry);
  }();
  const mesh::Box box = mesh::TessellatedBounds(geometry, nullptr);
  const render::Camera cam = render::Camera::Frame(box.lo, box.hi, 1920.0 / 1080, 30, 12, false);
  mesh::TessellateOptions opt;
  opt.view = mesh::ScreenView{cam.ViewProjection(1920.0 / 1080), 1920, 1080, 0.5};
  ThreadPool pool(int(state.range(0)));
  opt.pool = state.range(0) > 1 ? &pool : nullptr;
  mesh::TriangleMesh m;
  for (auto _ : state) {
    m.Clear();
    (void)mesh::Tessellate(geometry, opt, m);
    benchmark::DoNotOptimize(m.indices.data());
  }
  state.SetItemsProcessed(int64_t(m.triangleCount()) * state.iterations());
  state.counters["triangles"] = double(m.triangleCount());
  state.counters["segments"] = double(geometry.segments.size());
}
BENCHMARK(BM_TessellateScreenSpace)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

// The same with coverage lines (`sylva render`'s default: twigs under a
// pixel as 1 px ribbons with their coverage), one thread.
void BM_TessellateScreenSpaceCoverage(benchmark::State& state) {
  plant::PlantSpec spec;
  spec.path = std::string(SYLVA_SOURCE_DIR) + "/grammars/abop/fig2_06a_monopodial.lsys";
  spec.steps = 20;
  spec.until = plant::Stage::kGeometry;
  static const mesh::PlantGeometry geometry = std::move(plant::BuildPlant(spec).plant->geometry);
  const mesh::Box box = mesh::TessellatedBounds(geometry, nullptr);
  const render::Camera cam = render::Camera::Frame(box.lo, box.hi, 1920.0 / 1080, 30, 12, false);
  mesh::TessellateOptions opt;
  opt.view = mesh::ScreenView{cam.ViewProjection(1920.0 / 1080), 1920, 1080, 0.5};
  opt.view->coverage = state.range(0) != 0;
  mesh::TriangleMesh m;
  for (auto _ : state) {
    m.Clear();
    (void)mesh::Tessellate(geometry, opt, m);
    benchmark::DoNotOptimize(m.indices.data());
  }
  size_t lines = 0;
  for (float c : m.coverage) lines += c < 1;
  state.SetItemsProcessed(int64_t(m.triangleCount()) * state.iterations());
  state.counters["triangles"] = double(m.triangleCount());
  state.counters["coverageVertices"] = double(lines);
}
BENCHMARK(BM_TessellateScreenSpaceCoverage)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The viewer's mesh swap (issue 15: no frame blocked over 50 ms): ABOP
// 2.6a at n = 15 or 20 tessellated for two views of a 640x360 window
// (screen-space detail with coverage, shadows 2048), drawn in a DrawList
// with a sun. Frames, each waited for (Finish):
//   mode 0: the shown mesh drawn again (a plain frame);
//   mode 1: a new mesh drawn at once (upload and shadow pass in one frame);
//   mode 2: a new mesh staged (Renderer::Stage, 8 MB and a shadow band a
//           frame) while the shown one is drawn, then shown.
// Counters: the mean and the slowest frame (ms).
void BM_ViewerSwap(benchmark::State& state) {
  const int n = int(state.range(0)), mode = int(state.range(1));
  const int W = 640, H = 360;
  plant::PlantSpec spec;
  spec.path = std::string(SYLVA_SOURCE_DIR) + "/grammars/abop/fig2_06a_monopodial.lsys";
  spec.steps = n;
  spec.until = plant::Stage::kGeometry;
  const mesh::PlantGeometry geometry = std::move(plant::BuildPlant(spec).plant->geometry);
  const mesh::Box box = mesh::TessellatedBounds(geometry, nullptr);
  Gl& gl = Context();
  (void)gl.renderer->Resize(W, H);
  gl.renderer->SetShadowMapSize(2048);
  draw::DrawList lists[2];
  render::Camera cams[2];
  for (int k = 0; k < 2; ++k) {
    cams[k] = render::Camera::Frame(box.lo, box.hi, double(W) / H, 30 + 3 * k, 12, false);
    mesh::TessellateOptions opt;
    opt.view = mesh::ScreenView{cams[k].ViewProjection(double(W) / H), W, H, 0.5};
    opt.view->coverage = true;
    auto m = std::make_shared<mesh::TriangleMesh>();
    (void)mesh::Tessellate(geometry, opt, *m);
    draw::MeshDraw d;
    d.mesh = m;
    d.palette = mesh::DefaultPalette();
    d.instances.push_back({});
    lists[k].meshes.push_back(d);
    lists[k].lights = draw::DefaultLights();
    lists[k].shadowBounds = std::pair{box.lo, box.hi};
  }
  int shown = 0;
  (void)gl.renderer->Draw(lists[shown], cams[shown]);
  gl.renderer->Finish();
  bool staged = false;
  double slowest = 0, sum = 0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    if (mode == 1) {
      shown = 1 - shown;
    } else if (mode == 2) {
      if (staged) {
        shown = 1 - shown;
        staged = false;
      } else {
        staged = gl.renderer->Stage(lists[1 - shown], size_t(8) << 20).value();
      }
    }
    (void)gl.renderer->Draw(lists[shown], cams[shown]);
    gl.renderer->Finish();
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    state.SetIterationTime(s);
    slowest = std::max(slowest, s * 1e3);
    sum += s * 1e3;
  }
  state.counters["slowest_ms"] = slowest;
  state.counters["mean_ms"] = sum / double(state.iterations());
  state.counters["triangles"] = double(lists[0].meshes[0].mesh->triangleCount());
  (void)gl.renderer->Resize(1920, 1080);
  gl.renderer->SetShadowMapSize(render::Renderer::kDefaultShadowMapSize);
}
BENCHMARK(BM_ViewerSwap)
    ->ArgsProduct({{15, 20}, {0, 1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->Iterations(16);

}  // namespace

BENCHMARK_MAIN();
