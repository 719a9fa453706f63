// sylva render scene.xml: read the scene, build its terrain, plants and
// forests, describe the frame as a DrawList and render it headless.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <ostream>

#include "app/cli.h"
#include "app/commands.h"
#include "app/scene_camera.h"
#include "core/parallel.h"
#include "render/camera.h"
#include "render/headless_context.h"
#include "render/renderer.h"
#include "scene/build.h"
#include "scene/simulation.h"

namespace sylva::app {

// cli_render.cpp: the screen view of a camera, for screen-space detail.
mesh::ScreenView ViewOf(const render::Camera& camera, int width, int height, double eps);

// An image path (.png, .jpg) and a size WxH for it, or exit 2 saying which.
static int CheckPicture(const std::string& output, const std::string& size, int* width, int* height,
                        std::ostream& err) {
  if (!render::IsImagePath(output)) {
    err << "sylva: error: " << output << ": unknown image format; use .png, .jpg or .jpeg\n";
    return kExitBadInput;
  }
  if (!ParseSize(size, width, height)) {
    err << "sylva: error: --size '" << size << "': expected WxH from 1x1 to 8192x8192\n";
    return kExitBadInput;
  }
  return kExitOk;
}

int RunRenderScene(const RenderCommand& cmd, std::ostream& out, std::ostream& err) {
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  int width = 0, height = 0;
  if (int e = CheckPicture(cmd.output, cmd.size, &width, &height, err); e != kExitOk) return e;
  if (!cmd.camera.empty()) {
    err << "sylva: error: --camera is for grammars; a scene sets its view with <camera>\n";
    return kExitBadInput;
  }
  if (cmd.supersample != 1 || cmd.wireframe) {
    err << "sylva: error: --supersample and --wireframe are for grammars\n";
    return kExitBadInput;
  }
  if (cmd.lodEps && cmd.sides) {
    err << "sylva: error: --lod-eps and --sides exclude each other (--sides turns screen-space "
           "detail off)\n";
    return kExitBadInput;
  }
  const double lodEps = cmd.lodEps.value_or(0.5);
  if (!(lodEps > 0) || !std::isfinite(lodEps)) {
    err << "sylva: error: --lod-eps must be a number above 0\n";
    return kExitBadInput;
  }
  if (cmd.derive.steps || cmd.derive.seed) {
    err << "sylva: error: -n and --seed are for grammars; a scene sets them on <plant> and "
           "<forest>\n";
    return kExitBadInput;
  }
  int exit = kExitOk;
  // Uniform tubes for what collides (the same whatever the camera); the
  // picture gets screen-space detail below unless --sides is given.
  const auto run = StartScene({cmd.derive.file, cmd.derive.defines, cmd.derive.maxErrors,
                               cmd.derive.strict, cmd.derive.threads, cmd.sides.value_or(8)},
                              err, &exit);
  if (!run) return exit;
  const scene::Scene* const scene = &run->scene;
  scene::BuiltScene* const built = &run->built;
  scene::Simulation* const sim = run->simulation.get();
  const auto t1 = Clock::now();
  if (Status s = sim->AdvanceTo(cmd.time); !s.ok()) return Report(s.error(), err);
  const auto t2 = Clock::now();

  const render::Camera camera = SceneCamera(*scene, *built, double(width) / height);
  size_t staticTriangles = built->trianglesDrawn;
  if (!cmd.sides) {
    DiagnosticList detailWarnings;
    mesh::ScreenView view = ViewOf(camera, width, height, lodEps);
    // Twigs under a pixel fade as coverage lines, leaves under a pixel as
    // points (the DrawList pipeline blends them), as for a grammar.
    view.coverage = true;
    auto drawn = scene::DetailForView(*built, view, detailWarnings);
    exit = Report(detailWarnings, err, cmd.derive.maxErrors, cmd.derive.strict);
    if (exit != kExitOk) return exit;
    if (!drawn) return Report(drawn.error(), err);
    staticTriangles = *drawn;
  }
  const auto t2b = Clock::now();
  draw::DrawList list = scene::MakeDrawList(*scene, *built);
  sim->AddToDrawList(list);
  auto context = render::HeadlessContext::Create();
  if (!context) return Report(context.error(), err);
  auto renderer = render::Renderer::Create(render::FindShaderDir());
  if (!renderer) return Report(renderer.error(), err);
  if (Status s = (*renderer)->Resize(width, height); !s.ok()) return Report(s.error(), err);
  if (Status s = (*renderer)->Draw(list, camera); !s.ok()) return Report(s.error(), err);
  const render::Image image = (*renderer)->ReadPixels();
  if (Status s = render::WriteImage(image, cmd.output); !s.ok()) return Report(s.error(), err);
  const auto t3 = Clock::now();
  auto seconds = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); };
  char line[480];
  std::snprintf(line, sizeof line,
                "%s: %dx%d at t = %.3f s, %zu meshes, %zu static triangles drawn (%s), %zu "
                "simulated points; build %.2f s, simulate %.2f s, detail %.2f s, render %.2f s "
                "(%s)\n",
                cmd.output.c_str(), width, height, sim->time(), list.meshes.size(), staticTriangles,
                cmd.sides ? "uniform sides" : "screen-space detail", sim->Count(), seconds(t0, t1),
                seconds(t1, t2), seconds(t2, t2b), seconds(t2b, t3),
                (*context)->Renderer().c_str());
  if (cmd.stats) {
    std::snprintf(line, sizeof line,
                  "triangles: %zu\nbuild: %.1f ms\nsimulate: %.1f ms\ndetail: %.1f ms\nrender: "
                  "%.1f ms\n",
                  staticTriangles, 1e3 * seconds(t0, t1), 1e3 * seconds(t1, t2),
                  1e3 * seconds(t2, t2b), 1e3 * seconds(t2b, t3));
    out << line;
  }
  if (!cmd.stats) err << line;
  return kExitOk;
}

int RunSimulateWithFrames(const SimulateCommand& cmd, std::ostream& out, std::ostream& err) {
  if (cmd.output.empty()) return RunSimulate(cmd, out, err, {});
  int width = 0, height = 0;
  if (int e = CheckPicture(cmd.output, cmd.size, &width, &height, err); e != kExitOk) return e;
  // The context and renderer are made at the first frame, after the scene
  // has loaded (a bad scene fails without touching OpenGL).
  std::unique_ptr<render::HeadlessContext> context;
  std::unique_ptr<render::Renderer> renderer;
  std::optional<render::Camera> camera;
  const FrameWriter write = [&](const SimulationFrame& f, const std::string& path) -> Status {
    if (!renderer) {
      auto c = render::HeadlessContext::Create();
      if (!c) return c.error();
      context = std::move(*c);
      auto r = render::Renderer::Create(render::FindShaderDir());
      if (!r) return r.error();
      renderer = std::move(*r);
      if (Status s = renderer->Resize(width, height); !s.ok()) return s;
      camera = SceneCamera(f.scene, f.built, double(width) / height);
    }
    draw::DrawList list = scene::MakeDrawList(f.scene, f.built);
    f.simulation.AddToDrawList(list);
    if (Status s = renderer->Draw(list, *camera); !s.ok()) return s;
    // Each frame's folder is made on demand (frames/%04d.png into frames/).
    const size_t slash = path.rfind('/');
    if (slash != std::string::npos && slash > 0) {
      std::error_code ec;
      std::filesystem::create_directories(path.substr(0, slash), ec);
    }
    return render::WriteImage(renderer->ReadPixels(), path);
  };
  return RunSimulate(cmd, out, err, write);
}

}  // namespace sylva::app
