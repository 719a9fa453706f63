// A flag in the wind (Angel & Shreiner 9.3: a rectangular mesh of particles
// tied to its neighbours, under gravity and wind): XPBD cloth pinned along
// one edge. Runs headless, prints what it did, and draws the last frame as
// a lit mesh.
//
//   particles_flag [SECONDS] [OUT.png]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "draw/convert.h"
#include "particles/cloth.h"
#include "render/headless_context.h"
#include "render/renderer.h"
#include "scene/default_scene.h"

using namespace sylva;

int main(int argc, char** argv) {
  const double seconds = argc > 1 ? std::atof(argv[1]) : 3.0;
  const char* out = argc > 2 ? argv[2] : "out/particles_flag.png";
  if (!(seconds > 0)) {
    std::fprintf(stderr, "usage: particles_flag [SECONDS > 0] [OUT.png]\n");
    return 2;
  }
  particles::ClothDef def;
  def.columns = 30;
  def.rows = 20;
  def.origin = Vec3(0, 2, 0);
  def.u = Vec3(1.5, 0, 0);
  def.v = Vec3(0, -1, 0);
  def.mass = 0.3;
  def.stretchCompliance = 1e-6;
  def.shearCompliance = 1e-4;
  def.bendCompliance = 5e-2;
  def.windDrag = 2.0;  // with equal lift: the pressure on a flat plate
  def.windLift = 2.0;
  def.windFriction = 0.05;
  def.damping = 0.2;
  def.substeps = 40;
  def.iterations = 4;
  for (int r = 0; r < def.rows; ++r) def.pinned.push_back(r * def.columns);  // the pole side
  auto made = particles::Cloth::Create(def);
  if (!made) {
    std::fputs(made.error().Format().c_str(), stderr);
    return 1;
  }
  particles::Cloth& flag = **made;
  const double h = 1.0 / 60;
  for (int i = 0; i * h < seconds; ++i) {
    const double gust = 1 + 0.4 * std::sin(2.1 * i * h) + 0.2 * std::sin(5.3 * i * h);
    const Status st =
        flag.Step(h, Vec3(0, -9.81, 0), Vec3(7 * gust, 0, 1.5 * std::sin(1.3 * i * h)));
    if (!st.ok()) {
      std::fputs(st.error().Format().c_str(), stderr);
      return 1;
    }
  }
  double stretch = 0;
  for (const auto& c : flag.constraints()) {
    if (c.compliance != def.stretchCompliance) continue;
    stretch =
        std::max(stretch, (flag.positions()[c.a] - flag.positions()[c.b]).norm() / c.rest - 1);
  }
  const Vec3 tip = flag.positions()[size_t(flag.Index(def.columns - 1, def.rows - 1))];
  std::printf(
      "%.1f s of wind: %zu particles, %zu triangles, largest stretch %.3f%%, free corner at (%.2f, "
      "%.2f, %.2f)\n",
      seconds, flag.positions().size(), flag.triangles().size(), 100 * stretch, tip.x(), tip.y(),
      tip.z());

  auto context = render::HeadlessContext::Create();
  if (!context) {
    std::fprintf(stderr, "no OpenGL (%s): skipping the picture\n", context.error().message.c_str());
    return 0;
  }
  auto renderer = render::Renderer::Create(render::FindShaderDir());
  if (!renderer || !(*renderer)->Resize(480, 360).ok()) return 1;
  // The cloth's triangles as a mesh: smooth normals, striped colours.
  std::vector<uint16_t> stripes;
  for (const auto& t : flag.triangles()) {
    const int row = int(t[0]) / def.columns;
    stripes.push_back(uint16_t((row * 3 / def.rows) % 2 == 0 ? 7 : 5));  // red and white
  }
  auto m = draw::SheetMesh(flag.positions(), flag.triangles(), stripes);
  if (!m) {
    std::fputs(m.error().Format().c_str(), stderr);
    return 1;
  }
  const auto& x = flag.positions();
  // The pole: a thin column of the mesh's own palette colour 0.
  Vec3 lo = x[0], hi = x[0];
  for (const Vec3& p : x) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  // The default scene (a ground plane, the default lights) under the flag.
  const draw::DrawList list = scene::DefaultScene(
      std::make_shared<const mesh::TriangleMesh>(std::move(*m)), mesh::DefaultPalette(), lo, hi);
  if (Status s = (*renderer)->Draw(list, render::Camera::Frame(lo, hi, 480.0 / 360, 25, 15, false));
      !s.ok()) {
    std::fprintf(stderr, "%s", s.error().Format().c_str());
    return 1;
  }
  if (std::error_code ec; !std::filesystem::path(out).parent_path().empty()) {
    std::filesystem::create_directories(std::filesystem::path(out).parent_path(),
                                        ec);  // out/ by default
  }
  if (Status s = render::WritePng((*renderer)->ReadPixels(), out); !s.ok()) {
    std::fprintf(stderr, "%s", s.error().Format().c_str());
    return 1;
  }
  std::printf("wrote %s\n", out);
  return stretch < 0.02 ? 0 : 1;  // a flag, not a rubber sheet
}
