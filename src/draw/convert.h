// Conversions from simulation data to parts of a DrawList: particles to a
// batch of sprites, to mesh instances or to streaks, a triangulated sheet (a cloth) to
// a mesh with smooth normals. They take plain arrays (a
// particles::ParticleState's fields, a BulkState's coordinate arrays, a
// Cloth's positions and triangles), so the draw library depends on no
// simulation library (DESIGN.md: draw -> mesh, core), and every caller
// (the scene, the examples, your own program) converts the same way.
//
//   draw::PointStyle style;
//   style.size = 0.05f;
//   auto sprites = draw::PointSprites(sys.state.position, style, sys.state.color);
//   if (!sprites) ...;  // arrays of different lengths
//   list.sprites.push_back(std::move(*sprites));
//
//   auto sheet = draw::SheetMesh(cloth.positions(), cloth.triangles());
//
// Lengths are checked (an array that does not match the positions is a
// Diagnostic naming both lengths, never read past its end); numbers are
// not: DrawList::Check reports a non-finite one before anything is drawn.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>

#include "core/status.h"
#include "draw/draw_list.h"

namespace sylva::draw {

// How a batch of points looks where the arrays say nothing.
struct PointStyle {
  float size = 0.05f;    // diameter, m, for every point when `radii` is empty
  Vec3f color{1, 1, 1};  // linear RGB, for every point when `colors` is empty
  float alpha = 1;       // every point's opacity (1: opaque, no alpha array)
  Blend blend = Blend::kAlpha;
  std::string name;  // as Sprites::name
};

// Sprites at `positions` (metres; double precision, as particles keep
// them), of diameter 2 radii[i] (or style.size), colour colors[i] (or
// style.color). Each non-empty array must have one entry per position.
Expected<Sprites> PointSprites(std::span<const Vec3> positions, const PointStyle& style,
                               std::span<const Vec3f> colors = {},
                               std::span<const float> radii = {});
// The same from coordinates in three arrays (a BulkState's px, py, pz).
Expected<Sprites> PointSprites(std::span<const float> x, std::span<const float> y,
                               std::span<const float> z, const PointStyle& style,
                               std::span<const Vec3f> colors = {},
                               std::span<const float> radii = {});

// A model matrix that turns the mesh's +Z to `forward` with +Y up (any
// direction when forward is zero: +Z), scaled by `scale`, at `at`.
Mat4f Facing(const Vec3& at, const Vec3& forward, double scale);

// One instance per particle, facing its velocity (boids, darts, arrows),
// scaled by `scale`, tinted `tint`. velocities must have one entry per
// position.
Expected<std::vector<Instance>> FacingInstances(std::span<const Vec3> positions,
                                                std::span<const Vec3> velocities, double scale,
                                                const Vec3f& tint = Vec3f(1, 1, 1));

// Streaks: one line segment per particle, from where it was `seconds` ago
// along its velocity (positions[i] - seconds velocities[i]) to where it
// is, coloured colors[i] at the head (or `color`) and `tailShade` times
// that at the tail (a fading streak). velocities must have one entry per
// position, colors one or none; seconds and tailShade are taken as given.
Expected<Lines> Trails(std::span<const Vec3> positions, std::span<const Vec3> velocities,
                       double seconds, std::span<const Vec3f> colors = {},
                       const Vec3f& color = Vec3f(1, 1, 1), float tailShade = 0.3f,
                       std::string name = {});
// A mesh of a triangulated sheet: the vertices at `positions`, the
// triangles as given (each index below positions.size(), else a
// Diagnostic naming the triangle), smooth normals (area-weighted sums of
// the face normals; +Z where they cancel), UVs 0, and materials[t] for
// triangle t (empty: material 0; else one per triangle).
Expected<mesh::TriangleMesh> SheetMesh(std::span<const Vec3> positions,
                                       std::span<const std::array<uint32_t, 3>> triangles,
                                       std::span<const uint16_t> materials = {});

}  // namespace sylva::draw
