// The DrawList: one frame described without OpenGL. The scene (or any
// caller) fills it; the renderer (src/render) draws it and knows nothing of
// plants, particles or scenes.
//
//   draw::DrawList list;
//   list.lights.push_back(draw::Light::Sun({-0.4f, -1, -0.3f}, {1, 1, 1}, 2));
//   auto& trees = list.meshes.emplace_back();
//   trees.mesh = treeMesh;            // shared: many instances, one upload
//   trees.palette = palette;
//   trees.instances.push_back({Transform(position, yaw, scale)});
//   renderer.Draw(list, camera);
//
// Colours are linear RGB (mesh/color.h). Sizes: a mesh vertex is 36 bytes on
// the GPU (position, normal, colour), an instance 76 (4x4 matrix, tint).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/math.h"
#include "core/status.h"
#include "mesh/export.h"
#include "mesh/triangle_mesh.h"

namespace sylva::draw {

using Vec3f = mesh::Vec3f;
using Mat4f = Eigen::Matrix4f;

// At most this many lights a frame (the shaders' arrays).
inline constexpr size_t kMaxLights = 8;

struct Light {
  enum class Type { kSun, kAmbient, kPoint };
  Type type = Type::kSun;
  Vec3f direction{-0.4f, -1, -0.3f};  // the way the light travels (sun)
  Vec3f position{0, 0, 0};            // point lights
  Vec3f color{1, 1, 1};               // linear
  float intensity = 1;

  static Light Sun(const Vec3f& direction, const Vec3f& color, float intensity);
  static Light Ambient(const Vec3f& color, float intensity);
  static Light Point(const Vec3f& position, const Vec3f& color, float intensity);
};

// Background gradient by the elevation of the view ray: horizon at 0
// degrees, top at the zenith (and the horizon colour below it).
struct Sky {
  Vec3f top{0.16f, 0.33f, 0.62f};
  Vec3f horizon{0.62f, 0.72f, 0.83f};
};

struct Instance {
  Mat4f transform = Mat4f::Identity();  // model to world
  Vec3f tint{1, 1, 1};                  // multiplies the palette colour
};

// One mesh drawn once per instance (one instanced draw call).
struct MeshDraw {
  std::shared_ptr<const mesh::TriangleMesh> mesh;
  mesh::Palette palette;  // material index -> colour; empty: light grey
  std::vector<Instance> instances;
  bool castsShadow = true;
  std::string name;  // what it shows (an element id), for exporters; may be empty
};

enum class Blend { kAlpha, kAdditive };

// Round camera-facing sprites, sized in world units (diameters).
struct Sprites {
  std::vector<Vec3f> positions;
  std::vector<float> sizes;
  std::vector<Vec3f> colors;
  std::vector<float> alphas;  // empty: opaque
  Blend blend = Blend::kAlpha;
  std::string name;  // as MeshDraw::name
};

struct Lines {
  std::vector<Vec3f> points;  // pairs: one segment per two points
  std::vector<Vec3f> colors;  // one per point
  std::string name;           // as MeshDraw::name
};

// The default light rig: a warm key from the upper left (the shadow
// caster), a cool fill from the right and a hemisphere ambient. A list
// without lights is lit by it; a grammar's default scene uses it.
std::vector<Light> DefaultLights();

struct DrawList {
  std::vector<MeshDraw> meshes;
  std::vector<Sprites> sprites;
  std::vector<Lines> lines;
  std::vector<Light> lights;  // none: the renderer's default key, fill and ambient
  std::optional<Sky> sky;     // none: the flat background
  Vec3f background{0.87f, 0.89f, 0.91f};
  // The box the first sun's shadow map covers; none: the bounds of the
  // meshes that cast shadows. Set it to the whole plant's box when culling
  // (screen-space detail) drops parts whose shadows still fall in view, so
  // every view gets the same shadow map.
  std::optional<std::pair<Vec3, Vec3>> shadowBounds;
  bool wireframe = false;  // triangle edges drawn over the shaded meshes

  // Every array length agrees, at most kMaxLights lights, every number
  // finite (each component of every position, matrix and colour). An
  // error names the first problem.
  Status Check() const;
  // Bounds of everything drawn (meshes through their instances, sprites,
  // lines); false when there is nothing.
  bool Bounds(Vec3& lo, Vec3& hi) const;
};

// Model matrix: scale, then rotate about Y by yawDegrees, then translate.
Mat4f Transform(const Vec3& translation, double yawDegrees, double scale);

}  // namespace sylva::draw
