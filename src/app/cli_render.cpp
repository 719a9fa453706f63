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
#include "mesh/export.h"
#include "plant/frames.h"
#include "render/camera.h"
#include "render/headless_context.h"
#include "render/renderer.h"
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

// A cpfg view file's view direction, unless --camera gives one.
void UseViewFileDirection(const ViewFile* view, ViewFlags& v) {
  if (!view || v.explicitCamera) return;
  if (auto dir = ViewDirection(*view)) {
    v.explicitCamera = true;
    v.cam[0] = (*dir)[0];
    v.cam[1] = (*dir)[1];
    v.cam[2] = 0;  // framed
  }
}

// A cpfg file (`.l`) without a view file is viewed as cpfg views it by
// default (interpret.c, InitializeParameters): from viewpoint 0,0,1 toward
// the origin, in parallel projection. Unless --camera says otherwise.
bool UseCpfgDefaultView(const std::string& grammar, const ViewFile* view, ViewFlags& v) {
  if (std::filesystem::path(grammar).extension() != ".l") return false;
  if (view && !view->path.empty()) return false;
  if (v.explicitCamera) return false;
  v.explicitCamera = true;
  v.cam[0] = v.cam[1] = v.cam[2] = 0;
  return true;
}

// cpfg's `scale factor:` zooms the framed view of a parallel projection
// (CalculateWindow: the box's span divided by it). In perspective cpfg
// frames nothing (control.c, SetView): the eye is at vrp + (viewpoint -
// vrp) / scale, looking at the view reference point vrp, with a field of
// view of `viewing angle:` (45 degrees by default), so Sylva places the
// camera there when the view file gives a viewpoint or reference point.
// Otherwise `viewing angle:` is the field of view of the framed camera
// (moved back or forward so the framed box keeps its size: the distance
// times tan(35/2) / tan(a/2)).
void UseViewFileScale(const ViewFile* view, render::Camera& camera) {
  if (view && !view->path.empty() && !view->parallel && !camera.orthographic &&
      (view->viewpoint || view->target)) {
    const Vec3 at = view->target.value_or(Vec3(0, 0, 0));
    const double d =
        (view->viewpoint.value_or(Vec3(0, 0, 1)) - at).norm() / view->scale.value_or(1);
    if (d > 0 && std::isfinite(d)) {
      camera.target = at;
      camera.distance = d;
      camera.fovY = view->viewingAngle.value_or(45);
      return;
    }
  }
  if (view && view->viewingAngle && !camera.orthographic) {
    const double a = *view->viewingAngle;
    camera.distance *= std::tan(camera.fovY * kDegToRad / 2) / std::tan(a * kDegToRad / 2);
    camera.fovY = a;
  }
  if (!view || !view->scale) return;
  if (camera.orthographic)
    camera.orthoHeight /= *view->scale;  // the eye stays outside the plant
  else
    camera.distance /= *view->scale;
}

// The camera that frames the plant, or the one --camera gives. The box
// comes from the geometry, before tessellation, so every detail (uniform
// or screen-space) sees one view. Orthographic for 2D figures (`lines`)
// and when a cpfg view file asks for a parallel projection.
Expected<render::Camera> FrameCamera(const plant::Plant& p, const plant::PlantSpec& spec,
                                     const ViewFlags& v, bool lines, bool orthographic,
                                     mesh::Box* meshBox = nullptr, const ViewFile* view = nullptr) {
  Vec3 lo = p.geometry.boundsMin, hi = p.geometry.boundsMax;
  if (!lines) {
    auto box = plant::MeshBounds(p, spec);
    if (!box) return box.error();
    if (meshBox) *meshBox = *box;
    if ((box->lo.array() <= box->hi.array()).all()) {
      lo = box->lo;
      hi = box->hi;
    }
  }
  // cpfg's `box:` is the view volume a parallel view frames (CalculateWindow).
  if (view && view->box && orthographic) {
    lo = (*view->box)[0];
    hi = (*view->box)[1];
  }
  const double aspect = double(v.width) / v.height;
  render::Camera camera =
      render::Camera::Frame(lo, hi, aspect, v.explicitCamera ? v.cam[0] : (lines ? 0 : 30),
                            v.explicitCamera ? v.cam[1] : (lines ? 0 : 12), orthographic);
  if (v.explicitCamera && v.cam[2] > 0) camera.distance = v.cam[2];
  return camera;
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

// Whether a geometry's widths are pixels and some are wider than the one
// pixel of a line.
bool WiderThanAPixel(const mesh::PlantGeometry& g) {
  if (!g.widthInPixels) return false;
  for (const mesh::Segment& s : g.segments)
    if (std::max(s.radiusStart, s.radiusEnd) > 0.5f + 1e-4f) return true;
  return false;
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
  UseViewFileDirection(viewFile.get(), v);
  const bool cpfgDefaultView = UseCpfgDefaultView(cmd.derive.file, viewFile.get(), v);
  if (cmd.sides) spec->detail.sides = *cmd.sides;
  spec->until = plant::Stage::kGeometry;
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
  const mesh::PlantGeometry* geometry = &plant->geometry;
  const mesh::Palette& palette = plant->palette;
  // 2D figures (all in the z = 0 plane, nothing but segments) draw as lines
  // in an orthographic view from +Z; everything else as a lit mesh. A 2D
  // figure whose widths are pixels (a cpfg view file's line style) draws
  // (some wider than one) as ribbons of those widths, on white like the lines.
  const bool figure = plant::IsLineFigure(*geometry);
  const bool ribbons = figure && WiderThanAPixel(*geometry);
  const bool lines = figure && !ribbons;
  const bool parallel = figure || cpfgDefaultView || (viewFile && viewFile->parallel);
  render::LineBatch batch;
  mesh::Box bounds;
  auto camera = FrameCamera(*plant, *spec, v, figure, parallel, &bounds,
                            cmd.camera.empty() ? viewFile.get() : nullptr);
  if (!camera) return Report(camera.error(), err);
  if (cmd.camera.empty()) UseViewFileScale(viewFile.get(), *camera);
  const int W = v.width * K, H = v.height * K;
  float widestPixels = 0;  // the widest pixel width, in rendered pixels
  if (plant->geometry.widthInPixels) {
    // Pixel widths are output pixels: K of the K-times larger image.
    for (mesh::Segment& s : plant->geometry.segments) {
      s.radiusStart *= float(K);
      s.radiusEnd *= float(K);
      widestPixels = std::max({widestPixels, 2 * s.radiusStart, 2 * s.radiusEnd});
    }
  }
  // The key light (the shadow caster): toward cpfg's light when the view
  // file gives one.
  const Vec3 keyToward =
      viewFile && viewFile->lightToward ? *viewFile->lightToward : render::KeyLightDirection();
  if (lines) {
    draw::Lines figure = LinesOf(*plant);
    batch.points = std::move(figure.points);
    batch.colors = std::move(figure.colors);
  } else {
    // Screen-space detail unless --sides asks for uniform tubes; eps is in
    // output pixels, so K times as many in the K-times larger image.
    if (!cmd.sides || geometry->widthInPixels) {
      // Pixel widths need the view even at uniform detail (mesh/pixel_widths.h).
      spec->view = ViewOf(*camera, W, H, lodEps * K);
      // Shadows of what lies outside the view may fall inside it.
      if (!ribbons) {
        spec->view->shadowFrom = keyToward;
        spec->view->shadowPlaneY = bounds.lo.y();
        spec->view->shadowTexelsPerUnit = render::ShadowTexelsPerUnit(bounds);
      }
      // Twigs under a pixel fade as coverage lines (the renderer blends them).
      spec->view->coverage = true;
      // A 2D figure's pixel-wide lines are flat ribbons, never tubes
      // (ribbons are drawn under 3 eps of radius).
      if (ribbons) spec->view->eps = std::max(spec->view->eps, 0.2 * widestPixels);
    }
    DiagnosticList warnings;
    Status s = plant::Tessellate(*plant, *spec, warnings);
    exit = Report(warnings, err, cmd.derive.maxErrors, cmd.derive.strict);
    if (!s.ok()) return Report(s.error(), err);
    if (exit != kExitOk) return exit;
  }
  const auto m = std::make_shared<const mesh::TriangleMesh>(std::move(plant->mesh));

  auto t0 = Clock::now();
  auto context = render::HeadlessContext::Create();
  if (!context) return Report(context.error(), err);
  auto renderer = render::Renderer::Create(render::FindShaderDir());
  if (!renderer) return Report(renderer.error(), err);
  if (Status s = (*renderer)->Resize(W, H); !s.ok()) return Report(s.error(), err);
  const double contextMs = MsSince(t0);
  t0 = Clock::now();
  draw::DrawList list;
  if (lines) {
    (*renderer)->SetBackground(mesh::Vec3f(1, 1, 1));
    if (Status s = (*renderer)->SetLines(batch); !s.ok()) return Report(s.error(), err);
  } else if (ribbons) {
    (*renderer)->SetBackground(mesh::Vec3f(1, 1, 1));
    (*renderer)->SetShadows(false);
    (*renderer)->SetMesh(*m, palette);
    (*renderer)->SetWireframe(cmd.wireframe);
  } else {
    // The default scene: the plant on a ground plane, lit by the default
    // rig; the shadow map fitted to the whole plant, whatever was culled.
    // No ground when the camera looks from below it (it would hide
    // everything), nor for a cpfg object (a view file, or a `.l` drawn from
    // cpfg's default view): cpfg draws none, and a ground would hide what
    // hangs below the base and fight with a base polygon drawn at it.
    const bool cpfgObject = viewFile || cpfgDefaultView;
    list = scene::DefaultScene(m, palette, bounds.lo, bounds.hi,
                               !cpfgObject && scene::SeesGroundFromAbove(camera->Eye(), bounds.lo));
    if (viewFile && viewFile->lightToward) list.lights[0].direction = -keyToward.cast<float>();
    list.wireframe = cmd.wireframe;
  }
  const double uploadMs = MsSince(t0);
  t0 = Clock::now();
  if (lines || ribbons) {
    (*renderer)->Draw(*camera);
  } else if (Status s = (*renderer)->Draw(list, *camera); !s.ok()) {
    return Report(s.error(), err);
  }
  render::Image image = (*renderer)->ReadPixels();
  const double drawMs = MsSince(t0);
  t0 = Clock::now();
  if (K > 1) image = Downsample(image, K);
  const double downsampleMs = MsSince(t0);
  t0 = Clock::now();
  if (Status s = render::WriteImage(image, cmd.output); !s.ok()) return Report(s.error(), err);
  const double writeMs = MsSince(t0);
  char line[256];
  std::snprintf(line, sizeof line, "%s: %dx%d, %s, %zu triangles, %zu lines (%s)\n",
                cmd.output.c_str(), v.width, v.height,
                lines     ? "lines, orthographic"
                : ribbons ? "pixel-wide ribbons, orthographic"
                          : (parallel ? "mesh, orthographic" : "mesh, perspective"),
                m->triangleCount(), batch.points.size() / 2, (*context)->Renderer().c_str());
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
  UseViewFileDirection(viewFile.get(), v);
  const bool cpfgDefaultView = UseCpfgDefaultView(cmd.derive.file, viewFile.get(), v);
  spec->until = plant::Stage::kGeometry;
  auto plant = BuildPlant(*spec, cmd.derive.maxErrors, err, &exit, cmd.derive.strict);
  if (!plant) return exit;
  // Framed as `sylva render` frames a mesh (never as a line figure).
  auto camera =
      FrameCamera(*plant, *spec, v, false, cpfgDefaultView || (viewFile && viewFile->parallel));
  if (!camera) return Report(camera.error(), err);
  if (cmd.camera.empty()) UseViewFileScale(viewFile.get(), *camera);
  spec->view = ViewOf(*camera, v.width, v.height, eps);
  return TessellateAndWrite(cmd, *plant, *spec, err);
}

}  // namespace sylva::app
