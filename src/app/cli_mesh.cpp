// sylva mesh: grammar -> derived word -> turtle -> tessellation -> file.
#include <chrono>
#include <cstdio>
#include <ostream>

#include "app/cli.h"
#include "app/commands.h"
#include <filesystem>
#include <set>
#include <unordered_map>

#include "mesh/export.h"
#include "mesh/obj_reader.h"
#include "mesh/tessellator.h"
#include "turtle/interpreter.h"

namespace sylva::app {

std::optional<DrawnPlant> DeriveAndDraw(const DeriveFlags& f, std::ostream& err, int* exit) {
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  auto g = LoadGrammar(f, err, exit);
  if (!g) return std::nullopt;
  const lsys::DeriveOptions opt = DeriveOptionsFrom(f);
  auto derived = lsys::Derive(*g, opt);
  if (!derived) {
    *exit = Report(derived.error(), err);
    return std::nullopt;
  }
  auto word = lsys::Interpret(*g, derived->word, opt);
  if (!word) {
    *exit = Report(word.error(), err);
    return std::nullopt;
  }
  const auto t1 = Clock::now();
  auto geometry = turtle::Interpret(*word, g->symbols, turtle::TurtleDefFrom(*g));
  if (!geometry) {
    *exit = Report(geometry.error(), err);
    return std::nullopt;
  }
  for (const auto& w : geometry->warnings) err << g->path << ": warning: " << w << "\n";
  const auto t2 = Clock::now();
  auto ms = [](auto a, auto b) { return std::chrono::duration<double, std::milli>(b - a).count(); };
  DrawnPlant p{std::move(*g), word->size(), std::move(*geometry), ms(t0, t1), ms(t1, t2)};
  return p;
}

mesh::Palette PaletteOf(const lsys::Grammar& g) {
  if (g.palette.empty()) return mesh::DefaultPalette();
  mesh::Palette p;
  for (const auto& c : g.palette) p.push_back(mesh::Vec3f(c[0], c[1], c[2]));
  return p;
}

bool BuildMesh(const lsys::Grammar& g, const mesh::PlantGeometry& geometry, int sides,
               mesh::TriangleMesh* out, std::ostream& err, int* exit) {
  // Predefined surfaces: NAME.obj beside the grammar, in its surfaces/
  // folder, or in the project's grammars/surfaces/.
  std::unordered_map<std::string, mesh::TriangleMesh> surfaces;
  {
    std::set<std::string> names;
    for (const auto& si : geometry.surfaces) names.insert(si.name);
    const std::filesystem::path dir = std::filesystem::path(g.path).parent_path();
    const std::vector<std::filesystem::path> search = {
        dir, dir / "surfaces", std::filesystem::path(SYLVA_DATA_DIR) / "grammars" / "surfaces"};
    for (const std::string& name : names) {
      std::string found;
      for (const auto& d : search) {
        if (std::filesystem::is_regular_file(d / (name + ".obj"))) {
          found = (d / (name + ".obj")).string();
          break;
        }
      }
      if (found.empty()) {
        // Point at the surface's first use in the grammar.
        Diagnostic d;
        d.loc.file = g.path;
        d.message = "unknown surface '" + name + "': no " + name + ".obj beside the grammar, in " +
                    (dir / "surfaces").string() + " or in the bundled grammars/surfaces";
        if (auto it = g.symbolLoc.find("~" + name); it != g.symbolLoc.end()) {
          d.loc = it->second.loc;
          SetExcerpt(d, g.SourceLine(d.loc));
          d.length = int(name.size()) + 1;
        }
        *exit = Report(d, err);
        return false;
      }
      auto surface = mesh::ReadObj(found);
      if (!surface) {
        *exit = Report(surface.error(), err);
        return false;
      }
      surfaces.emplace(name, std::move(*surface));
    }
  }
  mesh::TessellateOptions topt;
  topt.detail.sides = sides;
  topt.surfaces = &surfaces;
  mesh::TessellateStats stats;
  if (std::string problem = mesh::Tessellate(geometry, topt, *out, &stats); !problem.empty()) {
    err << g.path << ": error: " << problem << "\n";
    *exit = kExitBadInput;
    return false;
  }
  for (const auto& w : stats.warnings) err << g.path << ": warning: " << w << "\n";
  return true;
}

int RunMesh(const MeshCommand& cmd, std::ostream& out, std::ostream& err) {
  using Clock = std::chrono::steady_clock;
  if (!mesh::FormatFromPath(cmd.output)) {
    err << "sylva: error: " << cmd.output
        << ": unknown mesh format; use .obj, .ply, .glb or .gltf\n";
    return kExitBadInput;
  }
  int exit = kExitOk;
  auto plant = DeriveAndDraw(cmd.derive, err, &exit);
  if (!plant) return exit;
  const lsys::Grammar* g = &plant->grammar;
  const mesh::PlantGeometry* geometry = &plant->geometry;
  const auto t2 = Clock::now();
  mesh::TriangleMesh m;
  if (!BuildMesh(*g, *geometry, cmd.sides, &m, err, &exit)) return exit;
  const auto t3 = Clock::now();
  if (Status s = mesh::WriteMesh(m, PaletteOf(*g), cmd.output); !s.ok()) {
    return Report(s.error(), err);
  }
  const auto t4 = Clock::now();
  auto ms = [](auto a, auto b) { return std::chrono::duration<double, std::milli>(b - a).count(); };
  char line[320];
  std::snprintf(line, sizeof line,
                "%s: %zu vertices, %zu triangles, %zu segments, %zu polygons (%llu modules)\n"
                "time: derive %.1f ms, turtle %.1f ms, tessellate %.1f ms, write %.1f ms\n",
                cmd.output.c_str(), m.vertexCount(), m.triangleCount(), geometry->segments.size(),
                geometry->polygons.size(), static_cast<unsigned long long>(plant->modules),
                plant->deriveMs, plant->turtleMs, ms(t2, t3), ms(t3, t4));
  err << line;
  (void)out;
  return kExitOk;
}

}  // namespace sylva::app
