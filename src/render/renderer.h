// The OpenGL renderer: a mesh pipeline (indexed triangles, per-vertex colour
// from the palette, key and fill lights and a hemisphere ambient term) and
// a line pipeline (2D ABOP curves, skeletons), drawn into a 4x multisampled
// framebuffer and resolved for read-back. It takes meshes and plain line
// batches, never particles, plants or scenes. Needs a current OpenGL 4.5
// context (HeadlessContext, or the viewer's window). GL types stay inside.
//
// Shaders are GLSL files loaded at run time from a shader folder (see
// FindShaderDir); a missing or broken shader is an error naming the file and
// the compiler's message.
#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/status.h"
#include "draw/draw_list.h"
#include "mesh/color.h"
#include "mesh/export.h"
#include "mesh/screen_detail.h"
#include "mesh/triangle_mesh.h"
#include "render/camera.h"

namespace sylva::render {

struct Image {
  int width = 0, height = 0;
  std::vector<uint8_t> rgba;  // rows top to bottom, 4 bytes a pixel
  const uint8_t* Pixel(int x, int y) const {
    return &rgba[4 * (size_t(y) * size_t(width) + size_t(x))];
  }
};

struct LineBatch {
  std::vector<mesh::Vec3f> points;  // pairs: one segment per two points
  std::vector<mesh::Vec3f> colors;  // one per point, linear RGB (mesh/color.h)
};

// Particles as the renderer sees them: plain arrays, one entry per point
// (the particles library fills it; the renderer never includes it). Sizes
// are diameters in world units; points are drawn as round sprites facing
// the camera, sized by perspective.
struct PointBatch {
  std::vector<mesh::Vec3f> positions;
  std::vector<float> sizes;
  std::vector<mesh::Vec3f> colors;  // linear RGB (mesh::Srgb converts from sRGB)
};

// The shader folder: $SYLVA_SHADER_DIR if set, else `shaders/` beside the
// executable or one or two levels up, else the source tree's `shaders/`.
std::string FindShaderDir();

// Unit direction toward the key light, which casts the shadows (fixed in
// world space).
Vec3 KeyLightDirection();

// The first sun's shadow map in Draw(DrawList): an orthographic view of
// the sphere of this radius about the centre of lo..hi (the list's
// shadowBounds, else what casts shadows).
double SunShadowRadius(const Vec3& lo, const Vec3& hi);
// Texels per world unit of that shadow map (at the default size) when it
// is fitted to `bounds` (screen-space detail keeps what casts a shadow of a
// texel or more).
double ShadowTexelsPerUnit(const mesh::Box& bounds);

class Renderer {
 public:
  // Compiles the shaders in `shaderDir`; needs a current context.
  static Expected<std::unique_ptr<Renderer>> Create(const std::string& shaderDir);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Size of the offscreen target in pixels (1..8192), with MSAA samples.
  Status Resize(int width, int height, int samples = 4);
  void SetBackground(const mesh::Vec3f& rgb) { background_ = rgb; }  // linear RGB
  mesh::Vec3f background() const { return background_; }

  // Replaces the mesh (uploaded once; drawing it again uploads nothing) and
  // renders its shadow map from the key light once.
  // `bounds`, when given, replaces the mesh's own box as the box the shadow
  // map is fitted to. No ground is drawn: a plant's ground is a scene
  // element (scene/default_scene.h, drawn through Draw(DrawList)).
  void SetMesh(const mesh::TriangleMesh& m, const mesh::Palette& palette,
               const mesh::Box* bounds = nullptr);
  void SetShadows(bool on) { shadows_ = on; }
  // Texels on a side of Draw(DrawList)'s shadow map (256..8192). The
  // default suits a still picture; the viewer takes 2048, whose samples
  // cost llvmpipe a third of the frame time of 4096.
  static constexpr int kDefaultShadowMapSize = 4096;
  void SetShadowMapSize(int texels) { shadowMapSize_ = std::clamp(texels, 256, 8192); }
  // Draws the mesh's triangle edges over it (docs/lod.md's pictures).
  void SetWireframe(bool on) { wireframe_ = on; }
  // Replaces the lines. colors must have one entry per point (else a
  // Diagnostic naming the lengths, and the lines are unchanged: a shorter
  // array used to be read past its end).
  [[nodiscard]] Status SetLines(const LineBatch& lines);
  // Replaces the points. sizes and colors must have one entry per position
  // (else a Diagnostic naming the lengths, and the points are unchanged: a
  // shorter array used to be read past its end).
  [[nodiscard]] Status SetPoints(const PointBatch& points);
  // Draws the current mesh, points and lines: no allocation and no upload;
  // one draw call for the mesh, one for the points, one for the lines.
  void Draw(const Camera& camera);
  // Draws a DrawList (src/draw): meshes by instance, lights (up to 8, the
  // first sun casting shadows), sky, sprites and lines. Meshes are uploaded
  // once while the list keeps sharing them. An error (Check()) draws
  // nothing.
  [[nodiscard]] Status Draw(const draw::DrawList& list, const Camera& camera);
  // Uploads the meshes of `list` the renderer does not hold yet, at most
  // `budgetBytes` of vertex and index data this call, into new buffers,
  // without drawing; true once all of them are on the GPU (Draw(list) then
  // uploads nothing). Call it once a frame with the next list while
  // drawing the current one: a large mesh arrives over several frames
  // instead of stalling one. The meshes
  // of the last Stage() list are kept while other lists are drawn; a mesh
  // that Draw needs before its upload completes is finished there.
  [[nodiscard]] Expected<bool> Stage(const draw::DrawList& list, size_t budgetBytes);
  void Finish();  // waits for the GPU (for timing)
  // Copies the last frame to the window's framebuffer (the viewer), scaled
  // to width x height.
  void PresentToWindow(int width, int height);
  Image ReadPixels();

  int width() const { return width_; }
  int height() const { return height_; }

 private:
  Renderer() = default;
  struct Gl;
  std::unique_ptr<Gl> gl_;
  int width_ = 0, height_ = 0;
  mesh::Vec3f background_ = mesh::Srgb(0.94f, 0.95f, 0.96f);  // linear
  bool shadows_ = true, wireframe_ = false;
  int shadowMapSize_ = kDefaultShadowMapSize;
  void RenderShadowMap();
  unsigned MultisampleFramebuffer() const;
  unsigned ResolveFramebuffer() const;
  struct ScenePass;  // scene_pass.cpp: the DrawList pipelines, made on first use
  ScenePass* scene_ = nullptr;
  static void DestroyScenePass(ScenePass* pass);
  Status InitScenePass();
  std::string shaderDir_;
};

// Reads the current window's back buffer (after everything, UI included,
// is drawn and before the swap): the viewer's screenshots.
Image ReadWindowPixels(int width, int height);

// Writes an RGBA image as PNG (stb_image_write), atomically.
Status WritePng(const Image& image, const std::string& path);
// Writes PNG (.png) or JPEG (.jpg, .jpeg; quality 95) by the file name's
// extension, case-insensitive; any other extension is an input error.
Status WriteImage(const Image& image, const std::string& path);
// True when WriteImage knows the file name's extension.
bool IsImagePath(const std::string& path);

}  // namespace sylva::render
