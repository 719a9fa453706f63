// Tessellation: PlantGeometry (segments, polygons, spheres, surfaces) to
// triangles, at a detail chosen per primitive.
//
// Branches become generalized cylinders. Consecutive segments of one branch
// (the end of one is the start of the next, same branch id) form one chain
// with one ring of vertices per joint, shared by the segments on both sides
// (no cracks, no overlaps). Ring frames are rotation-minimizing: the double
// reflection method of Wang, Juttler, Zheng & Liu, "Computation of rotation
// minimizing frames" (ACM TOG 27(1), 2008) carries the first ring's normal
// (the turtle's L) along the chain, so tubes do not twist. The radius at a
// joint is the next segment's start radius (the width set by `!` before its
// F), so each internode tapers linearly to the next one. Every chain is
// closed by a fan at its base and at its tip, so each tube is a closed
// 2-manifold (after welding the UV seam). Lateral branches start on their
// parent's axis, so their base lies inside the parent tube: no gap shows.
//
// UVs: u runs 0..1 around the tube (the seam vertex is duplicated), v is the
// distance along the chain in world units, so a bark texture keeps its
// scale. Polygons `{ . }` are triangulated by ear clipping in their best-fit
// plane (Newell's normal), so concave outlines work; they are one-sided with
// the Newell normal (renderers and glTF draw them double-sided). Spheres are
// UV spheres. Counts, for a chain of m segments at S sides: S(m+1)+... see
// TubeTriangles() (uniform detail; screen-space detail, below, merges rings,
// drops caps and draws thin tubes as ribbons).
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <unordered_map>

#include "core/status.h"
#include "mesh/plant_geometry.h"
#include "mesh/screen_detail.h"
#include "mesh/triangle_mesh.h"
#include "mesh/triangulate.h"

namespace sylva {
class ThreadPool;
}

namespace sylva::mesh {

struct Detail {
  int sides = 8;  // vertices around a tube ring and a sphere's equator, 3..256
};

// Chooses the detail per primitive; the screen-space level-of-detail code
// passes one that looks at the camera. `center` and `radius` bound the
// primitive (a whole chain, sphere or polygon).
using DetailFn = std::function<Detail(const Vec3& center, double radius)>;

// Triangles of a tube chain with `segments` segments and S sides, caps included.
constexpr size_t TubeTriangles(size_t segments, int sides) {
  return 2 * size_t(sides) * segments + 2 * size_t(sides);
}

// 2^26 triangles: about 2 GiB of mesh (a triangle costs about 30 bytes:
// 12 of indices, 2 of material, and half a vertex of 32 bytes).
inline constexpr uint64_t kDefaultMaxTriangles = uint64_t(1) << 26;

// A mesh handed over in pieces instead of appended whole (TessellateOptions::
// stream): `sylva mesh` writes a 50-million-triangle tree to a .glb without
// ever holding it. The pieces, concatenated, are exactly the mesh Tessellate
// would append to an empty `out` (same vertices, same triangles, same order).
struct MeshStream {
  // Chains are handed over in pieces of about this many vertices (a chain
  // is never split); spheres, polygons and surfaces come last, in one piece.
  size_t pieceVertices = size_t(1) << 20;
  // Called once before any piece, with the whole mesh's vertex count and
  // its triangles per material (trianglesPerMaterial[m]: those with
  // material m; the vector is as long as the largest material used + 1).
  std::function<Status(size_t vertices, const std::vector<size_t>& trianglesPerMaterial)> begin;
  // Called with each piece in order. firstVertex: where the piece's
  // vertices start in the whole mesh; its indices are the whole mesh's.
  // The piece is reused after the call returns. An error stops tessellation.
  std::function<Status(const TriangleMesh& piece, size_t firstVertex)> piece;
};

struct TessellateOptions {
  Detail detail;  // used when detailFn is empty and there is no view
  DetailFn detailFn;
  // Screen-space detail (mesh/screen_detail.h, docs/lod.md): when set, it
  // replaces detail and detailFn. Each chain gets the sides its largest
  // projected radius needs for a silhouette error of view.eps pixels,
  // joints the straight tube passes within eps/2 pixels of are merged,
  // tubes under 3 eps (1.5 px) in radius become camera-facing ribbons (two
  // triangles a span) and tubes under a pixel get no caps. Spheres get the
  // sides of their projected radius at their centre. With view.shadowFrom
  // set, what lies outside the view but may shade it gets the detail of
  // the shadow map (view.shadowTexelsPerUnit) instead. With view.coverage,
  // tubes under kLinePixels wide become coverage lines and polygons and
  // surfaces under a pixel points, and out.coverage is filled (one value a
  // vertex, 1 for everything else).
  std::optional<ScreenView> view;
  // With a view: drop primitives whose box lies outside the view frustum
  // and, with view.shadowFrom, whose shadow cannot fall in it either (a box
  // straddling the frustum is kept).
  bool cull = true;
  // With a view: the level each chain had last frame, read and updated, so
  // a moving camera changes a chain's representation only past a margin
  // (ChainLevelAfter in mesh/screen_detail.h). Reset when its size is not
  // this geometry's chain count. Null: no hysteresis.
  DetailHistory* history = nullptr;
  // Threads for planning and writing chains; null: the calling thread.
  // The mesh is the same for any pool (offsets are fixed before writing).
  // A detailFn is always called from the calling thread.
  ThreadPool* pool = nullptr;
  // The mesh this call appends may not exceed this many triangles; the
  // count is made before any memory is allocated.
  uint64_t maxTriangles = kDefaultMaxTriangles;
  // Surfaces by name (without `~`), already loaded; unknown names are an error.
  const std::unordered_map<std::string, TriangleMesh>* surfaces = nullptr;
  // When set, the mesh goes to the stream in pieces (MeshStream) and `out`,
  // which must be empty, stays empty. Peak memory is a piece, not the mesh.
  const MeshStream* stream = nullptr;
};

struct TessellateStats {
  size_t chains = 0, polygonsSkipped = 0;
  size_t culled = 0;  // chains, spheres, polygons and surfaces outside the view
  std::vector<std::string> warnings;
};

// Appends the triangles of `g` to `out`. Fails, before appending anything,
// on a surface name that `options.surfaces` does not have (an input error
// naming it) and on a mesh larger than options.maxTriangles (a run-time
// error with the count).
Status Tessellate(const PlantGeometry& g, const TessellateOptions& options, TriangleMesh& out,
                  TessellateStats* stats = nullptr);

// A box holding every triangle Tessellate can make of `g` at any detail:
// the end discs of every segment (the ring at a bent joint tilts to the
// mean of its two segments, so it may reach a hair further), spheres,
// polygons, and the surfaces
// placed (those `surfaces` has; others are skipped). For framing a camera
// before tessellating. Empty (lo > hi) when `g` draws nothing.
Box TessellatedBounds(const PlantGeometry& g,
                      const std::unordered_map<std::string, TriangleMesh>* surfaces);

}  // namespace sylva::mesh
