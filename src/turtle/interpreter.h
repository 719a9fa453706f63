// The 3D turtle (ABOP chapter 1.5, as cpfg implements it) reading a word.
//
// The turtle starts at the origin with heading H = (0,1,0), left
// L = (-1,0,0) and up U = (0,0,-1). A rotation by angle a "toward" a vector
// uses X' = X cos a + Y sin a, Y' = Y cos a - X sin a:
//   +(a) H toward L    -(a) H toward -L
//   &(a) H toward U    ^(a) H toward -U
//   /(a) L toward U    \(a) L toward -U
//   |    H and L reversed
//   $    L = (Y x H)/|Y x H| with Y = (0,1,0), U = L x H (unchanged when H is vertical)
// F(l) f(l) move by l (default: the grammar's step), F drawing a segment;
// G g move without recording a polygon vertex. Inside a polygon `{ ... }`, F
// and f add their end point as a vertex and draw no segment; `.` adds the
// current position. `[` `]` push and pop the turtle state (not the polygon).
// !(w) and #(w) set the width (a diameter); ! alone multiplies it by the
// width factor and # divides by it, or, with `width increment:`, they
// subtract and add the increment (cpfg; never below 0); '(c) ;(c) ,(c) set
// the colour index, ' and ; add 1, , subtracts 1 (never below 0); ~name(s) places a surface scaled
// by s (default 1), ~name(sx,sy,sz) scaled along L, H, U; @O(d) a sphere of diameter d (default:
// the width); @M(x,y,z) moves to (x,y,z) drawing nothing. Tropism (ABOP eq. 2.3): after every F and
// f moves, the frame turns about H x T by e |H x T| (cpfg's older tropism).
//
// cpfg's commands (its manual, and vlab's blackbox.c):
//   @o(d)  a disc of diameter d (default: the width) in the world's xy
//          plane, facing +z (cpfg's 2D circle): a polygon of 24 vertices
//   @c(d)  the same in the plane of H and L, facing U (cpfg's 3D circle)
//   @v     roll to vertical: the same as $
//   @Gs @Gc(n) @Ge(n)  a generalized cylinder: a tube along the cubic
//          Hermite curve through the turtle's positions at @Gs, each @Gc and
//          @Ge (tangents: the headings there times the distance between the
//          points times the @Gt factors), n segments per piece (default 8),
//          the width running linearly between the points unless @Gr says
//          otherwise; F inside draws nothing; a branch `[` draws on its own
//          and `]` resumes the cylinder
//   @Gt(a, b)  tangent factors: a arriving at a control point, b leaving it
//          (one value: both; cpfg's default 1.2)
//   @Gr(a, l, a2, l2)  the radius along a piece follows a Hermite curve in
//          the plane (t, radius) with tangent l (cos a, sin a) arriving at a
//          control point and l2 (cos a2, sin a2) leaving it (2 values: both);
//          @Gr(k), k != 0, multiplies their radius parts by the chord
//   _(e) _  set the elasticity to e, or add the elasticity increment
//          (cpfg's old tropism; the same one tropism as @Ts)
//   @Ts(i, e) @Ti(i, d) @Td(i, d)  set, raise and lower the elasticity of
//          tropism i (kept by [ ]): with TurtleDef::movements, the i-th of
//          them (d: its step S by default; an i beyond them: a warning, once
//          per module name and i); without, the one tropism above, i = 1
//
// cpfg's tropisms and torques (vlab cpfg movements.c, movement_adjust),
// before each F f G g moves, with e_k the elasticities of the turtle:
//   tropisms: V = sum over tropisms k of e_k (cos A_k T_k + sin A_k P_k),
//          P_k the unit vector perpendicular to T_k in the plane of H and
//          T_k, on H's side (L when H is parallel to T_k); H turns toward V
//          about H x V by min(|H x V|, 1) rad, and U is the up vector after
//          the last F or G (or @Tf) carried by the rotation that takes that
//          heading to H (cpfg's no-twist rule), L = H x U. A = 90 bends H
//          toward the plane perpendicular to T (plagiotropism).
//   torques: W = sum of e_k T_k over torques; with D the part of W/|W|
//          perpendicular to H times |W|, U turns about H away from D, by
//          min(|U x D|, 1) rad (cpfg's rot_by_quat turns by the negative
//          of its quaternion's angle), L = H x U; that frame is then the one
//          @R and the no-twist rule turn from.
//   @Tf    records the frame @R turns from; nothing else: Sylva's tubes
//          never twist
//   @R(hx, hy[, hz[, ux, uy, uz]])  set the heading (normalised), and U
//          when given perpendicular to it; otherwise U is the up vector
//          after the last F or G (or @Tf) turned as that heading turns to
//          the new one (cpfg's no-twist rule); L = H x U
//   {(t[, r]) ... }(t)  t != 0: cpfg's spline through the positions after
//          each F and f (and each `.` outside a polygon): t = 1 Hermite
//          (as @Gc), 2 Hermite closed, 3 uniform cubic B-spline, 4 the same
//          closed; r segments a piece (default 4), `.(n)` n; a branch
//          continues it on its own copy
//   @#(n)  the cross-section of the generalized cylinders that follow: cpfg's
//          contour n (DrawOptions::contours); @# alone, or an n with no
//          contour, the circle. Kept by [ ]. A piece between control points
//          whose contours are not both circles is a ContourTube: rings of
//          the contours interpolated by the curve parameter, point (x, y, z)
//          of a ring of radius r at centre + r (x U - y L) + (r z / chord) H
//          in the ring's frame (cpfg's make_contour)
//   @!(s)  the sides those contours are drawn with (at least 3; @! alone, 8)
//   ?(id, s) ... $  in a grammar with sub-L-systems: the scale (TurtleDef::subLsystems)
#pragma once

#include <map>
#include <memory>
#include <optional>

#include "core/status.h"
#include "lsys/grammar.h"
#include "lsys/word.h"
#include "mesh/contour.h"
#include "mesh/plant_geometry.h"

namespace sylva::turtle {

using mesh::Frame;
using mesh::PlantGeometry;
using mesh::Polygon;
using mesh::Segment;
using mesh::Sphere;
using mesh::SurfaceInstance;

// What the turtle needs of a grammar; TurtleDefFrom fills it from the
// grammar's header (angle:, step:, width:, width factor:, width increment:,
// tropism:).
struct TurtleDef {
  double angle = 90;  // degrees, for rotations with no parameter
  double step = 1;    // for F f G g with no parameter
  double width = 1;   // initial width (diameter)
  double widthFactor = 0.7;
  double widthIncrement = 0;  // > 0: ! and # subtract and add it (cpfg); 0: the factor
  double widthScale = 1;      // drawn diameter = width x widthScale
  Vec3 tropism{0, -1, 0};
  bool tropismGiven = false;  // the grammar or view file names it; else cpfg's `_` bends up (0,1,0)
  double susceptibility = 0;  // 0: no tropism (until @Ts, @Ti or @Td changes it)
  double elasticityIncrement = 0;  // @Ti and @Td without a value add and subtract it
  // cpfg's newer tropisms and torques (a view file's `tropism:` and `torque:`
  // lines, lsys::Movement), at most lsys::kMaxMovements. When there are any,
  // @Ts(i, e) @Ti(i, d) @Td(i, d) change the elasticity of the i-th (from 1),
  // and before each F f G g moves, they turn the frame (see Interpret).
  std::vector<lsys::Movement> movements;
  int initialColor = 0;    // colour index the turtle starts with
  int colorIncrement = 1;  // ; and , without a parameter add and subtract it
  // cpfg's sub-L-systems (lsys::Grammar::subLsystems): `?(id, scale)`
  // multiplies the turtle's scale by `scale` (default 1) and `$` restores it
  // (instead of rolling the turtle); the scale multiplies F f G g lengths,
  // the width (at once, and what ! and # set or add later) and surfaces.
  bool subLsystems = false;
  // `'` steps the colour index as `;` does (Sylva's grammars, ABOP); false
  // for a cpfg file (lsys::Grammar::cpfgFile), whose turtle has no `'`:
  // it is a module that draws nothing.
  bool quoteIsColor = true;
  // The tropism above bends as cpfg's older tropism does (interpret.c,
  // bend): after a move, H turns toward U by asin(e T.U), then toward L by
  // asin(e T.L) (each sine kept within [-1, 1]), instead of ABOP's turn
  // about H x T by e |H x T|; the two agree to first order in e. True for
  // a cpfg file (lsys::Grammar::cpfgFile), whose tropism comes from its
  // view file's `tropism direction:` and `initial elasticity:`.
  bool cpfgBend = false;
  // The grammar the word comes from (TurtleDefFrom sets it; it must outlive
  // the Interpret call), or null: an error about a module is located where
  // the grammar first writes that module's name (Grammar::symbolLoc).
  const lsys::Grammar* grammar = nullptr;
};

TurtleDef TurtleDefFrom(const lsys::Grammar& g);

// cpfg's generalized-cylinder cross-sections (mesh/contour.h), as a view
// file with `line style: cylinder` gives them: its `contour: n FILE.con`
// lines, `contour sides: S` and `twist of cylinders: on|off`.
//
// The frame a ring is drawn in (cpfg's generalized.c): at each control
// point the turtle's H, and an up vector; between two points, the up of the
// first carried to the ring's heading by the rotation that takes the one
// heading to the other. With twist on, the up at a control point is the
// turtle's and the rings between turn by the curve parameter times the angle
// that takes the carried up to it; with twist off (cpfg's default), the up
// at each control point is the one carried from the previous point, so the
// turtle's rolls between control points do not turn the cross-section.
struct CylinderContours {
  std::map<int, mesh::Contour> byId;  // `contour: n FILE.con`
  int sides = 8;                      // `contour sides:` (cpfg's default 8)
  bool twist = false;                 // `twist of cylinders: on`
};

struct DrawOptions {
  bool recordModules = false;  // fill PlantGeometry::modulePosition / moduleFrame
  // The word may draw at most this many primitives (segments and polygon
  // vertices, spheres, surfaces); counted before anything is allocated. A
  // segment takes 112 bytes: 2^24 of them, 1.75 GiB.
  uint64_t maxPrimitives = uint64_t(1) << 24;
  // The widths are pixels on screen (cpfg's line style `pixels`): copied
  // to PlantGeometry::widthInPixels.
  bool widthInPixels = false;
  // cpfg's line style cylinder: copied to PlantGeometry::cylinderStyle.
  bool cylinderStyle = false;
  // cpfg's contours for @#(n) (null: none; every generalized cylinder round).
  std::shared_ptr<const CylinderContours> contours;
  // The caller draws PlantGeometry::labels (`sylva render`); otherwise a
  // word with @L labels gets one warning that they are not drawn.
  bool drawsLabels = false;
};

// cpfg's MakeLabel: `format` (a text parameter of @L) with its printf
// conversions filled from `values` in order (%f %e %g %a with a number, %d
// %i %u %x %X %o %c with the number truncated, %% a percent sign); a
// conversion beyond the values, or of another kind (%s), is kept as text.
// Widths and precisions above 99 are cut to 99. At most 1,000 characters.
std::string FormatCpfgLabel(const std::string& format, const double* values, size_t count);

// Coordinates, widths and scales the turtle may produce: beyond this, float
// meshes lose all precision and squared lengths overflow.
inline constexpr double kMaxCoordinate = 1e15;

// Interprets `word` (already through the interpretation rules). Errors: an
// unmatched `]` or `}`, a polygon left open, and any coordinate, width or
// scale that is not finite or beyond +-kMaxCoordinate (naming the module).
Expected<PlantGeometry> Interpret(const lsys::Word& word, const lsys::SymbolTable& symbols,
                                  const TurtleDef& def, const DrawOptions& options = {});

// The same, drawing into `out` and reusing its arrays' memory: the viewer
// redraws a plant many times, and fresh memory costs the kernel a page
// clear per 4 KiB. On error `out` is left empty.
Status InterpretInto(const lsys::Word& word, const lsys::SymbolTable& symbols, const TurtleDef& def,
                     const DrawOptions& options, PlantGeometry& out);

}  // namespace sylva::turtle
