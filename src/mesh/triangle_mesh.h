// TriangleMesh: indexed triangles as structure of arrays, ready for the GPU
// and the exporters. Positions, normals and UVs are 32-bit floats (what
// glTF and OpenGL take); each triangle carries a material id (the turtle's
// colour index).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/math.h"

namespace sylva::mesh {

using Vec3f = Eigen::Vector3f;
using Vec2f = Eigen::Vector2f;

struct TriangleMesh {
  std::vector<Vec3f> positions;
  std::vector<Vec3f> normals;      // unit, one per vertex
  std::vector<Vec2f> uvs;          // one per vertex
  std::vector<uint32_t> indices;   // 3 per triangle, counter-clockwise seen from outside
  std::vector<uint16_t> material;  // one per triangle
  // Sub-pixel coverage (docs/lod.md): empty (every vertex opaque), or one
  // value in (0, 1] per vertex, the fraction of the drawn width (or area)
  // the true geometry covers. Only screen-space tessellation for a renderer
  // that blends fills it (ScreenView::coverage); exporters ignore it.
  std::vector<float> coverage;

  size_t vertexCount() const { return positions.size(); }
  size_t triangleCount() const { return indices.size() / 3; }
  void Clear();
  void Append(const TriangleMesh& other);
};

// The first vertex whose position, normal or UV has a component that is not
// a finite number (NaN in any of x, y, z counts), described; empty if none.
// The exporters refuse such a mesh: no file with NaN in it is ever written.
std::string FindNonFinite(const TriangleMesh& m);

// Checks the invariants every mesh Sylva makes must hold: indices in range,
// finite values, unit normals, no zero-area triangle, array sizes agree,
// coverage (when present) in (0, 1].
// Returns a description of the first violation, or an empty string.
std::string Validate(const TriangleMesh& m, float areaEpsilon = 1e-12f);

}  // namespace sylva::mesh
