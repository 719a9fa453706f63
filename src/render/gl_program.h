// Shader programs from the shader folder (internal to src/render).
#pragma once

#include <string>

#include <vector>

#include "core/status.h"
#include "mesh/export.h"
#include "mesh/triangle_mesh.h"

namespace sylva::render {

// Compiles and links NAME.vert + NAME.frag from `dir`; an error names the
// file and carries the GLSL compiler's message.
Expected<unsigned> CompileProgram(const std::string& dir, const std::string& name);
// Same, with the vertex shader and fragment shader named separately.
Expected<unsigned> CompileProgram(const std::string& dir, const std::string& vert,
                                  const std::string& frag);

// Per-vertex colour: the material of the first triangle using the vertex
// (light grey without a palette).
std::vector<mesh::Vec3f> VertexColors(const mesh::TriangleMesh& m, const mesh::Palette& palette);

// Fills buffers[0..2] with positions, normals and `colors` (3 floats each)
// as vertex attributes 0..2 of the bound vertex array.
void UploadVertexAttributes(const unsigned buffers[3], const mesh::TriangleMesh& m,
                            const std::vector<mesh::Vec3f>& colors);

// Sub-pixel coverage (TriangleMesh::coverage, docs/lod.md): when some
// vertex has coverage < 1, fills the bound element buffer with the opaque
// triangles first and those with partial coverage after them, uploads the
// coverage into `coverageBuffer` as attribute `location` of the bound
// vertex array, and returns how many indices are opaque; otherwise fills
// the element buffer as it is, disables the attribute (its generic value,
// 1, is set before drawing) and returns the index count.
size_t UploadIndicesOpaqueFirst(const mesh::TriangleMesh& m, unsigned coverageBuffer,
                                unsigned location);
// The CPU half of it: with partial coverage, m's indices opaque first into
// `sorted` and the opaque count; without, `sorted` empty and the index count.
size_t OpaqueFirst(const mesh::TriangleMesh& m, std::vector<uint32_t>& sorted);

}  // namespace sylva::render
