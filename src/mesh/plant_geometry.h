// PlantGeometry: parametric primitives, the tessellator's input. The turtle
// never emits triangles; the mesh tessellator turns these into triangles at
// the detail a camera or an export asks for.
//
// Units are the grammar's (a step of 1 is 1 unit); the world is Y-up and
// right-handed. Frames are the turtle's (H heading, L left, U up), unit and
// orthogonal, with U = L x H.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/math.h"

namespace sylva::mesh {

struct Frame {
  Vec3 heading{0, 1, 0};
  Vec3 left{-1, 0, 0};
  Vec3 up{0, 0, -1};
};

// One drawn step (F or G) of a branch. 112 bytes.
struct Segment {
  Vec3 start, end;
  Vec3 left;                 // turtle L at the start; H is (end - start) normalised
  float radiusStart = 0.5f;  // half the turtle width at the start and the end
  float radiusEnd = 0.5f;
  uint32_t branch = 0;  // id of the branch (a `[`...`]` span) it belongs to
  uint32_t parent = 0;  // branch that this branch grew from (itself for the trunk)
  uint16_t depth = 0;   // bracket nesting depth
  uint16_t color = 0;   // colour index
  uint32_t module = 0;  // index of the module that drew it
};

struct Polygon {
  std::vector<Vec3> vertices;  // in drawing order; not closed (first != last)
  uint16_t color = 0;
  uint32_t module = 0;  // the `{` that opened it
};

struct SurfaceInstance {
  std::string name;  // without the `~`
  Vec3 position;
  Frame frame;
  // Scale along the surface's own x, y, z (the turtle's L, H, U):
  // `~name(s)` is (s, s, s), `~name(sx, sy, sz)` each its own.
  Vec3 scale{1, 1, 1};
  uint16_t color = 0;
  uint32_t module = 0;
};

struct Sphere {
  Vec3 center;
  double radius = 0.5;
  uint16_t color = 0;
  uint32_t module = 0;
};

// A stretch of a generalized cylinder drawn with a cpfg contour (`@#(n)`,
// mesh/contour.h): rings of `ringSize` points each, placed in the world by
// the turtle, one ring after another. The tessellator joins point j of a
// ring to points j and j + 1 of the next (two triangles a quad), the
// normals smooth across the quads. `closed`: the last point of each ring
// is its first (a closed contour; the seam's normals are shared).
struct ContourTube {
  std::vector<Vec3> points;  // rings * ringSize
  uint32_t ringSize = 0;     // contour sides + 1
  bool closed = false;
  uint16_t color = 0;
  uint32_t module = 0;  // the @Gc or @Ge that drew its first piece

  size_t rings() const { return ringSize ? points.size() / ringSize : 0; }
};

// A cpfg label (`@L("flux %.0f", v)`, blackbox.c 'L'): the text, formatted
// with the module's numbers, drawn on the screen with its lower left corner
// where `position` falls, in the turtle's colour.
struct Label {
  Vec3 position;
  std::string text;
  uint16_t color = 0;
  uint32_t module = 0;
};

struct PlantGeometry {
  std::vector<Segment> segments;
  std::vector<Polygon> polygons;
  std::vector<SurfaceInstance> surfaces;
  std::vector<Sphere> spheres;
  std::vector<ContourTube> tubes;  // generalized cylinders with a contour
  std::vector<Label> labels;       // cpfg's @L: text, drawn by `sylva render` only
  // Branch ids of closed curves (cpfg's closed splines `{(2)`, `{(4)`):
  // where such a branch's run of segments ends where it began, the
  // tessellator joins the tube's end to its start (no caps, one ring).
  std::vector<uint32_t> loops;
  uint32_t branchCount = 0;
  Vec3 boundsMin{0, 0, 0}, boundsMax{0, 0, 0};  // of every point drawn or visited
  bool planar = true;  // every point lies in the z = 0 plane (ABOP's 2D figures)
  // Segment radii are pixels on screen, not world units: a cpfg view file's
  // line style `pixels` (`initial line width: 2 pixels`). The tessellator
  // turns them into world radii for its view (mesh/pixel_widths.h).
  bool widthInPixels = false;
  // cpfg's line style cylinder (a view file's `line style: cylinder`): the
  // plant is drawn as tubes even when it lies in a plane, as cpfg draws it,
  // not as the lines of a 2D figure (plant::IsLineFigure).
  bool cylinderStyle = false;

  // Problems that do not stop the drawing (an unmatched `}`, a polygon with
  // fewer than 3 vertices), each naming the module.
  std::vector<std::string> warnings;
  // The same about a module the grammar writes (`@Ts(4, 0.2)` naming a
  // tropism the view file does not define): reported at the place the
  // grammar first writes that module name (lsys::Grammar::symbolLoc).
  struct ModuleWarning {
    std::string symbol;  // the module's name, as the grammar writes it
    std::string message;
  };
  std::vector<ModuleWarning> moduleWarnings;

  // Optional per-module state (DrawOptions::recordModules): the turtle's
  // position and frame after each module.
  std::vector<Vec3> modulePosition;
  std::vector<Frame> moduleFrame;
};

}  // namespace sylva::mesh
