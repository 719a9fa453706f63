// Writing a scene of shared meshes as glTF 2.0: each mesh stored once, drawn
// by any number of nodes (a forest of 50 trees made of 8 variants is 8
// meshes and 50 nodes), plus point clouds and line sets with per-vertex
// colours (particles as glTF POINTS, trails as LINES, both with COLOR_0).
// Plain structs, no scene or draw types: the caller (the `sylva mesh`
// command) fills them from what it built.
//
//   mesh::ExportScene s;
//   s.meshes.push_back({treeMesh, palette, "woods variant 0"});
//   s.nodes.push_back({"woods/0", 0, transform});   // model to world
//   s.points.push_back({"snow", mesh::PointMode::kPoints, positions, colors});
//   if (Status st = mesh::WriteSceneGltf(s, "scene.glb", true); !st.ok()) ...
//
// Nodes: one per instance, at the root of the glTF scene, with the
// instance's transform as `translation`, `rotation` (a unit quaternion)
// and `scale`; a transform with shear or a projective row cannot be
// written so and is an error naming the node. A node's `tint` multiplies
// its mesh's palette (the renderer's per-instance colour): a mesh drawn
// with several tints is written once per tint as glTF meshes sharing the
// same accessors, tints rounded to 8-bit sRGB so that a colour ramp over
// particle ages makes at most a few hundred of them.
//
// Materials: one per distinct linear colour (palette entry times tint,
// clamped to [0, 1]), rough, non-metallic and double-sided as in
// WriteGltf; points and lines carry their colours in COLOR_0 (linear, as
// glTF defines it) and use the default material. Point sizes and alpha are
// not part of glTF and are not written.
//
// The file is written whole or not at all (core/atomic_file.h).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/status.h"
#include "mesh/export.h"
#include "mesh/triangle_mesh.h"

namespace sylva::mesh {

using Mat4f = Eigen::Matrix4f;
using Quatf = Eigen::Quaternionf;

// A transform as glTF writes it: M = T * R * S.
struct Trs {
  Vec3f translation = Vec3f::Zero();
  Quatf rotation = Quatf::Identity();  // unit
  Vec3f scale = Vec3f::Ones();
};

// Splits a model matrix into translation, rotation and scale. A mirroring
// matrix (negative determinant) gets a negative x scale; a zero scale
// along an axis is kept (the rotation is completed from the other axes).
// Fails, saying why in *why, when the bottom row is not (0 0 0 1), a
// number is not finite, or the axes are not orthogonal to a relative
// tolerance of 1e-3 (shear).
std::optional<Trs> DecomposeTrs(const Mat4f& m, std::string* why);

struct SceneMesh {
  std::shared_ptr<const TriangleMesh> mesh;
  Palette palette;  // linear; material index i takes palette[i % size]; empty: light grey
  std::string name;
};

struct SceneNode {
  std::string name;
  int mesh = 0;                         // index into ExportScene::meshes
  Mat4f transform = Mat4f::Identity();  // model to world
  Vec3f tint{1, 1, 1};                  // multiplies the palette colours
};

enum class PointMode { kPoints, kLines };

// A point cloud (kPoints) or line segments (kLines: one per two points),
// in world space, one linear colour per point.
struct ScenePoints {
  std::string name;
  PointMode mode = PointMode::kPoints;
  std::vector<Vec3f> positions;
  std::vector<Vec3f> colors;
};

struct ExportScene {
  std::vector<SceneMesh> meshes;
  std::vector<SceneNode> nodes;
  std::vector<ScenePoints> points;
};

// What WriteSceneGltf wrote, for the command's summary.
struct SceneExportStats {
  size_t nodes = 0;   // glTF nodes (mesh instances and point sets)
  size_t meshes = 0;  // glTF meshes, tinted copies and point sets included
  size_t materials = 0;
  size_t points = 0;  // vertices of POINTS primitives
  size_t lines = 0;   // segments of LINES primitives
};

// .glb when `binary`, else .gltf with the buffer embedded as a data URI.
// Meshes with no triangles, their nodes, and empty point sets are left out.
// Errors: a node naming a mesh that does not exist, a mesh or point that is
// not finite, arrays whose lengths disagree, a transform that is not TRS,
// a .glb over 4 GiB, and I/O.
Status WriteSceneGltf(const ExportScene& scene, const std::string& path, bool binary,
                      SceneExportStats* stats = nullptr);

}  // namespace sylva::mesh
