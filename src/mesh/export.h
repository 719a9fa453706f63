// Writing meshes: Wavefront OBJ (+ MTL), binary PLY, glTF 2.0 (.glb binary,
// .gltf text with the buffer embedded). Every file is written to a temporary
// name and renamed when complete, so a failed export leaves nothing behind
// (and an existing file untouched).
//
// Materials: one per colour index used by the mesh, coloured from a palette
// (index i takes palette[i % palette.size()]); DefaultPalette() is used when
// the grammar sets none.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <optional>

#include "core/status.h"
#include "mesh/triangle_mesh.h"

namespace sylva::mesh {

using Palette = std::vector<Vec3f>;  // linear RGB in [0, 1] (mesh/color.h: the conventions)

// Bark, leaf green, light green, petal pink, yellow, white, dark bark, red.
const Palette& DefaultPalette();

enum class MeshFormat { kObj, kPly, kGlb, kGltf };

// From the file name's extension (case-insensitive); nullopt if unknown.
std::optional<MeshFormat> FormatFromPath(const std::string& path);

Status WriteObj(const TriangleMesh& m, const Palette& palette, const std::string& path);
Status WritePly(const TriangleMesh& m, const Palette& palette, const std::string& path);
Status WriteGltf(const TriangleMesh& m, const Palette& palette, const std::string& path,
                 bool binary);
// A .glb written while it is tessellated, never holding the whole mesh:
// `tessellate` is called once with a stream to pass on as
// TessellateOptions::stream (mesh/tessellator.h), and each piece goes to
// the file as it comes (peak memory: a piece, about 1 M vertices). The BIN
// chunk is byte for byte WriteGltf's for the same mesh; the JSON chunk is
// its text followed by more padding spaces (its room is reserved before
// the bounds are known). A piece with a non-finite value stops the write
// and leaves no file. A FIFO or device, which cannot seek, gets the pieces
// gathered and WriteGltf. `counts` (may be null): what was written.
struct MeshCounts {
  size_t vertices = 0, triangles = 0;
};
struct MeshStream;
Status WriteGlbStreamed(const Palette& palette, const std::string& path,
                        const std::function<Status(const MeshStream&)>& tessellate,
                        MeshCounts* counts = nullptr);

// By extension.
Status WriteMesh(const TriangleMesh& m, const Palette& palette, const std::string& path);

// Triangles grouped by material: order[] lists triangle indices, material
// by material (ascending); starts[k]..starts[k+1] are those of materials[k].
struct MaterialGroups {
  std::vector<uint16_t> materials;
  std::vector<uint32_t> starts;
  std::vector<uint32_t> order;
};
MaterialGroups GroupByMaterial(const TriangleMesh& m);

}  // namespace sylva::mesh
