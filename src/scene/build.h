// Building a scene's static world: terrain height fields and their meshes,
// plants and forests (each forest as `variants` derivations shared by its
// instances, scattered by deterministic Poisson-disc sampling), and the
// DrawList of the result (lights, sky, meshes with transforms).
//
//   scene::ReadResult r = scene::ReadScene("forest.xml");
//   scene::BuildResult b = scene::Build(*r.scene, {});
//   draw::DrawList list = scene::MakeDrawList(*b.scene);
//
// Particles, cloth and flocks live in the Simulation (simulation.h), which
// reads the built world (colliders, emitters on plants and terrain).
#pragma once

#include <array>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "core/diagnostic.h"
#include "draw/draw_list.h"
#include "mesh/export.h"
#include "mesh/screen_detail.h"
#include "mesh/triangle_mesh.h"
#include "particles/capsules.h"
#include "plant/plant.h"
#include "scene/scene.h"
#include "terrain/height_field.h"

namespace sylva::scene {

struct BuildOptions {
  // The process's pool (core/parallel.h SharedPool), shared by derivation
  // and tessellation; null: a pool of `threads` for each plant.
  ThreadPool* pool = nullptr;
  int threads = 0;  // derivation threads without a pool; 0: all cores
  int sides = 8;    // tube sides of every plant (uniform detail)
};

// One mesh with the places it is drawn.
struct BuiltMesh {
  // Uniform detail (BuildOptions::sides): what collides, what is exported
  // and what `simulate` knows, whatever the camera.
  std::shared_ptr<const mesh::TriangleMesh> mesh;
  // Screen-space detail for one view (DetailForView), drawn instead of
  // `mesh` when set.
  std::shared_ptr<const mesh::TriangleMesh> drawMesh;
  // The plant it was tessellated from (null for terrain), for DetailForView.
  std::shared_ptr<plant::Plant> plant;
  plant::PlantSpec spec;
  mesh::Palette palette;
  std::vector<draw::Instance> instances;
  SourceLoc loc;            // the element it comes from
  bool castsShadow = true;  // terrains do not (the sun's map then fits the plants)
};

// Points of a plant (or of every tree of a forest) in world space, where
// emitters place particles: branch tips (segment ends where nothing grows
// on, and the far ends of contour tubes), points along the segments and
// along the axes of contour tubes (midpoints, with their lengths as
// weights), leaves (polygon and surface centres, sphere centres, contour
// tube centres). Every primitive the turtle emits is in them.
struct PlantPoints {
  std::vector<Vec3> tips, segmentPoints, leaves;
  std::vector<double> segmentLengths;
  // What particles collide with, in world space: a capsule per segment (its
  // larger end radius) and per sphere (of no length), and as triangles the
  // polygons, the surfaces placed with `~` and the contour tubes' quads
  // (two triangles each, as the tessellator draws them).
  std::vector<particles::Capsule> capsules;
  std::vector<std::array<Vec3, 3>> leafTriangles;
};

// Adds the points of `g`, placed by `transform`, to `out`; `surfaces` are
// the meshes of the surfaces it places, by name (missing ones do not
// collide). Build calls it for every plant and forest instance with an id.
void AddPlantPoints(const mesh::PlantGeometry& g, const draw::Mat4f& transform,
                    const std::unordered_map<std::string, mesh::TriangleMesh>& surfaces,
                    PlantPoints& out);

struct BuiltScene {
  std::vector<terrain::HeightField> terrains;  // in the order of scene.terrains
  std::vector<BuiltMesh> meshes;               // terrains, plants, forest variants
  // By element id: the meshes of a terrain, plant or forest (indices into
  // `meshes`) and the emission points of a plant or forest.
  std::map<std::string, std::vector<size_t>> meshesOf;
  std::map<std::string, PlantPoints> points;
  size_t trianglesDrawn = 0;                  // over every instance
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();  // bounds of everything drawn
  // The surface height under (x, z): the first terrain containing the
  // point, else 0 (the ground plane).
  double GroundHeight(double x, double z) const;
};

struct BuildResult {
  std::optional<BuiltScene> scene;  // set when there is no error
  DiagnosticList diagnostics;       // grammar errors carry a note at the scene element
};

BuildResult Build(const Scene& scene, const BuildOptions& options);

// Tessellates every plant mesh again for `view` (world coordinates), as
// `drawMesh`: each mesh at the detail its closest instance needs (the view
// is taken into the plant's own frame through that instance's transform),
// without culling, since one mesh serves every instance. Returns the
// triangles drawn over all instances; warnings go to `diagnostics`.
Expected<size_t> DetailForView(BuiltScene& built, const mesh::ScreenView& view,
                               DiagnosticList& diagnostics);

// The scene's terrain def for the terrain library, with its seed.
terrain::TerrainDef TerrainDefOf(const TerrainDef& t, uint64_t seed);

// Forest placement: up to `count` points in `area` at least `minDistance`
// apart (0: chosen from the area and count), deterministic for a seed.
std::vector<Vec2> ScatterPoisson(const ForestDef& forest, uint64_t seed);

// Lights (the renderer's defaults when the scene has none), sky and every
// built mesh with its instances.
draw::DrawList MakeDrawList(const Scene& scene, const BuiltScene& built);

}  // namespace sylva::scene
