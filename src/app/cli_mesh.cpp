// sylva mesh: a plant (src/plant) written to a mesh file; a scene goes to
// cli_mesh_scene.cpp.
#include <chrono>
#include <cstdio>
#include <ostream>

#include "app/cli.h"
#include "app/commands.h"
#include "mesh/export.h"

namespace sylva::app {

int RunMesh(const MeshCommand& cmd, std::ostream& out, std::ostream& err) {
  (void)out;
  if (!mesh::FormatFromPath(cmd.output)) {
    err << "sylva: error: " << cmd.output
        << ": unknown mesh format; use .obj, .ply, .glb or .gltf\n";
    return kExitBadInput;
  }
  if (IsSceneFile(cmd.derive.file)) return RunMeshScene(cmd, out, err);
  if (cmd.time) {
    err << "sylva: error: --time is for scene files (.xml)\n";
    return kExitBadInput;
  }
  int exit = kExitOk;
  auto spec = SpecFrom(cmd.derive, err, &exit);
  if (!spec) return exit;
  spec->detail.sides = cmd.sides;
  auto plant = BuildPlant(*spec, cmd.derive.maxErrors, err, &exit, cmd.derive.strict);
  if (!plant) return exit;
  return WriteMeshOf(cmd, *plant, err);
}

int WriteMeshOf(const MeshCommand& cmd, const plant::Plant& plant, std::ostream& err) {
  using Clock = std::chrono::steady_clock;
  const mesh::TriangleMesh& m = plant.mesh;
  const auto t0 = Clock::now();
  if (Status s = mesh::WriteMesh(m, plant.palette, cmd.output); !s.ok()) {
    return Report(s.error(), err);
  }
  const double writeMs = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  const plant::Timings& t = plant.time;
  char line[320];
  std::snprintf(line, sizeof line,
                "%s: %zu vertices, %zu triangles, %zu segments, %zu polygons (%llu modules)\n"
                "time: derive %.1f ms, turtle %.1f ms, tessellate %.1f ms, write %.1f ms\n",
                cmd.output.c_str(), m.vertexCount(), m.triangleCount(),
                plant.geometry.segments.size(), plant.geometry.polygons.size(),
                static_cast<unsigned long long>(plant.DrawnWord().size()),
                t.parse + t.derive + t.interpret, t.turtle, t.tessellate, writeMs);
  err << line;
  return kExitOk;
}

}  // namespace sylva::app
