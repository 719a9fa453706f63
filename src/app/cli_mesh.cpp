// sylva mesh: a plant (src/plant) written to a mesh file; a scene goes to
// cli_mesh_scene.cpp.
#include <chrono>
#include <cstdio>
#include <ostream>

#include "app/cli.h"
#include "app/commands.h"
#include "mesh/export.h"
#include "mesh/plant_geometry.h"
#include "mesh/tessellator.h"

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
  spec->until = plant::Stage::kGeometry;
  auto plant = BuildPlant(*spec, cmd.derive.maxErrors, err, &exit, cmd.derive.strict);
  if (!plant) return exit;
  return TessellateAndWrite(cmd, *plant, *spec, err);
}

int TessellateAndWrite(const MeshCommand& cmd, plant::Plant& plant, const plant::PlantSpec& spec,
                       std::ostream& err) {
  using Clock = std::chrono::steady_clock;
  // Tessellation warnings are reported before the file is committed, so
  // --strict leaves no file.
  int exit = kExitOk;
  auto tessellate = [&](const mesh::MeshStream* stream) -> Status {
    DiagnosticList warnings;
    Status s = plant::Tessellate(plant, spec, warnings, stream);
    exit = Report(warnings, err, cmd.derive.maxErrors, cmd.derive.strict);
    if (!s.ok() || exit == kExitOk) return s;
    Diagnostic d;
    d.message = "--strict";  // already reported
    return d;
  };
  const auto t0 = Clock::now();
  mesh::MeshCounts counts;
  Status s;
  // A .glb is written while it is tessellated: the mesh is never held whole.
  const bool streamed = mesh::FormatFromPath(cmd.output) == mesh::MeshFormat::kGlb;
  if (streamed) {
    s = mesh::WriteGlbStreamed(
        plant.palette, cmd.output,
        [&](const mesh::MeshStream& stream) { return tessellate(&stream); }, &counts);
  } else {
    s = tessellate(nullptr);
    if (s.ok()) s = mesh::WriteMesh(plant.mesh, plant.palette, cmd.output);
    counts = {plant.mesh.vertexCount(), plant.mesh.triangleCount()};
  }
  if (!s.ok()) return exit != kExitOk ? exit : Report(s.error(), err);
  const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  const plant::Timings& t = plant.time;
  char times[160];
  if (streamed) {
    std::snprintf(times, sizeof times, "tessellate and write %.1f ms", ms);
  } else {
    std::snprintf(times, sizeof times, "tessellate %.1f ms, write %.1f ms", t.tessellate,
                  ms - t.tessellate);
  }
  // Every primitive the turtle emits is counted (mesh/plant_geometry.h).
  const mesh::PlantGeometry& g = plant.geometry;
  char line[600];
  std::snprintf(line, sizeof line,
                "%s: %zu vertices, %zu triangles, %zu segments, %zu polygons, %zu spheres, %zu "
                "surfaces, %zu contour tubes (%llu modules)\n"
                "time: derive %.1f ms, turtle %.1f ms, %s\n",
                cmd.output.c_str(), counts.vertices, counts.triangles, g.segments.size(),
                g.polygons.size(), g.spheres.size(), g.surfaces.size(), g.tubes.size(),
                static_cast<unsigned long long>(plant.DrawnWord().size()),
                t.parse + t.derive + t.interpret, t.turtle, times);
  err << line;
  return kExitOk;
}

}  // namespace sylva::app
