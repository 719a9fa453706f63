// Screen-space detail: how many sides a tube needs, and whether a primitive
// can be seen, for one camera and one viewport. See docs/lod.md.
//
// The view is plain data (a 4x4 view-projection matrix in OpenGL
// conventions, clip x, y, z in [-w, w], and the viewport in pixels), so the
// mesh library needs no renderer: the app builds it from render::Camera.
//
// Sides. A ring of n sides inscribed in a circle of radius r misses the
// circle by at most r (1 - cos(pi/n)) (the sagitta of one side), so the
// silhouette of a tube of projected radius r pixels moves by at most that
// many pixels. SidesForPixelRadius picks the smallest n in 3..256 that
// keeps it within eps: with eps = 0.5 px, r = 1 -> 3, 2 -> 5, 4 -> 7,
// 8 -> 9, 16 -> 13, 32 -> 18, 64 -> 26, 128 -> 36 sides. The projected
// radius is the world radius times the largest singular value of the
// Jacobian of world -> pixels at the point (PixelsPerUnit), so an oblique
// view near the image border, which stretches the picture, gets more sides,
// and an orthographic view works alike. Same formula as meshoptimizer's
// cluster LOD (a world error divided by the distance, scaled to pixels).
//
// Culling. A bounding volume hierarchy (axis-aligned boxes, median split)
// over every primitive's box, tube radius included, classified against the
// six clip planes (Gribb & Hartmann's extraction): a box wholly outside one
// plane is dropped with all it holds, a box wholly inside all six keeps
// everything below it untested. A primitive that straddles a plane is kept,
// so culling never removes a visible pixel.
#pragma once

#include <cstdint>
#include <vector>

#include "core/math.h"

namespace sylva::mesh {

struct ScreenView {
  Mat4 viewProjection = Mat4::Identity();  // world -> clip, OpenGL conventions
  int width = 960, height = 540;           // viewport, pixels
  double eps = 0.5;                        // silhouette tolerance, pixels (--lod-eps)
  // Shadows: when nonzero, the unit direction toward a directional light
  // whose shadows fall on the plane y = shadowPlaneY. Culling then keeps a
  // primitive whose shadow may show even when the primitive does not (its
  // box swept away from the light down to the plane).
  // A primitive outside the view kept for its shadow gets the detail of
  // the shadow map instead (texels per world unit; no ribbons, which face
  // the camera rather than the light).
  Vec3 shadowFrom = Vec3::Zero();
  double shadowPlaneY = 0;
  double shadowTexelsPerUnit = 0;
  // Sub-pixel coverage, for a renderer that blends (never for export):
  // a tube under kLinePixels wide on screen is drawn as a ribbon
  // kLinePixels wide whose TriangleMesh::coverage is its true width over
  // that, so a twig fades instead of vanishing or aliasing; a polygon or
  // surface under a pixel across becomes a one-pixel camera-facing quad (a
  // point) whose coverage is its projected area.
  bool coverage = false;
};

// The width, in pixels, of a coverage line (ScreenView::coverage): tubes
// thinner than this are drawn this wide with their coverage in alpha.
inline constexpr double kLinePixels = 1.0;

// A tube's representation as one ordered number, coarse to fine: 0 a
// coverage line (only with ScreenView::coverage), 1 a camera-facing
// ribbon, n >= 3 a tube of n sides. Monotone in the projected radius r:
// a line under kLinePixels / 2, a ribbon under 3 eps, else
// SidesForPixelRadius(r, eps).
int ChainLevel(double radiusPx, double eps, bool coverage);

// Hysteresis (docs/lod.md, "Without popping"): the level a chain drawn
// at `last` last frame (-1: none) takes now. It is never coarser than
// ChainLevel(r) (the error stays within eps), and it drops to a coarser
// level only once r is kHysteresis below that level's threshold, so a
// camera wobbling about a threshold does not flip the choice back and forth.
inline constexpr double kHysteresis = 0.15;
int ChainLevelAfter(int last, double radiusPx, double eps, bool coverage);

// The level each chain of one geometry had in the last frame, for
// TessellateOptions::history: index c is the c-th chain in Tessellate's
// order (a different geometry resets it). -1: not drawn yet.
// rings[c]: the rings it kept along its axis (0: none yet); a curved
// chain keeps fewer only once a tolerance kHysteresis tighter allows it.
struct DetailHistory {
  std::vector<int16_t> level;
  std::vector<uint16_t> rings;
};

// The fewest sides (3..256) whose chord error r (1 - cos(pi/n)) is at most
// eps for a projected radius of r pixels. A non-finite r gives 256.
int SidesForPixelRadius(double radiusPx, double eps);

// Pixels per world unit at p: how far, at most, the image of p moves when p
// moves by one unit in any direction. +inf at or behind the eye's plane.
double PixelsPerUnit(const ScreenView& view, const Vec3& p);

// How far, in pixels (x right, y up), the image of p moves when p moves by
// one world unit along d (the Jacobian of world -> pixels at p times d).
// Non-finite at or behind the eye's plane.
Vec2 PixelOffset(const ScreenView& view, const Vec3& p, const Vec3& d);

// The unit direction from p toward the eye (for an orthographic view, the
// reverse of the view direction): the direction in which moving p does not
// move its image. Zero at the eye's plane.
Vec3 TowardEye(const ScreenView& view, const Vec3& p);

struct Box {
  Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  void Add(const Vec3& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  void Add(const Box& b) {
    lo = lo.cwiseMin(b.lo);
    hi = hi.cwiseMax(b.hi);
  }
  void Grow(double r) {
    lo.array() -= r;
    hi.array() += r;
  }
};

// The clip volume as six planes n . p + d >= 0 (left, right, bottom, top,
// near, far).
struct Frustum {
  Vec4 planes[6];
  static Frustum FromViewProjection(const Mat4& viewProjection);
  enum class Side { kOutside, kInside, kStraddles };
  Side Classify(const Box& b) const;
};

// A bounding volume hierarchy over boxes, built once; Visible() marks the
// boxes inside or straddling a frustum. Deterministic: the same boxes give
// the same tree and the same answer.
class BoundingHierarchy {
 public:
  explicit BoundingHierarchy(const std::vector<Box>& boxes);
  // visible[i] is 1 when boxes[i] may show in the frustum. Boxes with a NaN
  // or an inverted (empty) extent are kept.
  std::vector<uint8_t> Visible(const Frustum& f) const;
  size_t nodeCount() const { return nodes_.size(); }

 private:
  struct Node {  // 64 bytes
    Box box;
    uint32_t first = 0, count = 0;  // leaf: items_[first, first + count)
    uint32_t left = 0, right = 0;   // inner (count == 0): children
  };
  uint32_t Build(uint32_t first, uint32_t count, const std::vector<Box>& boxes);
  void Mark(uint32_t node, const Frustum& f, bool inside, std::vector<uint8_t>& out) const;
  std::vector<Node> nodes_;
  std::vector<uint32_t> items_;
  std::vector<uint32_t> unbounded_;  // boxes that cannot be classified: always kept
  size_t size_ = 0;
};

}  // namespace sylva::mesh
