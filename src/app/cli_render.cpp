// sylva render: grammar -> mesh or lines -> headless OpenGL -> PNG.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <ostream>

#include "app/cli.h"
#include "app/commands.h"
#include "app/plant_view.h"
#include "mesh/color.h"
#include "mesh/export.h"
#include "plant/frames.h"
#include "render/camera.h"
#include "render/headless_context.h"
#include "render/renderer.h"
#include "render/text.h"
#include "scene/default_scene.h"

namespace sylva::app {

bool ParseSize(const std::string& s, int* w, int* h) {
  int n = 0;
  if (std::sscanf(s.c_str(), "%dx%d%n", w, h, &n) != 2 || size_t(n) != s.size()) return false;
  return *w >= 1 && *h >= 1 && *w <= 8192 && *h <= 8192;
}

bool ParseCamera(const std::string& s, double v[3]) {
  int n = 0;
  if (std::sscanf(s.c_str(), "%lf,%lf,%lf%n", &v[0], &v[1], &v[2], &n) != 3 ||
      size_t(n) != s.size())
    return false;
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]) && v[2] >= 0 &&
         v[1] > -90 && v[1] < 90;
}

namespace {

using Clock = std::chrono::steady_clock;

double MsSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// The view flags of render and mesh --lod-eps, parsed.
struct ViewFlags {
  int width = 0, height = 0;
  bool explicitCamera = false;
  double cam[3] = {0, 0, 0};
};

int ParseView(const std::string& size, const std::string& camera, ViewFlags& v, std::ostream& err) {
  if (!ParseSize(size, &v.width, &v.height)) {
    err << "sylva: error: --size '" << size << "': expected WxH from 1x1 to 8192x8192\n";
    return kExitBadInput;
  }
  v.explicitCamera = !camera.empty();
  if (v.explicitCamera && !ParseCamera(camera, v.cam)) {
    err << "sylva: error: --camera '" << camera
        << "': expected azimuth,elevation,distance as finite numbers, elevation in (-90, 90), "
           "distance >= 0\n";
    return kExitBadInput;
  }
  return kExitOk;
}

// Box filter of K x K pixel blocks, averaged in linear light (sRGB decoded
// and encoded again), alpha linearly.
render::Image Downsample(const render::Image& big, int k) {
  float toLinear[256];
  for (int i = 0; i < 256; ++i) {
    const float c = float(i) / 255.0f;
    toLinear[i] = c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
  }
  auto toSrgb = [](float l) {
    const float c = l <= 0.0031308f ? l * 12.92f : 1.055f * std::pow(l, 1 / 2.4f) - 0.055f;
    return uint8_t(std::clamp(c * 255.0f + 0.5f, 0.0f, 255.0f));
  };
  render::Image out;
  out.width = big.width / k;
  out.height = big.height / k;
  out.rgba.resize(size_t(out.width) * size_t(out.height) * 4);
  const float inv = 1.0f / float(k * k);
  for (int y = 0; y < out.height; ++y) {
    for (int x = 0; x < out.width; ++x) {
      float sum[4] = {0, 0, 0, 0};
      for (int dy = 0; dy < k; ++dy) {
        for (int dx = 0; dx < k; ++dx) {
          const uint8_t* p = big.Pixel(x * k + dx, y * k + dy);
          for (int c = 0; c < 3; ++c) sum[c] += toLinear[p[c]];
          sum[3] += float(p[3]);
        }
      }
      uint8_t* q = &out.rgba[4 * (size_t(y) * size_t(out.width) + size_t(x))];
      for (int c = 0; c < 3; ++c) q[c] = toSrgb(sum[c] * inv);
      q[3] = uint8_t(std::clamp(sum[3] * inv + 0.5f, 0.0f, 255.0f));
    }
  }
  return out;
}

}  // namespace

draw::Lines LinesOf(const plant::Plant& plant) {
  draw::Lines out;
  const mesh::Palette& palette = plant.palette;
  const float lineShade = plant.grammar.palette.empty() ? std::pow(0.6f, 2.2f) : 1.0f;
  for (const auto& s : plant.geometry.segments) {
    // A grammar's own palette is drawn as written; the default palette is
    // darkened (to 0.6 of its sRGB value) so lines read on white.
    const mesh::Vec3f c =
        palette.empty() ? mesh::Vec3f(0, 0, 0) : palette[s.color % palette.size()] * lineShade;
    out.points.push_back(s.start.cast<float>());
    out.points.push_back(s.end.cast<float>());
    out.colors.push_back(c);
    out.colors.push_back(c);
  }
  return out;
}

mesh::ScreenView ViewOf(const render::Camera& camera, int width, int height, double eps) {
  mesh::ScreenView view;
  view.viewProjection = camera.ViewProjection(double(width) / height);
  view.width = width;
  view.height = height;
  view.eps = eps;
  return view;
}

int RunRender(const RenderCommand& cmd, std::ostream& out, std::ostream& err) {
  const auto tStart = Clock::now();
  if (IsSceneFile(cmd.derive.file)) return RunRenderScene(cmd, out, err);
  if (!render::IsImagePath(cmd.output)) {
    err << "sylva: error: " << cmd.output << ": unknown image format; use .png, .jpg or .jpeg\n";
    return kExitBadInput;
  }
  ViewFlags v;
  if (int e = ParseView(cmd.size, cmd.camera, v, err); e != kExitOk) return e;
  const int K = cmd.supersample;
  if (K < 1 || K > 8 || v.width * K > 8192 || v.height * K > 8192) {
    err << "sylva: error: --supersample " << K << " with --size " << cmd.size
        << ": the rendered image may be at most 8192x8192 (K from 1 to 8)\n";
    return kExitBadInput;
  }
  const double lodEps = cmd.lodEps.value_or(0.5);
  if (!(lodEps > 0) || !std::isfinite(lodEps)) {
    err << "sylva: error: --lod-eps must be a positive number of pixels\n";
    return kExitBadInput;
  }
  int exit = kExitOk;
  std::shared_ptr<const ViewFile> viewFile;
  auto spec = SpecFrom(cmd.derive, err, &exit, &viewFile);
  if (!spec) return exit;
  if (cmd.sides) spec->detail.sides = *cmd.sides;
  spec->until = plant::Stage::kGeometry;
  spec->draw.drawsLabels = true;  // cpfg's @L: written over the picture below
  auto plant = BuildPlant(*spec, cmd.derive.maxErrors, err, &exit, cmd.derive.strict);
  if (!plant) return exit;
  if (viewFile && viewFile->overlay) {
    // cpfg's animation file says to draw its frames over each other: the
    // picture is their union (plant/frames.h). The grammar's warnings were
    // reported above; this second pass reports its errors only.
    DiagnosticList again;
    auto frames = plant::DrawFrames(*spec, *viewFile->overlay, again);
    if (!frames) return Report(frames.error(), err);
    plant->geometry = std::move(*frames);
  }
  // The look, projection, direction, framing and lights the viewer starts
  // from too (app/plant_view.h).
  const PlantView view = ChoosePlantView(cmd.derive.file, viewFile.get(), &plant->geometry,
                                         v.explicitCamera ? v.cam : nullptr);
  const bool lines = view.look == PlantLook::kLines;
  const bool ribbons = view.look == PlantLook::kRibbons;
  auto bounds = FramedBox(view, *plant, *spec);
  if (!bounds) return Report(bounds.error(), err);
  const render::Camera camera = FramePlant(view, *bounds, double(v.width) / v.height);
  // cpfg's own camera may look away from the plant: an empty picture is
  // said, not written silently.
  if (auto unseen = UnseenPlantWarning(view, viewFile.get(), camera, double(v.width) / v.height,
                                       *bounds, plant->geometry)) {
    DiagnosticList warnings;
    warnings.Add(*unseen);
    exit = Report(warnings, err, cmd.derive.maxErrors, cmd.derive.strict);
    if (exit != kExitOk) return exit;
  }
  const int W = v.width * K, H = v.height * K;
  if (plant->geometry.widthInPixels) {
    // Pixel widths are output pixels: K of the K-times larger image.
    for (mesh::Segment& s : plant->geometry.segments) {
      s.radiusStart *= float(K);
      s.radiusEnd *= float(K);
    }
  }
  draw::Lines figure;
  if (lines) {
    figure = LinesOf(*plant);
  } else {
    // Screen-space detail unless --sides asks for uniform tubes; eps is in
    // output pixels, so K times as many in the K-times larger image.
    // Pixel widths need the view even at uniform detail (mesh/pixel_widths.h).
    if (!cmd.sides || plant->geometry.widthInPixels)
      spec->view = ScreenViewFor(view, camera, W, H, lodEps * K, *bounds, 1.0, plant->geometry);
    DiagnosticList warnings;
    Status s = plant::Tessellate(*plant, *spec, warnings);
    exit = Report(warnings, err, cmd.derive.maxErrors, cmd.derive.strict);
    if (!s.ok()) return Report(s.error(), err);
    if (exit != kExitOk) return exit;
  }
  const size_t lineCount = figure.points.size() / 2;
  const auto m = std::make_shared<const mesh::TriangleMesh>(std::move(plant->mesh));

  auto t0 = Clock::now();
  auto context = render::HeadlessContext::Create();
  if (!context) return Report(context.error(), err);
  auto renderer = render::Renderer::Create(render::FindShaderDir());
  if (!renderer) return Report(renderer.error(), err);
  if (Status s = (*renderer)->Resize(W, H); !s.ok()) return Report(s.error(), err);
  const double contextMs = MsSince(t0);
  t0 = Clock::now();
  draw::DrawList list = PlantScene(view, m, plant->palette, std::move(figure), *bounds, camera);
  list.wireframe = cmd.wireframe;
  const double uploadMs = MsSince(t0);
  t0 = Clock::now();
  if (Status s = (*renderer)->Draw(list, camera); !s.ok()) return Report(s.error(), err);
  render::Image image = (*renderer)->ReadPixels();
  const double drawMs = MsSince(t0);
  t0 = Clock::now();
  if (K > 1) image = Downsample(image, K);
  // cpfg's labels (@L, iGlLabel): the text's baseline starts where the
  // turtle's position falls on the screen, in the turtle's colour, over
  // the picture (cpfg draws them without depth test as bitmap text).
  if (!plant->geometry.labels.empty()) {
    const Mat4 vp = camera.ViewProjection(double(v.width) / v.height);
    const int scale = std::max(1, v.height / 300);
    for (const mesh::Label& label : plant->geometry.labels) {
      const Vec4 c = vp * Vec4(label.position.x(), label.position.y(), label.position.z(), 1.0);
      if (!(c.w() > 0)) continue;  // behind the eye
      const Vec2 px = render::ToPixel(vp, label.position, v.width, v.height);
      const Vec3f color = label.color < plant->palette.size()
                              ? mesh::ToSrgb(plant->palette[label.color])
                              : Vec3f(0, 0, 0);
      render::DrawText(image, px.x(), px.y(), label.text, color, scale);
    }
  }
  const double downsampleMs = MsSince(t0);
  t0 = Clock::now();
  if (Status s = render::WriteImage(image, cmd.output); !s.ok()) return Report(s.error(), err);
  const double writeMs = MsSince(t0);
  char line[256];
  std::snprintf(line, sizeof line, "%s: %dx%d, %s, %zu triangles, %zu lines (%s)\n",
                cmd.output.c_str(), v.width, v.height,
                lines     ? "lines, orthographic"
                : ribbons ? "pixel-wide ribbons, orthographic"
                          : (view.orthographic ? "mesh, orthographic" : "mesh, perspective"),
                m->triangleCount(), lineCount, (*context)->Renderer().c_str());
  err << line;
  if (cmd.stats) {
    const plant::Timings& t = plant->time;
    const std::string detail =
        lines ? "lines"
              : (cmd.sides ? "uniform " + std::to_string(*cmd.sides) + " sides" : "screen-space");
    char buf[1024];
    std::snprintf(buf, sizeof buf,
                  "triangles: %zu\n"
                  "detail: %s\n"
                  "parse: %.1f ms\nderive: %.1f ms\ninterpret: %.1f ms\nturtle: %.1f ms\n"
                  "tessellate: %.1f ms\ncontext: %.1f ms\nupload: %.1f ms\ndraw: %.1f ms\n"
                  "downsample: %.1f ms\nwrite: %.1f ms\ntotal: %.1f ms\n",
                  m->triangleCount(), detail.c_str(), t.parse, t.derive, t.interpret, t.turtle,
                  t.tessellate, contextMs, uploadMs, drawMs, downsampleMs, writeMs,
                  MsSince(tStart));
    out << buf;
  }
  return exit;
}

int RunMeshForView(const MeshCommand& cmd, std::ostream& out, std::ostream& err) {
  (void)out;
  if (IsSceneFile(cmd.derive.file)) {
    err << "sylva: error: --lod-eps is for grammars; a scene is written at uniform --sides (its "
           "screen-space detail is not implemented yet)\n";
    return kExitBadInput;
  }
  if (!mesh::FormatFromPath(cmd.output)) {
    err << "sylva: error: " << cmd.output
        << ": unknown mesh format; use .obj, .ply, .glb or .gltf\n";
    return kExitBadInput;
  }
  ViewFlags v;
  if (int e = ParseView(cmd.size, cmd.camera, v, err); e != kExitOk) return e;
  const double eps = cmd.lodEps.value_or(0.5);
  if (!(eps > 0) || !std::isfinite(eps)) {
    err << "sylva: error: --lod-eps must be a positive number of pixels\n";
    return kExitBadInput;
  }
  int exit = kExitOk;
  std::shared_ptr<const ViewFile> viewFile;
  auto spec = SpecFrom(cmd.derive, err, &exit, &viewFile);
  if (!spec) return exit;
  spec->until = plant::Stage::kGeometry;
  auto plant = BuildPlant(*spec, cmd.derive.maxErrors, err, &exit, cmd.derive.strict);
  if (!plant) return exit;
  // Framed as `sylva render` frames a mesh (never as a line figure).
  const PlantView view =
      ChoosePlantView(cmd.derive.file, viewFile.get(), nullptr, v.explicitCamera ? v.cam : nullptr);
  auto bounds = FramedBox(view, *plant, *spec);
  if (!bounds) return Report(bounds.error(), err);
  const render::Camera camera = FramePlant(view, *bounds, double(v.width) / v.height);
  spec->view = ViewOf(camera, v.width, v.height, eps);
  return TessellateAndWrite(cmd, *plant, *spec, err);
}

}  // namespace sylva::app
