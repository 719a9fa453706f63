// sylva render: grammar -> mesh or lines -> headless OpenGL -> PNG.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ostream>

#include "app/cli.h"
#include "app/commands.h"
#include "render/camera.h"
#include "render/headless_context.h"
#include "render/renderer.h"

namespace sylva::app {

static bool ParseSize(const std::string& s, int* w, int* h) {
  int n = 0;
  if (std::sscanf(s.c_str(), "%dx%d%n", w, h, &n) != 2 || size_t(n) != s.size()) return false;
  return *w >= 1 && *h >= 1 && *w <= 8192 && *h <= 8192;
}

static bool ParseCamera(const std::string& s, double v[3]) {
  int n = 0;
  if (std::sscanf(s.c_str(), "%lf,%lf,%lf%n", &v[0], &v[1], &v[2], &n) != 3 ||
      size_t(n) != s.size())
    return false;
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]) && v[2] >= 0 &&
         v[1] > -90 && v[1] < 90;
}

int RunRender(const RenderCommand& cmd, std::ostream& out, std::ostream& err) {
  if (!render::IsImagePath(cmd.output)) {
    err << "sylva: error: " << cmd.output << ": unknown image format; use .png, .jpg or .jpeg\n";
    return kExitBadInput;
  }
  int width = 0, height = 0;
  if (!ParseSize(cmd.size, &width, &height)) {
    err << "sylva: error: --size '" << cmd.size << "': expected WxH from 1x1 to 8192x8192\n";
    return kExitBadInput;
  }
  double cam[3] = {0, 0, 0};
  const bool explicitCamera = !cmd.camera.empty();
  if (explicitCamera && !ParseCamera(cmd.camera, cam)) {
    err << "sylva: error: --camera '" << cmd.camera
        << "': expected azimuth,elevation,distance as finite numbers, elevation in (-90, 90), "
           "distance >= 0\n";
    return kExitBadInput;
  }
  int exit = kExitOk;
  auto spec = SpecFrom(cmd.derive, err, &exit);
  if (!spec) return exit;
  spec->detail.sides = cmd.sides;
  spec->until = plant::Stage::kGeometry;
  auto plant = BuildPlant(*spec, cmd.derive.maxErrors, err, &exit);
  if (!plant) return exit;
  const mesh::PlantGeometry* geometry = &plant->geometry;
  const mesh::Palette& palette = plant->palette;
  // 2D figures (all in the z = 0 plane, nothing but segments) draw as lines
  // in an orthographic view from +Z; everything else as a lit mesh.
  const bool lines = plant::IsLineFigure(*geometry);
  const mesh::TriangleMesh& m = plant->mesh;
  render::LineBatch batch;
  Vec3 lo = geometry->boundsMin, hi = geometry->boundsMax;
  if (lines) {
    const float lineShade = plant->grammar.palette.empty() ? std::pow(0.6f, 2.2f) : 1.0f;
    for (const auto& s : geometry->segments) {
      // A grammar's own palette is drawn as written; the default palette is
      // darkened (to 0.6 of its sRGB value) so lines read on white.
      const mesh::Vec3f c =
          palette.empty() ? mesh::Vec3f(0, 0, 0) : palette[s.color % palette.size()] * lineShade;
      batch.points.push_back(s.start.cast<float>());
      batch.points.push_back(s.end.cast<float>());
      batch.colors.push_back(c);
      batch.colors.push_back(c);
    }
  } else {
    DiagnosticList warnings;
    Status s = plant::Tessellate(*plant, *spec, warnings);
    exit = Report(warnings, err, cmd.derive.maxErrors);
    if (!s.ok()) return Report(s.error(), err);
    if (m.vertexCount()) {
      lo = hi = m.positions[0].cast<double>();
      for (const auto& p : m.positions) {
        lo = lo.cwiseMin(p.cast<double>());
        hi = hi.cwiseMax(p.cast<double>());
      }
      // Frame the ground disc the renderer puts under the plant too.
      const double r = 0.55 * (hi - lo).norm();
      const Vec3 c((lo.x() + hi.x()) / 2, lo.y(), (lo.z() + hi.z()) / 2);
      lo = lo.cwiseMin(c - Vec3(r, 0, r));
      hi = hi.cwiseMax(c + Vec3(r, 0, r));
    }
  }
  const double aspect = double(width) / height;
  render::Camera camera =
      render::Camera::Frame(lo, hi, aspect, explicitCamera ? cam[0] : (lines ? 0 : 30),
                            explicitCamera ? cam[1] : (lines ? 0 : 12), lines);
  if (explicitCamera && cam[2] > 0) camera.distance = cam[2];

  auto context = render::HeadlessContext::Create();
  if (!context) return Report(context.error(), err);
  auto renderer = render::Renderer::Create(render::FindShaderDir());
  if (!renderer) return Report(renderer.error(), err);
  if (Status s = (*renderer)->Resize(width, height); !s.ok()) return Report(s.error(), err);
  if (lines) {
    (*renderer)->SetBackground(mesh::Vec3f(1, 1, 1));
    if (Status s = (*renderer)->SetLines(batch); !s.ok()) return Report(s.error(), err);
  } else {
    (*renderer)->SetGround(true);
    (*renderer)->SetMesh(m, palette);
  }
  (*renderer)->Draw(camera);
  const render::Image image = (*renderer)->ReadPixels();
  if (Status s = render::WriteImage(image, cmd.output); !s.ok()) return Report(s.error(), err);
  char line[256];
  std::snprintf(line, sizeof line, "%s: %dx%d, %s, %zu triangles, %zu lines (%s)\n",
                cmd.output.c_str(), width, height,
                lines ? "lines, orthographic" : "mesh, perspective", m.triangleCount(),
                batch.points.size() / 2, (*context)->Renderer().c_str());
  err << line;
  (void)out;
  return kExitOk;
}

}  // namespace sylva::app
