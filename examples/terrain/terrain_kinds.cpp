// The three noise kinds of a scene's <terrain> side by side: fBm, ridged
// multifractal and diamond-square, each 100 x 100 m at 257 x 257 vertices
// and 14 m of amplitude (SCENE.md's defaults otherwise). Each height field
// becomes a TriangleMesh through its plain mesh arrays, coloured by height
// band; the program checks each mesh (mesh::Validate: indices, finite
// values, unit normals, no degenerate triangle) and that the surface
// queries meet the grid, then draws the three through Sylva's renderer.
//
//   terrain_kinds [OUT.png]
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "mesh/color.h"
#include "mesh/triangle_mesh.h"
#include "render/headless_context.h"
#include "render/renderer.h"
#include "terrain/height_field.h"

using namespace sylva;

namespace {

// The height field's arrays as a mesh, shifted by `dx` in x; triangles take
// material 0..3 by the height of their centre (grass, dry grass, rock, snow).
mesh::TriangleMesh ToMesh(const terrain::HeightField& f, const terrain::TerrainMesh& a, float dx) {
  mesh::TriangleMesh m;
  const size_t n = a.positions.size() / 3;
  for (size_t v = 0; v < n; ++v) {
    m.positions.emplace_back(a.positions[3 * v] + dx, a.positions[3 * v + 1],
                             a.positions[3 * v + 2]);
    m.normals.emplace_back(a.normals[3 * v], a.normals[3 * v + 1], a.normals[3 * v + 2]);
    m.uvs.emplace_back(0.0f, 0.0f);
  }
  m.indices = a.indices;
  const float lo = f.minHeight(), span = std::max(1e-6f, f.maxHeight() - f.minHeight());
  for (size_t t = 0; t < m.indices.size(); t += 3) {
    const float y = (m.positions[m.indices[t]].y() + m.positions[m.indices[t + 1]].y() +
                     m.positions[m.indices[t + 2]].y()) /
                    3;
    const float s = (y - lo) / span;
    m.material.push_back(uint16_t(s < 0.45f ? 0 : s < 0.65f ? 1 : s < 0.85f ? 2 : 3));
  }
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  const char* out = argc > 1 ? argv[1] : "out/terrain_kinds.png";
  const terrain::NoiseKind kinds[3] = {terrain::NoiseKind::kFbm, terrain::NoiseKind::kRidged,
                                       terrain::NoiseKind::kDiamondSquare};
  mesh::TriangleMesh all;
  bool ok = true;
  for (int k = 0; k < 3; ++k) {
    terrain::TerrainDef def;
    def.noise = kinds[k];
    def.height = 14;
    def.seed = 3;
    def.gain = kinds[k] == terrain::NoiseKind::kDiamondSquare ? 0.62 : 0.5;
    auto f = terrain::HeightField::Create(def);
    if (!f) {
      std::fputs(f.error().Format().c_str(), stderr);
      return 1;
    }
    auto arrays = f->MakeMesh();
    if (!arrays) {
      std::fputs(arrays.error().Format().c_str(), stderr);
      return 1;
    }
    const mesh::TriangleMesh m = ToMesh(*f, *arrays, float(110 * (k - 1)));
    const std::string problem = mesh::Validate(m);
    double worst = 0;
    for (int j = 0; j < f->resolution(); j += 8) {
      for (int i = 0; i < f->resolution(); i += 8) {
        worst = std::max(
            worst, std::fabs(f->Height(f->VertexX(i), f->VertexZ(j)) - double(f->HeightAt(i, j))));
      }
    }
    std::printf("%-14s heights %6.2f .. %5.2f m, %zu triangles, surface vs grid %.1e m%s%s\n",
                terrain::NameOf(kinds[k]), double(f->minHeight()), double(f->maxHeight()),
                m.triangleCount(), worst,
                problem.empty() ? "" : ", invalid mesh: ", problem.c_str());
    ok = ok && problem.empty() && worst < 1e-9;
    all.Append(m);
  }

  auto context = render::HeadlessContext::Create();
  if (!context) {
    std::fprintf(stderr, "no OpenGL (%s): skipping the picture\n", context.error().message.c_str());
    return ok ? 0 : 1;
  }
  auto renderer = render::Renderer::Create(render::FindShaderDir());
  if (!renderer || !(*renderer)->Resize(960, 300).ok()) return 1;
  const mesh::Palette palette = {mesh::Srgb(0.36f, 0.52f, 0.24f), mesh::Srgb(0.58f, 0.58f, 0.32f),
                                 mesh::Srgb(0.52f, 0.47f, 0.42f), mesh::Srgb(0.93f, 0.94f, 0.96f)};
  (*renderer)->SetBackground(mesh::Srgb(0.72f, 0.82f, 0.93f));
  (*renderer)->SetMesh(all, palette);
  (*renderer)->Draw(
      render::Camera::Frame(Vec3(-160, -8, -45), Vec3(160, 8, 45), 960.0 / 300, 0, 40, false));
  if (std::error_code ec; !std::filesystem::path(out).parent_path().empty()) {
    std::filesystem::create_directories(std::filesystem::path(out).parent_path(), ec);
  }
  if (Status s = render::WritePng((*renderer)->ReadPixels(), out); !s.ok()) {
    std::fputs(s.error().Format().c_str(), stderr);
    return 1;
  }
  std::printf("wrote %s\n", out);
  return ok ? 0 : 1;
}
