// HeightField: a terrain as a regular grid of heights, centred on the
// origin in x and z (Y up), made from a TerrainDef (the fields of the scene
// file's <terrain> element, SCENE.md), and the exact surface of its
// triangle mesh.
//
// Grid: resolution^2 vertices; vertex (i, j) (i along x, j along z) is at
//   x = -sizeX/2 + i sizeX / (resolution - 1),  z likewise,
// with height heights()[j resolution + i].
//
// Surface: each cell is split along the diagonal from (i, j) to
// (i+1, j+1) into two triangles,
//   A = (i,j) (i,j+1) (i+1,j+1)   where the cell fractions satisfy u <= w
//   B = (i,j) (i+1,j+1) (i+1,j)   where u > w
// (u along x, w along z, both in [0, 1]; counter-clockwise seen from +y).
// Height(x, z) is the height of that triangle's plane, and Normal(x, z) its
// unit normal (on the diagonal itself, triangle A's): the surface the mesh
// draws and a collider should meet, exactly, not a bilinear patch. Queries
// outside the extent take the nearest point of the border (Contains tells
// whether a point is inside); NaN in x or z gives NaN.
//
// Noise kinds (the height is `height` times the kind's value):
//   fbm             fBm of gradient noise (fractal.h), in [-1, 1]
//   ridged          ridged multifractal (fractal.h), in [0, 1]
//   diamond-square  diamond_square.h divided by its bound, in [-1, 1];
//                   needs resolution 2^k + 1; `gain` is its roughness
//   flat            0 everywhere
// fbm and ridged sample at (x, z) / featureSize: the first octave's
// lattice spacing is featureSize metres (0 = half the larger extent).
//
// A HeightField is immutable once made: its const queries may run on any
// number of threads at once. To draw it, turn MakeMesh()'s arrays into a
// mesh::TriangleMesh (examples/terrain/terrain_kinds.cpp does).
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "core/assert.h"
#include "core/math.h"
#include "core/status.h"

namespace sylva {
class ThreadPool;
}

namespace sylva::terrain {

enum class NoiseKind { kFbm, kRidged, kDiamondSquare, kFlat };

// "fbm", "ridged", "diamond-square", "flat".
const char* NameOf(NoiseKind kind);
// The kind of one of those names; a Diagnostic (with "did you mean" when a
// name is close) otherwise.
Expected<NoiseKind> NoiseKindFromName(std::string_view name);

// Defaults are SCENE.md's. Ranges are checked by Validate (NaN fails all).
struct TerrainDef {
  double sizeX = 100, sizeZ = 100;  // metres, 0.001..1e6, extent centred on the origin
  int resolution = 257;             // vertices per side, 2..8193 (2^k + 1 for diamond-square)
  double height = 10;               // metres, 0..1e5: amplitude of the noise
  NoiseKind noise = NoiseKind::kFbm;
  int octaves = 6;         // 1..16 (fbm, ridged)
  double lacunarity = 2;   // 1..16 (fbm, ridged)
  double gain = 0.5;       // 0..1: amplitude per octave; diamond-square: roughness
  double featureSize = 0;  // metres, 0 (auto) or 0.001..1e7 (fbm, ridged)
  uint64_t seed = 1;
};

// The first bad number, named with its value and range:
//   "TerrainDef.resolution 0 is outside 2..8193"
// including combinations: diamond-square at a resolution that is not
// 2^k + 1, and fbm or ridged octaves whose finest lattice coordinates pass
// 2^24 (where a float has no fraction left and the noise would be 0).
Status Validate(const TerrainDef& def);

// Plain arrays for a triangle mesh of the grid: 3 floats a vertex for
// positions and unit normals (central differences of the grid, one-sided
// on the border: smooth shading, not Normal()'s facets), 3 indices a
// triangle, the cells' triangles A and B in the order above, row by row.
struct TerrainMesh {
  std::vector<float> positions;
  std::vector<float> normals;
  std::vector<uint32_t> indices;
};

class HeightField {
 public:
  // Validates the def, checks that the heights fit in memory (half the
  // machine's physical memory at most: a kRuntime error otherwise, before
  // any allocation), then fills the grid, rows on `pool` when given (the
  // heights do not depend on it).
  static Expected<HeightField> Create(const TerrainDef& def, ThreadPool* pool = nullptr);

  const TerrainDef& def() const { return def_; }
  int resolution() const { return def_.resolution; }
  double spacingX() const { return dx_; }
  double spacingZ() const { return dz_; }
  double VertexX(int i) const { return x0_ + double(i) * dx_; }
  double VertexZ(int j) const { return z0_ + double(j) * dz_; }
  float HeightAt(int i, int j) const {
    SYLVA_DCHECK(i >= 0 && i < def_.resolution && j >= 0 && j < def_.resolution);
    return heights_[size_t(j) * size_t(def_.resolution) + size_t(i)];
  }
  // resolution^2 heights, row-major by z: [j resolution + i].
  const std::vector<float>& heights() const { return heights_; }
  float minHeight() const { return minHeight_; }
  float maxHeight() const { return maxHeight_; }

  bool Contains(double x, double z) const;
  double Height(double x, double z) const;
  Vec3 Normal(double x, double z) const;

  // The mesh arrays; a kRuntime error if they would not fit in memory.
  Expected<TerrainMesh> MakeMesh() const;

 private:
  struct Cell {
    size_t i, j;
    double u, w;
  };
  Cell Locate(double x, double z) const;

  TerrainDef def_;
  double x0_ = 0, z0_ = 0, dx_ = 1, dz_ = 1;
  float minHeight_ = 0, maxHeight_ = 0;
  std::vector<float> heights_;
};

}  // namespace sylva::terrain
