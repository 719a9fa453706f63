// sylva mesh scene.xml: the scene built and simulated to --time, written as
// glTF (mesh/scene_export.h). Static meshes (terrains, plants, forest
// variants) are written once each, with a node per instance; what the
// simulation draws at that time follows: instanced particle meshes and
// boids as one node per particle, cloth as a mesh, sprites as POINTS and
// trails as LINES with their colours. OBJ and PLY have no instances, so a
// scene asks for .glb or .gltf.
#include <unistd.h>
#include <chrono>

#include <cstdio>
#include <iostream>
#include <map>
#include <ostream>

#include "app/cli.h"
#include "app/commands.h"
#include "core/parallel.h"
#include "mesh/scene_export.h"
#include "scene/build.h"
#include "scene/simulation.h"

namespace sylva::app {
namespace {

bool SameLoc(const SourceLoc& a, const SourceLoc& b) {
  return a.file == b.file && a.line == b.line && a.column == b.column;
}

std::string NameOf(const std::string& kind, const std::string& id, size_t index) {
  return id.empty() ? kind + " " + std::to_string(index + 1) : id;
}

// The element a built mesh comes from, by its location: its name (the id,
// else "plant 2": the kind and its rank among its kind) and whether it is
// a forest.
std::pair<std::string, bool> ElementOf(const scene::Scene& s, const SourceLoc& loc) {
  for (size_t i = 0; i < s.terrains.size(); ++i)
    if (SameLoc(s.terrains[i].loc, loc)) return {NameOf("terrain", s.terrains[i].id, i), false};
  for (size_t i = 0; i < s.plants.size(); ++i)
    if (SameLoc(s.plants[i].loc, loc)) return {NameOf("plant", s.plants[i].id, i), false};
  for (size_t i = 0; i < s.forests.size(); ++i)
    if (SameLoc(s.forests[i].loc, loc)) return {NameOf("forest", s.forests[i].id, i), true};
  return {"mesh", false};
}

// One mesh and a node per instance: named `nodeName` when there is one
// instance and no `counter`, else "nodeName/N" with N counting from
// *counter (forests number their trees across variants).
void AddMesh(mesh::ExportScene& out, std::shared_ptr<const mesh::TriangleMesh> m,
             const mesh::Palette& palette, const std::string& meshName, const std::string& nodeName,
             const std::vector<draw::Instance>& instances, size_t* counter = nullptr) {
  const int index = int(out.meshes.size());
  out.meshes.push_back({std::move(m), palette, meshName});
  size_t own = 0;
  size_t& n = counter ? *counter : own;
  for (const draw::Instance& instance : instances) {
    const std::string name =
        instances.size() == 1 && !counter ? nodeName : nodeName + "/" + std::to_string(n++);
    out.nodes.push_back({name, index, instance.transform, instance.tint});
  }
}

// The static world, then the simulated frame.
mesh::ExportScene ToExport(const scene::Scene& s, const scene::BuiltScene& built,
                           const draw::DrawList& simulated) {
  mesh::ExportScene out;
  std::map<std::string, size_t> variants, trees;  // per forest: meshes and trees so far
  for (const scene::BuiltMesh& b : built.meshes) {
    const auto [name, forest] = ElementOf(s, b.loc);
    if (!forest) {
      AddMesh(out, b.mesh, b.palette, name, name, b.instances);
      continue;
    }
    AddMesh(out, b.mesh, b.palette, name + " variant " + std::to_string(variants[name]++), name,
            b.instances, &trees[name]);
  }
  for (size_t i = 0; i < simulated.meshes.size(); ++i) {
    const draw::MeshDraw& d = simulated.meshes[i];
    const std::string name = NameOf("simulated mesh", d.name, i);
    AddMesh(out, d.mesh, d.palette, name, name, d.instances);
  }
  for (size_t i = 0; i < simulated.sprites.size(); ++i) {
    const draw::Sprites& p = simulated.sprites[i];
    out.points.push_back(
        {NameOf("points", p.name, i), mesh::PointMode::kPoints, p.positions, p.colors});
  }
  for (size_t i = 0; i < simulated.lines.size(); ++i) {
    const draw::Lines& l = simulated.lines[i];
    out.points.push_back({NameOf("lines", l.name, i), mesh::PointMode::kLines, l.points, l.colors});
  }
  return out;
}

}  // namespace

int RunMeshScene(const MeshCommand& cmd, std::ostream& out, std::ostream& err) {
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  const auto format = mesh::FormatFromPath(cmd.output);
  if (format != mesh::MeshFormat::kGlb && format != mesh::MeshFormat::kGltf) {
    err << "sylva: error: " << cmd.output
        << ": a scene is written as glTF (.glb or .gltf), the only format that keeps its "
           "instances and particles\n";
    return kExitBadInput;
  }
  if (cmd.derive.steps || cmd.derive.seed) {
    err << "sylva: error: -n and --seed are for grammars; a scene sets them on <plant> and "
           "<forest>\n";
    return kExitBadInput;
  }
  if (cmd.lodEps || cmd.size != "960x540" || !cmd.camera.empty()) {
    err << "sylva: error: --lod-eps, --size and --camera are for grammars; a scene is written at "
           "uniform --sides\n";
    return kExitBadInput;
  }
  if (cmd.derive.maxModules || cmd.derive.maxTriangles) {
    err << "sylva: error: --max-modules and --max-triangles are for grammars; a scene is bounded "
           "by its own sizes (docs/scene.md)\n";
    return kExitBadInput;
  }
  int exit = kExitOk;
  const auto run = StartScene({cmd.derive.file, cmd.derive.defines, cmd.derive.maxErrors,
                               cmd.derive.strict, cmd.derive.threads, cmd.sides},
                              err, &exit);
  if (!run) return exit;
  const scene::Scene* const scene = &run->scene;
  const scene::BuiltScene* const built = &run->built;
  scene::Simulation* const sim = run->simulation.get();
  const auto t1 = Clock::now();
  // On a terminal, progress every quarter of a simulated second (the steps
  // taken are the same either way: AdvanceTo takes whole steps).
  const double until = cmd.time.value_or(0);
  if (&err == &std::cerr && isatty(2)) {
    for (double t = 0.25; t < until; t += 0.25) {
      if (Status s = sim->AdvanceTo(t); !s.ok()) return Report(s.error(), err);
      char progress[120];
      std::snprintf(progress, sizeof progress, "\rsimulating: t = %.2f of %.2f s, %zu points",
                    sim->time(), until, sim->Count());
      err << progress << std::flush;
    }
    if (until > 0.25) err << "\n";
  }
  if (Status s = sim->AdvanceTo(until); !s.ok()) return Report(s.error(), err);
  draw::DrawList simulated;
  sim->AddToDrawList(simulated);
  if (Status s = simulated.Check(); !s.ok()) return Report(s.error(), err);
  const auto t2 = Clock::now();

  mesh::SceneExportStats stats;
  const mesh::ExportScene exported = ToExport(*scene, *built, simulated);
  if (Status s =
          mesh::WriteSceneGltf(exported, cmd.output, format == mesh::MeshFormat::kGlb, &stats);
      !s.ok())
    return Report(s.error(), err);
  const auto t3 = Clock::now();
  auto seconds = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); };
  char line[400];
  std::snprintf(line, sizeof line,
                "%s: t = %.3f s, %zu nodes, %zu meshes, %zu materials, %zu points, %zu line "
                "segments; build %.2f s, simulate %.2f s, write %.2f s\n",
                cmd.output.c_str(), sim->time(), stats.nodes, stats.meshes, stats.materials,
                stats.points, stats.lines, seconds(t0, t1), seconds(t1, t2), seconds(t2, t3));
  err << line;
  (void)out;
  return kExitOk;
}

}  // namespace sylva::app
