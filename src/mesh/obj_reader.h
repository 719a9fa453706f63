// Reading Wavefront OBJ files, for predefined surfaces (`~leaf`). Supports
// v, vt, vn and f (any polygon, fan-triangulated; v, v/vt, v//vn, v/vt/vn;
// negative indices); other statements are ignored. Missing normals are
// computed per face; missing UVs are 0. Errors name file:line:col.
#pragma once

#include <string>

#include "core/status.h"
#include "mesh/triangle_mesh.h"

namespace sylva::mesh {

// ReadObj reads regular files of at most this size (a leaf or flower surface
// is a few kilobytes); anything else is an error naming the path.
inline constexpr size_t kMaxObjFileBytes = size_t(256) << 20;

Expected<TriangleMesh> ReadObj(const std::string& path);
Expected<TriangleMesh> ParseObj(const std::string& text, const std::string& path);

}  // namespace sylva::mesh
