#include "turtle/interpreter.h"

#include <math.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <set>
#include <type_traits>

#include "core/assert.h"
#include "core/memory.h"

namespace sylva::turtle {
namespace {

constexpr int kDiscSides = 24;     // polygon vertices of a @o or @c disc
constexpr int kCylinderRings = 8;  // segments per @Gc/@Ge piece without a parameter
constexpr int kSplineRings = 4;    // segments per `{(n)` spline piece (cpfg's DEFAULT_RINGS)
constexpr uint32_t kNoBranch = UINT32_MAX;

enum class Op : uint8_t {
  kNone,
  kForwardDraw,
  kForwardMove,
  kForwardDrawNoVertex,
  kForwardMoveNoVertex,
  kTurnLeft,
  kTurnRight,
  kPitchDown,
  kPitchUp,
  kRollLeft,
  kRollRight,
  kTurnAround,
  kLevel,
  kPush,
  kPop,
  kWidth,
  kWidthUp,
  kColor,
  kColorDown,
  kPolygonBegin,
  kVertex,
  kPolygonEnd,
  kSurface,
  kSphere,
  kMoveTo,
  kDisc,          // @o
  kCircle,        // @c
  kGcStart,       // @Gs
  kGcPoint,       // @Gc
  kGcEnd,         // @Ge
  kTropismSet,    // @Ts
  kTropismUp,     // @Ti
  kTropismDown,   // @Td
  kElasticity,    // _ (cpfg: elasticity of the tropism)
  kTwistForce,    // @Tf
  kGcTangent,     // @Gt
  kGcRadius,      // @Gr
  kContour,       // @#: the cylinders' contour
  kContourSides,  // @!: the sides contours are drawn with
  kSubStart,      // ?(id, scale): a sub-L-system starts (grammars with sub-L-systems)
  kSubEnd,        // $ there: it ends
  kSplineBegin,   // {(type[, rings]): a polygon when type is 0, else cpfg's spline
  kSplineEnd,     // }(type): the same
  kSetHeading,    // @R(hx, hy[, hz[, ux, uy, uz]])
  kLabel,         // @L(text, values...): cpfg's label
};

Op OpFor(const std::string& name) {
  if (name.size() == 1) {
    switch (name[0]) {
      case 'F':
        return Op::kForwardDraw;
      case 'f':
        return Op::kForwardMove;
      case 'G':
        return Op::kForwardDrawNoVertex;
      case 'g':
        return Op::kForwardMoveNoVertex;
      case '+':
        return Op::kTurnLeft;
      case '-':
        return Op::kTurnRight;
      case '&':
        return Op::kPitchDown;
      case '^':
        return Op::kPitchUp;
      case '/':
        return Op::kRollRight;
      case '\\':
        return Op::kRollLeft;
      case '|':
        return Op::kTurnAround;
      case '$':
        return Op::kLevel;
      case '[':
        return Op::kPush;
      case ']':
        return Op::kPop;
      case '!':
        return Op::kWidth;
      case '\'':
      case ';':
        return Op::kColor;
      case ',':
        return Op::kColorDown;
      case '#':
        return Op::kWidthUp;
      case '{':
        return Op::kPolygonBegin;
      case '.':
        return Op::kVertex;
      case '}':
        return Op::kPolygonEnd;
      case '_':
        return Op::kElasticity;
      default:
        return Op::kNone;
    }
  }
  if (name[0] == '~') return Op::kSurface;
  if (name == "@O") return Op::kSphere;
  if (name == "@M") return Op::kMoveTo;
  if (name == "@v") return Op::kLevel;  // cpfg's roll to vertical is `$`
  if (name == "@o") return Op::kDisc;
  if (name == "@c") return Op::kCircle;
  if (name == "@Gs") return Op::kGcStart;
  if (name == "@Gc") return Op::kGcPoint;
  if (name == "@Ge") return Op::kGcEnd;
  if (name == "@Gt") return Op::kGcTangent;
  if (name == "@Gr") return Op::kGcRadius;
  if (name == "@Ts") return Op::kTropismSet;
  if (name == "@Ti") return Op::kTropismUp;
  if (name == "@Td") return Op::kTropismDown;
  if (name == "@Tf") return Op::kTwistForce;
  if (name == "@R") return Op::kSetHeading;
  if (name == "@L") return Op::kLabel;
  if (name == "@#") return Op::kContour;
  if (name == "@!") return Op::kContourSides;
  return Op::kNone;
}

// What `[` saves and `]` restores. 112 bytes: copied at every bracket.
struct State {
  Vec3 pos{0, 0, 0};
  Frame frame;
  double width = 1;
  uint32_t branch = 0;
  uint16_t depth = 0;
  uint16_t color = 0;
};

// The part of the state only cpfg's @T and @G commands change, saved on its
// own stack only when the word's symbols include them, so that State stays
// small for every other word.
// How the pieces of a generalized cylinder bend and swell (cpfg's turtle
// fields tangent_parameter, radius_tangent, scale_radius_tangents), set by
// @Gt and @Gr and read at each control point.
struct CylinderShape {
  // @Gt(a, b): the Hermite tangents are the headings times the chord times
  // b leaving a control point and a arriving at one (cpfg's default 1.2).
  double arriving = 1.2, leaving = 1.2;
  // @Gr(a, l[, a2, l2]): the radius along a piece is a Hermite curve in the
  // plane (t, radius) whose tangent arriving at a control point is
  // l (cos a, sin a) and leaving it l2 (cos a2, sin a2) (the first pair
  // when there is no second); (0, 0): none, a straight line.
  Vec2 radiusArriving{0, 0}, radiusLeaving{0, 0};
  bool scaleRadiusTangents = false;  // @Gr(k), k != 0: their radius parts times the chord
};

// The contour id of cpfg's default circle (no @#, or @# alone).
constexpr int32_t kCircle = std::numeric_limits<int32_t>::min();

struct CpfgState {
  double elasticity = 0;  // the older tropism's susceptibility (cpfg: elasticity), `_` changes it
  // The elasticity of each of TurtleDef::movements (cpfg: the turtle's
  // movements[i].elasticity), @Ts @Ti @Td change them.
  std::array<double, lsys::kMaxMovements> movement{};
  int32_t cylinder = -1;  // the open generalized cylinder (@Gs), or -1
  // In a branch opened inside a generalized cylinder: that cylinder, whose
  // last control point starts the branch's first @Gc/@Ge piece (cpfg's `[`
  // pushes the turtle with its open cylinder); -1: none.
  int32_t branchFrom = -1;
  CylinderShape shape;
  double scale = 1;     // sub-L-system scale (cpfg: scale_factor) of steps, widths, surfaces
  int32_t spline = -1;  // the open `{(n)` spline (an index into the splines), or -1
  // The frame after the last F or G (or @Tf): @R without an up vector
  // turns this up vector as it turns this heading (cpfg: prev_heading,
  // prev_up; the "no twist" rule of adjust_up_and_left).
  Vec3 prevHeading{0, 1, 0}, prevUp{0, 0, -1};
  int32_t contour = kCircle;  // @#: the contour id, or kCircle
  int32_t sides = 8;          // @!: the sides of contours
};

// A control point of a generalized cylinder: where the turtle was at @Gs,
// @Gc or @Ge.
struct ControlPoint {
  Vec3 pos, heading, left;
  double width = 0;
  uint16_t color = 0;
  CylinderShape shape;  // the turtle's @Gt and @Gr settings there
  // For contours: the up vector of the cross-section's frame (the turtle's,
  // or carried from the previous point: CylinderContours), the contour and
  // its sides.
  Vec3 up{0, 0, -1};
  int32_t contour = kCircle;
  int32_t sides = 8;
};

// An open generalized cylinder: its last control point, the branch id its
// tube segments carry, and the contour tube its last piece went to (-1:
// none), which the next piece continues.
struct Cylinder {
  ControlPoint last;
  uint32_t branch = 0;
  int32_t tube = -1;
};

// cpfg's older generalized cylinder (vlab cpfg general.c, InitializeSpline,
// SetControlPoint, FinishSpline): `{(type, rings)` opens it, and the
// turtle's position after each F and f, and at each `.` outside a polygon,
// is a control point; `}(type)` ends it. Types: 1 an open Hermite curve
// (through the points, tangents along the headings, as @Gc), 2 the same
// closed back to the first point, 3 an open uniform cubic B-spline (near the
// points, not through them), 4 the same closed. Each piece between two
// control points is cut into `rings` segments (cpfg's default 4).
struct Spline {
  bool closed = false, bspline = false;
  int rings = kSplineRings;
  uint32_t count = 0;           // control points so far
  uint32_t branch = kNoBranch;  // the branch id of its segments, made at its first piece
  uint32_t module = 0;          // the `{` that opened it
  uint32_t depth = 0;           // the bracket depth that owns this copy (copied on write)
  bool opened = true;           // opened by a `{` at that depth (not a branch's copy)
  ControlPoint first[3];        // a closed spline's first points: they close it
  ControlPoint last[3];         // the last 3 points (B-spline) or the last one (Hermite: last[2])
};

// X' = X cos a + Y sin a, Y' = Y cos a - X sin a: X turns toward Y.
[[gnu::always_inline]] inline void Rotate(Vec3& x, Vec3& y, double c, double s) {
  const Vec3 nx = x * c + y * s;
  const Vec3 ny = y * c - x * s;
  x = nx;
  y = ny;
}

// Both at once where the C library offers it (glibc's sincos).
inline void SinCosRadians(double r, double* s, double* c) {
#if defined(__GLIBC__)
  ::sincos(r, s, c);
#else
  *s = std::sin(r);
  *c = std::cos(r);
#endif
}

// sin and cos of a small angle (|r| <= 0.5 rad) by their Taylor series to
// degree 17 and 18: the first omitted terms are below 1e-22, so the result
// is the correctly rounded double in practice, and it does not depend on the
// C library. Tropism turns the frame by such angles after every step.
inline void SinCosSmall(double r, double* s, double* c) {
  if (std::abs(r) > 0.5) {
    SinCosRadians(r, s, c);
    return;
  }
  const double x2 = r * r;
  double ps = 1.0 / 355687428096000.0;   // 1/17!
  ps = 1.0 / 1307674368000.0 - x2 * ps;  // 1/15!
  ps = 1.0 / 6227020800.0 - x2 * ps;     // 1/13!
  ps = 1.0 / 39916800.0 - x2 * ps;       // 1/11!
  ps = 1.0 / 362880.0 - x2 * ps;         // 1/9!
  ps = 1.0 / 5040.0 - x2 * ps;
  ps = 1.0 / 120.0 - x2 * ps;
  ps = 1.0 / 6.0 - x2 * ps;
  *s = r - r * x2 * ps;
  double pc = 1.0 / 6402373705728000.0;   // 1/18!
  pc = 1.0 / 20922789888000.0 - x2 * pc;  // 1/16!
  pc = 1.0 / 87178291200.0 - x2 * pc;     // 1/14!
  pc = 1.0 / 479001600.0 - x2 * pc;       // 1/12!
  pc = 1.0 / 3628800.0 - x2 * pc;         // 1/10!
  pc = 1.0 / 40320.0 - x2 * pc;
  pc = 1.0 / 720.0 - x2 * pc;
  pc = 1.0 / 24.0 - x2 * pc;
  pc = 0.5 - x2 * pc;
  *c = 1.0 - x2 * pc;
}

// sin and cos of an angle in degrees, with a small cache: parametric plants
// reuse a handful of angles millions of times.
class SinCos {
 public:
  void Get(double degrees, double* s, double* c) {
    uint64_t bits;
    std::memcpy(&bits, &degrees, 8);
    Entry& e = cache_[(bits * 0x9E3779B97F4A7C15ULL) >> 60];  // Fibonacci hashing
    if (!e.valid || e.degrees != degrees) {
      e.valid = true;
      e.degrees = degrees;
      SinCosRadians(degrees * kDegToRad, &e.s, &e.c);
    }
    *s = e.s;
    *c = e.c;
  }

 private:
  struct Entry {
    double degrees = 0, s = 0, c = 1;
    bool valid = false;
  };
  Entry cache_[16];
};

// Re-orthonormalises a frame that has drifted by rounding over many turns.
inline void Orthonormalise(Frame& f) {
  f.heading.normalize();
  f.up = f.left.cross(f.heading);
  f.up.normalize();
  f.left = f.heading.cross(f.up);
}

}  // namespace

TurtleDef TurtleDefFrom(const lsys::Grammar& g) {
  TurtleDef d;
  d.grammar = &g;
  d.angle = g.angle;
  d.step = g.step;
  d.width = g.width;
  d.widthFactor = g.widthFactor;
  d.widthIncrement = g.widthIncrement;
  d.widthScale = g.widthScale;
  if (g.tropism) {
    d.tropism = Vec3(g.tropism->x, g.tropism->y, g.tropism->z);
    d.susceptibility = g.tropism->susceptibility;
    d.tropismGiven = true;
  }
  d.initialColor = g.initialColor;
  d.colorIncrement = g.colorIncrement;
  d.elasticityIncrement = g.elasticityIncrement;
  d.movements = g.movements;
  if (d.movements.size() > size_t(lsys::kMaxMovements)) d.movements.resize(lsys::kMaxMovements);
  d.subLsystems = g.subLsystems;
  d.quoteIsColor = !g.cpfgFile;
  d.cpfgBend = g.cpfgFile;
  return d;
}

Expected<PlantGeometry> Interpret(const lsys::Word& word, const lsys::SymbolTable& symbols,
                                  const TurtleDef& def, const DrawOptions& options) {
  PlantGeometry g;
  if (Status s = InterpretInto(word, symbols, def, options, g); !s.ok()) return s.error();
  return g;
}

// Module i as written: its name and parameters (%g), for error messages.
[[gnu::noinline]] static std::string ModuleText(const lsys::Word& word,
                                                const lsys::SymbolTable& symbols, size_t i) {
  std::string text = symbols.name(word.symbols[i]);
  const auto params = word.ParamsOf(i);
  for (size_t k = 0; k < params.size(); ++k) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", params[k]);
    text += k ? ',' : '(';
    text += buf;
  }
  if (!params.empty()) text += ")";
  return text;
}

// ABOP eq. 2.3: after a move, the frame turns about H x T by e |H x T|
// (Rodrigues' rotation). True when it turned.
static inline bool ApplyTropism(const Vec3& tropismVector, double e, Frame& f) {
  if (e == 0) return false;
  const Vec3 axis = f.heading.cross(tropismVector);
  const double norm = axis.norm();
  if (!(norm > 1e-12)) return false;
  // v' = v cos a + (k x v) sin a + k (k.v)(1 - cos a).
  const double a = e * norm;
  const Vec3 k = axis / norm;
  double sa, ca;
  SinCosSmall(a, &sa, &ca);
  auto turn = [&](Vec3& v) { v = v * ca + k.cross(v) * sa + k * (k.dot(v) * (1 - ca)); };
  turn(f.heading);
  turn(f.left);
  turn(f.up);
  return true;
}

// Rodrigues' rotation of v about the unit axis k by the angle whose sine and
// cosine are sa and ca.
static inline Vec3 Turned(const Vec3& v, const Vec3& k, double sa, double ca) {
  return v * ca + k.cross(v) * sa + k * (k.dot(v) * (1 - ca));
}

// cpfg's "no twist" rule (adjust_up_and_left): the up vector after the last
// F or G (or @Tf), turned by the rotation that takes the heading there to
// h; `up` when the two headings are parallel (|H0 x h| <= 1e-6). Made
// exactly perpendicular to h.
static Vec3 NoTwistUp(const Vec3& prevHeading, const Vec3& prevUp, const Vec3& h, Vec3 up) {
  const Vec3 axis = prevHeading.cross(h);
  const double sinA = axis.norm();
  if (sinA > 1e-6) {
    const double cosA = prevHeading.dot(h);
    up = Turned(prevUp, axis / sinA, sinA, cosA);
  }
  up -= h * up.dot(h);
  const double n = up.norm();
  if (n > 1e-12) return up / n;
  // U along H: any perpendicular
  return h.cross(std::abs(h.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitZ()).normalized();
}

// cpfg's older tropism after a move (vlab cpfg interpret.c, bend): H turns
// toward U by asin(e T.U), then toward L by asin(e T.L). True when it
// turned.
static bool CpfgBend(const Vec3& tropismVector, double e, Frame& f) {
  if (e == 0) return false;
  const double towardUp = std::clamp(e * tropismVector.dot(f.up), -1.0, 1.0);
  Rotate(f.heading, f.up, std::sqrt(1 - towardUp * towardUp), towardUp);
  const double towardLeft = std::clamp(e * tropismVector.dot(f.left), -1.0, 1.0);
  Rotate(f.heading, f.left, std::sqrt(1 - towardLeft * towardLeft), towardLeft);
  return towardUp != 0 || towardLeft != 0;
}

// @R(hx, hy[, hz[, ux, uy, uz]]): cpfg's set heading (vlab cpfg
// blackbox.c, 'R'). The heading becomes (hx, hy, hz) normalised (hz = 0
// when not given; (0, 1, 0) when all are 0). With 6 parameters, a non-zero
// up vector perpendicular to it (within 1e-9 of its length) becomes U,
// normalised. Otherwise U follows cpfg's "no twist" rule
// (adjust_up_and_left): the rotation that takes the heading after the last
// F or G (or @Tf; the initial one before any) to the new heading turns the
// up vector there; when they are parallel (|H0 x H| <= 1e-6) U stays. U is
// then made exactly perpendicular to H, and L = H x U.
[[gnu::noinline]] static void SetHeading(const double* p, uint32_t np, const Vec3& prevHeading,
                                         const Vec3& prevUp, Frame& f) {
  Vec3 h(p[0], p[1], np >= 3 ? p[2] : 0.0);
  // stableNorm: norm() overflows to inf past 1e154 (the heading became 0)
  // and underflows to 0 below 1e-154 (it became +Y).
  const double hn = h.stableNorm();
  h = hn == 0 ? Vec3(0, 1, 0) : Vec3(h / hn);  // NaN stays NaN: the range check names it
  Vec3 up = f.up;
  bool given = false;
  if (np >= 6) {
    const Vec3 u(p[3], p[4], p[5]);
    const double un = u.stableNorm();
    if (un > 0 && std::abs(u.dot(h)) <= 1e-9 * un) {
      up = u / un;
      given = true;
    }
  }
  if (!given) up = NoTwistUp(prevHeading, prevUp, h, up);
  f.heading = h;
  f.up = up;
  f.left = h.cross(up);
}

// cpfg's tropisms and torques, before a move (vlab cpfg movements.c,
// movement_adjust; interpreter.h has the formulas): the first `count`
// movements, `e` holding the elasticity of each. True when the frame turned.
[[gnu::noinline]] static bool ApplyMovements(const lsys::Movement* movements, size_t count,
                                             const double* e, Vec3& prevHeading, Vec3& prevUp,
                                             Frame& f) {
  // The direction H bends toward: each tropism's T, or at an angle A from it.
  Vec3 v = Vec3::Zero(), w = Vec3::Zero();
  for (size_t k = 0; k < count; ++k) {
    const lsys::Movement& m = movements[k];
    const Vec3 t(m.x, m.y, m.z);
    if (m.torque) {
      w += e[k] * t;
      continue;
    }
    if (e[k] == 0) continue;
    double sa, ca;
    SinCosRadians(m.angle * kDegToRad, &sa, &ca);
    v += (ca * e[k]) * t;
    if (sa != 0) {
      // T x (H x T) / |H x T|: perpendicular to T, toward H (cpfg takes L
      // for H x T when H is parallel to T).
      Vec3 r = f.heading.cross(t);
      double rn = r.norm();
      if (rn < 1e-7) {
        r = f.left;
        rn = 1;
      }
      v += (sa * e[k] / rn) * t.cross(r);
    }
  }
  bool turned = false;
  // H turns toward V about H x V by |H x V| (at most 1 rad); U follows by
  // the no-twist rule (cpfg's adjust_up_and_left).
  const Vec3 axis = f.heading.cross(v);
  const double an = axis.norm();
  if (an >= 1e-6) {
    double sa, ca;
    SinCosSmall(std::min(an, 1.0), &sa, &ca);
    f.heading = Turned(f.heading, axis / an, sa, ca);
    f.up = NoTwistUp(prevHeading, prevUp, f.heading, f.up);
    f.left = f.heading.cross(f.up);
    turned = true;
  }
  // Torque: U turns about H away from the part of W perpendicular to H.
  const double wn = w.norm();
  if (wn > 0) {
    const Vec3 hw = f.heading.cross(w / wn);
    if (hw.squaredNorm() > 1e-8) {
      const Vec3 d = hw.cross(f.heading) * wn;
      const Vec3 ud = f.up.cross(d);
      const double un = ud.norm();
      if (un >= 1e-7) {
        double sa, ca;
        SinCosSmall(std::min(un, 1.0), &sa, &ca);
        f.up = Turned(f.up, ud / un, -sa, ca);
        f.left = f.heading.cross(f.up);
        turned = true;
      }
      // cpfg: this twist is wanted; the no-twist rule turns from here.
      prevHeading = f.heading;
      prevUp = f.up;
    }
  }
  return turned;
}

// @o and @c: a disc of diameter `diameter` centred at `centre` in the plane
// of the unit vectors a and b, as a polygon of kDiscSides vertices running
// from a toward b (its normal is a x b).
[[gnu::noinline]] static void AddDisc(const Vec3& centre, const Vec3& a, const Vec3& b,
                                      double diameter, uint16_t color, uint32_t module,
                                      PlantGeometry& g) {
  Polygon poly;
  poly.vertices.reserve(kDiscSides);
  const double r = diameter * 0.5;
  for (int k = 0; k < kDiscSides; ++k) {
    double s, c;
    SinCosRadians(2 * kPi * k / kDiscSides, &s, &c);
    poly.vertices.push_back(centre + (a * c + b * s) * r);
  }
  poly.color = color;
  poly.module = module;
  g.polygons.push_back(std::move(poly));
}

// The radius profile of one piece of a generalized cylinder or spline from
// control point a to b, as cpfg draws it (vlab cpfg general.c,
// interpolate_connection, version 3400 on). At ring k of n the curve
// parameter t and the radius are the cubic Hermite curve in the plane
// (t, radius) from (0, r_a) to (1, r_b) with tangents a.shape.radiusLeaving
// and b.shape.radiusArriving (@Gr; a zero tangent is (1, r_b - r_a), so
// without @Gr t = k / n and the width runs linearly). `chord` scales the
// radius tangents under @Gr(1).
struct RadiusCurve {
  RadiusCurve(const ControlPoint& a, const ControlPoint& b, double chord)
      : r0(0.5 * a.width), dr(0.5 * (b.width - a.width)), endWidth(b.width) {
    // Radii are half widths (cpfg's line_width / 2).
    s0 = a.shape.radiusLeaving;
    s1 = b.shape.radiusArriving;
    if (b.shape.scaleRadiusTangents) {
      s0.y() *= chord;
      s1.y() *= chord;
    }
    if (s0.x() == 0 && s0.y() == 0) s0 = Vec2(1, dr);
    if (s1.x() == 0 && s1.y() == 0) s1 = Vec2(1, dr);
    c2 = Vec2(3 - 2 * s0.x() - s1.x(), 3 * dr - 2 * s0.y() - s1.y());
    c3 = Vec2(-2 + s0.x() + s1.x(), -2 * dr + s0.y() + s1.y());
  }
  // Ring k of `rings`: the curve parameter and the width (ring `rings` is b).
  void Ring(int k, int rings, double* t, double* width) const {
    if (k == rings) {
      *t = 1;
      *width = endWidth;
      return;
    }
    const double r = double(k) / rings;
    *t = ((c3.x() * r + c2.x()) * r + s0.x()) * r;
    *width = 2 * (((c3.y() * r + c2.y()) * r + s0.y()) * r + r0);
  }
  double r0, dr, endWidth;
  Vec2 s0, s1, c2, c3;
};

// The segments of one piece from control point a to b, along `curve`
// (curve(t), t in [0, 1], from `start` to `end`), cut into `rings` segments
// of one branch, with the radii of RadiusCurve.
template <class Curve>
static void AddPiece(const ControlPoint& a, const ControlPoint& b, const Vec3& start,
                     const Vec3& end, double chord, int rings, const Curve& curve,
                     double widthScale, uint32_t branch, uint32_t parent, uint16_t depth,
                     uint32_t module, PlantGeometry& g) {
  const RadiusCurve radius(a, b, chord);
  Vec3 prev = start;
  double prevWidth = a.width;
  for (int k = 1; k <= rings; ++k) {
    double t, w;
    radius.Ring(k, rings, &t, &w);
    const Vec3 p = k == rings ? end : curve(t);
    Segment sg;
    sg.start = prev;
    sg.end = p;
    sg.left = a.left;
    sg.radiusStart = float(prevWidth * widthScale * 0.5);
    sg.radiusEnd = float(w * widthScale * 0.5);
    sg.branch = branch;
    sg.parent = parent;
    sg.depth = depth;
    sg.color = a.color;
    sg.module = module;
    g.segments.push_back(sg);
    prev = p;
    prevWidth = w;
  }
}

// The cubic Hermite curve of a piece (@Gc, @Ge, and `{(1)` and `{(2)`
// splines) from control point a to b with tangents H_a |b - a| a.leaving and
// H_b |b - a| b.arriving (@Gt), with its radius profile.
struct PieceCurve {
  PieceCurve(const ControlPoint& from, const ControlPoint& to)
      : a(from), b(to), chord((b.pos - a.pos).norm()), radius(a, b, chord) {
    m0 = a.heading * (chord * a.shape.leaving);
    m1 = b.heading * (chord * b.shape.arriving);
  }
  void Ring(int k, int rings, double* t, double* width) const { radius.Ring(k, rings, t, width); }
  Vec3 Point(double t) const {
    const double t2 = t * t, t3 = t2 * t;
    return a.pos * (2 * t3 - 3 * t2 + 1) + m0 * (t3 - 2 * t2 + t) + b.pos * (3 * t2 - 2 * t3) +
           m1 * (t3 - t2);
  }
  Vec3 Tangent(double t) const {
    const double t2 = t * t;
    return (a.pos - b.pos) * (6 * t2 - 6 * t) + m0 * (3 * t2 - 4 * t + 1) + m1 * (3 * t2 - 2 * t);
  }
  const ControlPoint& a;
  const ControlPoint& b;
  double chord;
  RadiusCurve radius;
  Vec3 m0, m1;
};

// A Hermite piece as `rings` tube segments of one branch.
[[gnu::noinline]] static void AddCylinderPiece(const ControlPoint& a, const ControlPoint& b,
                                               int rings, double widthScale, uint32_t branch,
                                               uint32_t parent, uint16_t depth, uint32_t module,
                                               PlantGeometry& g) {
  const PieceCurve curve(a, b);
  AddPiece(
      a, b, a.pos, b.pos, curve.chord, rings, [&](double t) { return curve.Point(t); }, widthScale,
      branch, parent, depth, module, g);
}

// A uniform cubic B-spline piece (`{(3)` and `{(4)` splines) over the
// control points q0 q1 q2 q3: from (q0 + 4 q1 + q2)/6 to (q1 + 4 q2 + q3)/6,
// with the width, colour and @Gr settings of q1 at its start and q2 at its
// end (cpfg general.c).
[[gnu::noinline]] static void AddBSplinePiece(const ControlPoint& q0, const ControlPoint& q1,
                                              const ControlPoint& q2, const ControlPoint& q3,
                                              int rings, double widthScale, uint32_t branch,
                                              uint32_t parent, uint16_t depth, uint32_t module,
                                              PlantGeometry& g) {
  const Vec3 c0 = (q0.pos + 4 * q1.pos + q2.pos) / 6;
  const Vec3 c1 = (q2.pos - q0.pos) / 2;
  const Vec3 c2 = (q0.pos - 2 * q1.pos + q2.pos) / 2;
  const Vec3 c3 = (-q0.pos + 3 * q1.pos - 3 * q2.pos + q3.pos) / 6;
  auto bspline = [&](double t) { return Vec3(((c3 * t + c2) * t + c1) * t + c0); };
  const Vec3 end = (q1.pos + 4 * q2.pos + q3.pos) / 6;
  AddPiece(q1, q2, c0, end, (end - c0).norm(), rings, bspline, widthScale, branch, parent, depth,
           module, g);
}

// `v` turned by the rotation that takes the unit vector `from` to the unit
// vector `to` about their common perpendicular (cpfg's adjust_up_and_leftS),
// then made perpendicular to `to` and unit.
static Vec3 Carry(const Vec3& v, const Vec3& from, const Vec3& to) {
  const Vec3 axis = from.cross(to);
  const double s = axis.norm(), c = from.dot(to);
  Vec3 r = v;
  if (s > 1e-12) {
    const Vec3 k = axis / s;
    r = v * c + k.cross(v) * s + k * (k.dot(v) * (1 - c));
  }
  r -= to * r.dot(to);
  const double n = r.norm();
  if (n > 1e-12) return r / n;
  return mesh::Frame{}.up;  // degenerate (v along to): any perpendicular will not do better
}

// `v` (perpendicular to the unit axis k) turned about k by the angle whose
// cosine and sine are c and s.
static Vec3 Turn(const Vec3& v, const Vec3& k, double c, double s) {
  return v * c + k.cross(v) * s;
}

// The piece as rings of the contours of a and b (each `ring` of ringSize
// points, mesh::SampleContour), interpolated by the curve parameter, in the
// frame carried along the curve (CylinderContours), appended to g.tubes:
// to the tube `tube` when it ends where this piece starts, else to a new
// one (`tube` is set to it). cpfg draws nothing for a piece shorter than
// 1e-5.
[[gnu::noinline]] static void AddContourPiece(const ControlPoint& a, const ControlPoint& b,
                                              const std::vector<Vec3>& ringA,
                                              const std::vector<Vec3>& ringB, bool closed,
                                              int rings, double widthScale, bool twist,
                                              uint32_t module, int32_t& tube, PlantGeometry& g) {
  const PieceCurve curve(a, b);
  if (!(curve.chord >= 1e-5)) return;
  SYLVA_DCHECK(ringA.size() == ringB.size());
  const size_t W = ringA.size();
  // The angle from the up carried to b to b's own up, about b's heading.
  double twistAngle = 0;
  if (twist) {
    const Vec3 carried = Carry(a.up, a.heading, b.heading);
    twistAngle = std::atan2(b.heading.dot(carried.cross(b.up)), carried.dot(b.up));
  }
  std::vector<Vec3> points;
  points.reserve(size_t(rings + 1) * W);
  for (int k = 0; k <= rings; ++k) {
    double t, w;
    Vec3 p, h, up;
    if (k == 0) {
      t = 0;
      w = a.width;
      p = a.pos;
      h = a.heading;
      up = a.up;
    } else if (k == rings) {
      t = 1;
      w = b.width;
      p = b.pos;
      h = b.heading;
      up = b.up;
    } else {
      curve.Ring(k, rings, &t, &w);
      p = curve.Point(t);
      h = curve.Tangent(t);
      const double n = h.norm();
      h = n > 1e-12 ? Vec3(h / n) : a.heading;
      up = Carry(a.up, a.heading, h);
      if (twistAngle != 0) up = Turn(up, h, std::cos(twistAngle * t), std::sin(twistAngle * t));
    }
    const Vec3 left = h.cross(up);
    const double r = 0.5 * w * widthScale;
    const double along = r / curve.chord;
    for (size_t j = 0; j < W; ++j) {
      const Vec3 c = ringA[j] * (1 - t) + ringB[j] * t;
      points.push_back(p + up * (r * c.x()) - left * (r * c.y()) + h * (along * c.z()));
    }
  }
  if (tube >= 0) {
    mesh::ContourTube& last = g.tubes[size_t(tube)];
    bool joins = last.ringSize == W && last.color == a.color && last.closed == closed;
    for (size_t j = 0; joins && j < W; ++j) {
      const Vec3& q = last.points[last.points.size() - W + j];
      joins = (q - points[j]).norm() <= 1e-9 * (1 + q.norm());
    }
    if (joins) {
      last.points.insert(last.points.end(), points.begin() + std::ptrdiff_t(W), points.end());
      return;
    }
  }
  mesh::ContourTube t;
  t.points = std::move(points);
  t.ringSize = uint32_t(W);
  t.closed = closed;
  t.color = a.color;
  t.module = module;
  tube = int32_t(g.tubes.size());
  g.tubes.push_back(std::move(t));
}

// The rings of a @Gc(n) or @Ge(n) piece: n (at least 1), kCylinderRings
// without a parameter. A double: the caller compares it with its limit
// before converting.
static double CylinderRings(const double* p, uint32_t np) {
  if (!np) return kCylinderRings;
  if (!(p[0] >= 1)) return 1;  // NaN and below 1 (cpfg: at least 1)
  return std::floor(p[0]);
}

// The rings of a `{(type, rings)` spline or of a `.(rings)` piece in one:
// cpfg truncates to an integer; 0 (or none) is `fallback`, below 1 a
// straight segment. A double: the caller compares it with its limit before
// converting.
static double SplineRings(double v, double fallback) {
  if (!(v == v)) return 1;  // NaN
  const double r = std::trunc(v);
  if (r == 0) return fallback;
  return r < 1 ? 1 : r;
}

// An upper bound on the segments that `{(n)` splines draw: every F, f and
// `.` while a spline is open in the turtle's branch draws at most a piece,
// and a closing `}` at most 3.
static double SplineSegmentBound(const lsys::Word& word, const std::vector<Op>& ops) {
  struct Open {
    bool open = false;
    double rings = kSplineRings;
  };
  std::vector<Open> stack;
  Open s;
  double total = 0;
  const bool hasParams = word.HasParams();
  for (size_t i = 0; i < word.size(); ++i) {
    const Op op = ops[word.symbols[i]];
    const uint32_t np = hasParams ? word.paramStart[i + 1] - word.paramStart[i] : 0;
    const double* p = np ? word.params.data() + word.paramStart[i] : nullptr;
    switch (op) {
      case Op::kPush:
        stack.push_back(s);
        break;
      case Op::kPop:
        if (!stack.empty()) {
          s = stack.back();
          stack.pop_back();
        }
        break;
      case Op::kSplineBegin:
        if (np && p[0] != 0) {
          s.open = true;
          s.rings = SplineRings(np >= 2 ? p[1] : 0, kSplineRings);
        }
        break;
      case Op::kSplineEnd:
        if (np && p[0] != 0 && s.open) {
          total += 3 * s.rings;
          s.open = false;
        }
        break;
      case Op::kForwardDraw:
      case Op::kForwardMove:
        if (s.open) total += s.rings;
        break;
      case Op::kVertex:
        if (s.open) total += np ? SplineRings(p[0], s.rings) : s.rings;
        break;
      default:
        break;
    }
  }
  return total;
}

// Every number the tessellator and the exporters will see must be finite
// and small enough that float arithmetic on it stays finite (squared
// lengths included): each component of every point, every radius and
// scale. NaN is caught in any component (no max(|x|), which drops NaN).
static Status CheckRange(const PlantGeometry& g, const lsys::Word& word,
                         const lsys::SymbolTable& symbols, const lsys::Grammar* grammar) {
  auto ok = [](double v) { return v >= -kMaxCoordinate && v <= kMaxCoordinate; };  // false for NaN
  auto okPoint = [&](const Vec3& p) { return ok(p.x()) && ok(p.y()) && ok(p.z()); };
  auto fail = [&](uint32_t module, const char* what) -> Status {
    char limit[32];
    std::snprintf(limit, sizeof limit, "%g", kMaxCoordinate);
    std::string where = module < word.size() ? "module " + std::to_string(module + 1) + " (" +
                                                   ModuleText(word, symbols, module) + ")"
                                             : "a module";
    std::string message =
        where + " gives " + what + " that is not a finite number within +-" + limit + " units";
    // Located where the grammar first writes the module's name.
    if (grammar && module < word.size()) {
      const std::string& name = symbols.name(word.symbols[module]);
      auto it = grammar->symbolLoc.find(name);
      if (it != grammar->symbolLoc.end()) {
        message += " ('" + name + "' is first written here)";
        return MakeError(it->second.loc, std::move(message), int(name.size()),
                         grammar->SourceLine(it->second.loc));
      }
    }
    return MakeError({}, std::move(message));
  };
  for (const Segment& sg : g.segments) {
    if (!okPoint(sg.start) || !okPoint(sg.end)) return fail(sg.module, "a segment end");
    if (!ok(sg.radiusStart) || !ok(sg.radiusEnd)) return fail(sg.module, "a segment width");
  }
  for (const Polygon& poly : g.polygons) {
    for (const Vec3& v : poly.vertices) {
      if (!okPoint(v)) return fail(poly.module, "a polygon vertex");
    }
  }
  for (const Sphere& sp : g.spheres) {
    if (!okPoint(sp.center) || !ok(sp.radius)) return fail(sp.module, "a sphere");
  }
  for (const SurfaceInstance& si : g.surfaces) {
    if (!okPoint(si.position) || !okPoint(si.scale)) return fail(si.module, "a surface placement");
  }
  for (const mesh::ContourTube& t : g.tubes) {
    for (const Vec3& v : t.points) {
      if (!okPoint(v)) return fail(t.module, "a contour point of a generalized cylinder");
    }
  }
  return {};
}

// Empties `g` and sizes its arrays for what `word` draws (counted first,
// so they are allocated once); an error when that is more than
// options.maxPrimitives.
static Status ClearAndReserve(const lsys::Word& word, const std::vector<Op>& ops,
                              const DrawOptions& options, PlantGeometry& g) {
  g.segments.clear();
  g.polygons.clear();
  g.surfaces.clear();
  g.spheres.clear();
  g.tubes.clear();
  g.loops.clear();
  g.warnings.clear();
  g.moduleWarnings.clear();
  g.modulePosition.clear();
  g.labels.clear();
  g.moduleFrame.clear();
  // How often each symbol occurs (one increment a module), then what each draws.
  std::vector<size_t> count(ops.size(), 0);
  for (size_t i = 0; i < word.size(); ++i) ++count[word.symbols[i]];
  size_t draws = 0, spheres = 0, surfaces = 0;
  bool cylinders = false, splines = false;
  for (size_t sym = 0; sym < ops.size(); ++sym) {
    switch (ops[sym]) {
      case Op::kForwardDraw:
      case Op::kForwardDrawNoVertex:
        draws += count[sym];
        break;
      case Op::kSphere:
        spheres += count[sym];
        break;
      case Op::kSurface:
        surfaces += count[sym];
        break;
      case Op::kDisc:
      case Op::kCircle:
        draws += count[sym] * kDiscSides;
        break;
      case Op::kGcPoint:
      case Op::kGcEnd:
        cylinders |= count[sym] > 0;
        break;
      case Op::kSplineBegin:
        splines |= count[sym] > 0;
        break;
      default:
        break;
    }
  }
  double cylinderRings = 0;  // a double: a @Gc(1e300) must not overflow the count
  if (cylinders) {
    const bool hasParams = word.HasParams();
    for (size_t i = 0; i < word.size(); ++i) {
      const Op op = ops[word.symbols[i]];
      if (op != Op::kGcPoint && op != Op::kGcEnd) continue;
      const uint32_t np = hasParams ? word.paramStart[i + 1] - word.paramStart[i] : 0;
      cylinderRings +=
          CylinderRings(hasParams ? word.params.data() + word.paramStart[i] : nullptr, np);
    }
  }
  if (splines) cylinderRings += SplineSegmentBound(word, ops);
  if (cylinderRings > double(options.maxPrimitives))
    cylinderRings = double(options.maxPrimitives) + 1;
  draws += size_t(cylinderRings);
  if (draws + spheres + surfaces > options.maxPrimitives) {
    Diagnostic d;
    d.kind = ErrorKind::kRuntime;
    d.message = "the word draws " + std::to_string(draws + spheres + surfaces) +
                " primitives (segments, polygon vertices, spheres, surfaces), more than the "
                "limit of " +
                std::to_string(options.maxPrimitives) +
                "; lower the derivation length (-n) or raise --max-triangles";
    return d;
  }
  if (g.segments.capacity() < draws) {
    g.segments = std::vector<Segment>();
    g.segments.reserve(draws);
    AdviseHugePages(g.segments.data(), draws * sizeof(Segment));
  }
  g.spheres.reserve(spheres);
  g.surfaces.reserve(surfaces);
  return {};
}

// `}`: closes the innermost open polygon into g.polygons, dropping a closing
// vertex that repeats the first; warns about an unmatched `}` or a polygon
// of fewer than 3 vertices (module i).
static void ClosePolygon(std::vector<Polygon>& open, size_t i, PlantGeometry& g) {
  if (open.empty()) {
    g.warnings.push_back("unmatched '}' at module " + std::to_string(i + 1) + " ignored");
    return;
  }
  Polygon poly = std::move(open.back());
  open.pop_back();
  if (poly.vertices.size() > 1 && (poly.vertices.front() - poly.vertices.back()).norm() < 1e-9)
    poly.vertices.pop_back();
  if (poly.vertices.size() < 3) {
    g.warnings.push_back("polygon at module " + std::to_string(poly.module + 1) + " has " +
                         std::to_string(poly.vertices.size()) + " vertices; skipped");
    return;
  }
  g.polygons.push_back(std::move(poly));
}

std::string FormatCpfgLabel(const std::string& format, const double* values, size_t count) {
  constexpr size_t kMaxLength = 1000;
  std::string out;
  size_t next = 0;  // the value the next conversion takes
  for (size_t i = 0; i < format.size() && out.size() < kMaxLength;) {
    if (format[i] != '%') {
      out += format[i++];
      continue;
    }
    if (i + 1 < format.size() && format[i + 1] == '%') {
      out += '%';
      i += 2;
      continue;
    }
    // %[flags][width][.precision][length]conversion
    size_t j = i + 1;
    std::string flags;
    while (j < format.size() && std::strchr("-+ #0", format[j])) flags += format[j++];
    auto number = [&](int* n) {
      *n = -1;
      while (j < format.size() && std::isdigit(static_cast<unsigned char>(format[j]))) {
        *n = std::min(99, std::max(*n, 0) * 10 + (format[j] - '0'));
        ++j;
      }
    };
    int width = -1, precision = -1;
    number(&width);
    bool dot = false;
    if (j < format.size() && format[j] == '.') {
      dot = true;
      ++j;
      number(&precision);
      if (precision < 0) precision = 0;
    }
    while (j < format.size() && std::strchr("hlLqjzt", format[j])) ++j;
    const char c = j < format.size() ? format[j] : '\0';
    const bool real = c && std::strchr("fFeEgGaA", c);
    const bool whole = c && std::strchr("diuxXoc", c);
    if ((!real && !whole) || next >= count) {
      out += format.substr(i, (c ? j + 1 : j) - i);  // kept as text
      i = c ? j + 1 : j;
      continue;
    }
    std::string spec = "%" + flags;
    if (width >= 0) spec += std::to_string(width);
    if (dot) spec += "." + std::to_string(precision);
    const double v = values[next++];
    char buf[256];
    if (real) {
      spec += c;
      std::snprintf(buf, sizeof buf, spec.c_str(), v);
    } else {
      const long long w = std::isfinite(v) ? static_cast<long long>(std::clamp(v, -9e18, 9e18)) : 0;
      if (c == 'c') {
        spec += 'c';
        std::snprintf(buf, sizeof buf, spec.c_str(), int(static_cast<unsigned char>(w)));
      } else {
        spec += "ll";
        spec += c;
        std::snprintf(buf, sizeof buf, spec.c_str(), w);
      }
    }
    out += buf;
    i = j + 1;
  }
  if (out.size() > kMaxLength) out.resize(kMaxLength);
  return out;
}

Status InterpretInto(const lsys::Word& word, const lsys::SymbolTable& symbols, const TurtleDef& def,
                     const DrawOptions& options, PlantGeometry& g) {
  std::vector<Op> ops(symbols.size());
  for (size_t s = 0; s < symbols.size(); ++s) ops[s] = OpFor(symbols.name(lsys::SymbolId(s)));
  if (!def.quoteIsColor) {  // cpfg's turtle has no `'` (interpret.c, InterpretSymbol)
    for (size_t s = 0; s < symbols.size(); ++s)
      if (symbols.name(lsys::SymbolId(s)) == "'") ops[s] = Op::kNone;
  }
  if (def.subLsystems) {  // cpfg's `?(id, scale)` and `$` (not the roll of ABOP's `$`)
    for (size_t s = 0; s < symbols.size(); ++s) {
      const std::string& name = symbols.name(lsys::SymbolId(s));
      if (name == "?" && symbols.arity(lsys::SymbolId(s)) >= 1) ops[s] = Op::kSubStart;
      if (name == "$") ops[s] = Op::kSubEnd;
    }
  }
  // cpfg's `{(n)` and `}(n)`: a polygon when n is 0, else a spline.
  for (size_t s = 0; s < symbols.size(); ++s) {
    if (symbols.arity(lsys::SymbolId(s)) < 1) continue;
    if (ops[s] == Op::kPolygonBegin) ops[s] = Op::kSplineBegin;
    if (ops[s] == Op::kPolygonEnd) ops[s] = Op::kSplineEnd;
  }

  if (Status st = ClearAndReserve(word, ops, options, g); !st.ok()) return st;
  std::vector<uint32_t> branchParent{0};
  std::vector<State> stack;
  std::vector<Polygon> openPolygons;
  std::vector<Cylinder> cylinders;
  State t;
  t.width = def.width;
  CpfgState x;
  x.elasticity = def.susceptibility;
  const size_t movementCount = std::min(def.movements.size(), size_t(lsys::kMaxMovements));
  for (size_t k = 0; k < movementCount; ++k) x.movement[k] = def.movements[k].elasticity;
  // @Ts @Ti @Td naming a movement beyond them: warned once per name and index.
  std::set<std::pair<lsys::SymbolId, int64_t>> warnedMovements;
  // cpfg's contours (@#, @!): drawn only when the view file gives them.
  const CylinderContours* contours = options.contours.get();
  if (contours) x.sides = std::clamp(contours->sides, 3, mesh::kMaxContourSides);
  // The rings of each (contour, sides) used, sampled once.
  std::map<std::pair<int32_t, int32_t>, std::vector<Vec3>> contourRings;
  auto ringOf = [&](int32_t id, int32_t sides) -> const std::vector<Vec3>& {
    auto [it, fresh] = contourRings.try_emplace({id, sides});
    if (fresh) {
      it->second = id == kCircle ? mesh::CircleContour(sides)
                                 : mesh::SampleContour(contours->byId.at(id), sides);
    }
    return it->second;
  };
  std::set<int32_t> warnedContours;
  bool warnedSides = false;
  uint64_t tubePoints = 0;
  std::vector<CpfgState> xstack;
  std::vector<double> subScales;  // the scale outside each open sub-L-system
  std::vector<Spline> splines;    // `{(n)` splines, and their copies in branches
  // What went wrong with splines, counted and reported once each: the first
  // module and how many.
  struct Problem {
    uint32_t count = 0, module = 0;
    void Add(size_t i) {
      if (count++ == 0) module = uint32_t(i);
    }
  };
  Problem badSplineType, strayEnd, fewPoints, neverEnded, strayClose, badLabel, noText;
  t.color = uint16_t(std::clamp(def.initialColor, 0, 65535));
  const int colorStep = def.colorIncrement;
  SinCos sincos;
  double defSin, defCos;
  sincos.Get(def.angle, &defSin, &defCos);
  bool changesTropism = false, drawsCylinders = false, underscore = false;
  for (Op op : ops) {
    underscore |= op == Op::kElasticity;
    changesTropism |= op == Op::kTropismSet || op == Op::kTropismUp || op == Op::kTropismDown ||
                      op == Op::kElasticity;
    drawsCylinders |= op == Op::kGcStart || op == Op::kGcPoint || op == Op::kGcEnd ||
                      op == Op::kGcTangent || op == Op::kGcRadius || op == Op::kSplineBegin ||
                      op == Op::kSplineEnd || op == Op::kSetHeading || op == Op::kTwistForce ||
                      op == Op::kContour || op == Op::kContourSides;
  }
  const bool movements = movementCount > 0;
  const bool cpfgState = changesTropism || drawsCylinders || def.subLsystems || movements;
  // The older tropism: @Ts @Ti @Td change it only when there are no movements.
  const bool tropism = def.susceptibility != 0 || underscore || (changesTropism && !movements);
  // cpfg's `_` bends toward the view file's `tropism direction:`, which is
  // up (0, 1, 0) when the file gives none (interpret.c InitializeParameters).
  const Vec3 tropismDir = underscore && !def.tropismGiven ? Vec3(0, 1, 0) : def.tropism;
  Vec3 lo = t.pos, hi = t.pos;
  bool planar = true;
  const size_t n = word.size();
  const bool hasParams = word.HasParams();
  if (options.recordModules) {
    g.modulePosition.resize(n);
    g.moduleFrame.resize(n);
  }
  auto visit = [&](const Vec3& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
    planar &= p.z() == 0;
  };
  uint32_t turnsSinceOrtho = 0;

  // The open spline, owned by the current bracket depth: a branch that adds
  // to its parent's spline works on its own copy (cpfg's PushSpline), so
  // that `]` resumes the parent's where it was.
  auto ownSpline = [&]() -> Spline& {
    if (splines[size_t(x.spline)].depth != stack.size()) {
      Spline copy = splines[size_t(x.spline)];
      copy.depth = uint32_t(stack.size());
      copy.branch = kNoBranch;
      copy.opened = false;
      x.spline = int32_t(splines.size());
      splines.push_back(copy);
    }
    return splines[size_t(x.spline)];
  };
  // A control point of the open spline at the turtle, and the piece that
  // ends there (`rings` segments; none before the spline has enough points,
  // or between coincident ones).
  auto splinePoint = [&](const ControlPoint& here, double rings, size_t i) {
    Spline& sp = ownSpline();
    if (sp.branch == kNoBranch) {
      branchParent.push_back(t.branch);
      sp.branch = uint32_t(branchParent.size() - 1);
    }
    const int ringCount = int(std::min(rings, 1e9));
    const uint32_t need = sp.bspline ? 3 : 1;  // points before the first piece
    if (sp.count >= need) {
      if (!sp.bspline) {
        if (here.pos != sp.last[2].pos)
          AddCylinderPiece(sp.last[2], here, ringCount, def.widthScale, sp.branch, t.branch,
                           t.depth, uint32_t(i), g);
      } else if ((sp.last[0].pos + 4 * sp.last[1].pos + sp.last[2].pos) !=
                 (sp.last[1].pos + 4 * sp.last[2].pos + here.pos)) {
        AddBSplinePiece(sp.last[0], sp.last[1], sp.last[2], here, ringCount, def.widthScale,
                        sp.branch, t.branch, t.depth, uint32_t(i), g);
      }
    }
    if (sp.count < need) sp.first[sp.count] = here;
    sp.last[0] = sp.last[1];
    sp.last[1] = sp.last[2];
    sp.last[2] = here;
    ++sp.count;
  };

  // The loop, compiled twice: words with cpfg's @T and @G commands keep a
  // second stack of state (CpfgState); every other word runs without it.
  auto run = [&](auto cpfgTag) -> Status {
    constexpr bool kCpfg = decltype(cpfgTag)::value;
    for (size_t i = 0; i < n; ++i) {
      const lsys::SymbolId sym = word.symbols[i];
      const Op op = ops[sym];
      if (op == Op::kNone) {
        if (options.recordModules) {
          g.modulePosition[i] = t.pos;
          g.moduleFrame[i] = t.frame;
        }
        continue;
      }
      const double* p = nullptr;
      uint32_t np = 0;
      if (hasParams) {
        p = word.params.data() + word.paramStart[i];
        np = word.paramStart[i + 1] - word.paramStart[i];
      }
      double s = defSin, c = defCos;
      auto angle = [&] {
        if (np) sincos.Get(p[0], &s, &c);
        ++turnsSinceOrtho;
      };
      switch (op) {
        case Op::kForwardDraw:
        case Op::kForwardMove:
        case Op::kForwardDrawNoVertex:
        case Op::kForwardMoveNoVertex: {
          double len = np ? p[0] : def.step;
          if constexpr (kCpfg) {
            len *= x.scale;
            // cpfg turns the frame by its tropisms and torques before the move.
            if (movements && ApplyMovements(def.movements.data(), movementCount, x.movement.data(),
                                            x.prevHeading, x.prevUp, t.frame))
              ++turnsSinceOrtho;
          }
          const Vec3 start = t.pos;
          t.pos += t.frame.heading * len;
          visit(t.pos);
          const bool inPolygon = !openPolygons.empty();
          if (inPolygon) {
            if (op == Op::kForwardDraw || op == Op::kForwardMove)
              openPolygons.back().vertices.push_back(t.pos);
          } else if (op == Op::kForwardDraw || op == Op::kForwardDrawNoVertex) {
            // Inside a generalized cylinder too: cpfg's F draws its segment
            // whatever @Gs says (interpret.c calls StartNode and EndNode for
            // every F and G; start_spline's spline_flag 2 only keeps F and f
            // from adding control points), beside the tube.
            Segment sg;
            sg.start = start;
            sg.end = t.pos;
            sg.left = t.frame.left;
            sg.radiusStart = sg.radiusEnd = float(t.width * def.widthScale * 0.5);
            sg.branch = t.branch;
            sg.parent = branchParent[t.branch];
            sg.depth = t.depth;
            sg.color = t.color;
            sg.module = uint32_t(i);
            g.segments.push_back(sg);
          }
          if (tropism && (def.cpfgBend ? CpfgBend(tropismDir, x.elasticity, t.frame)
                                       : ApplyTropism(tropismDir, x.elasticity, t.frame)))
            ++turnsSinceOrtho;
          if constexpr (kCpfg) {
            // cpfg: F and f add a control point to an open `{(n)` spline
            // (G and g do not); F and G set the frame @R turns from.
            if (x.spline >= 0 && (op == Op::kForwardDraw || op == Op::kForwardMove)) {
              splinePoint({t.pos, t.frame.heading, t.frame.left, t.width, t.color, x.shape},
                          splines[size_t(x.spline)].rings, i);
            }
            if (op == Op::kForwardDraw || op == Op::kForwardDrawNoVertex) {
              x.prevHeading = t.frame.heading;
              x.prevUp = t.frame.up;
            }
          }
          break;
        }
        case Op::kTurnLeft:
          angle();
          Rotate(t.frame.heading, t.frame.left, c, s);
          break;
        case Op::kTurnRight:
          angle();
          Rotate(t.frame.heading, t.frame.left, c, -s);
          break;
        case Op::kPitchDown:
          angle();
          Rotate(t.frame.heading, t.frame.up, c, s);
          break;
        case Op::kPitchUp:
          angle();
          Rotate(t.frame.heading, t.frame.up, c, -s);
          break;
        case Op::kRollRight:
          angle();
          Rotate(t.frame.left, t.frame.up, c, s);
          break;
        case Op::kRollLeft:
          angle();
          Rotate(t.frame.left, t.frame.up, c, -s);
          break;
        case Op::kTurnAround:
          t.frame.heading = -t.frame.heading;
          t.frame.left = -t.frame.left;
          break;
        case Op::kLevel: {
          const Vec3 v = Vec3::UnitY().cross(t.frame.heading);
          const double norm = v.norm();
          if (norm > 1e-9) {
            t.frame.left = v / norm;
            t.frame.up = t.frame.left.cross(t.frame.heading);
          }
          break;
        }
        case Op::kPush:
          stack.push_back(t);
          branchParent.push_back(t.branch);
          t.branch = uint32_t(branchParent.size() - 1);
          t.depth = uint16_t(std::min<int>(t.depth + 1, 65535));
          if constexpr (kCpfg) {
            xstack.push_back(x);
            // A branch draws its own segments; its first @Gc/@Ge continues
            // the cylinder from the last control point before the `[`
            // (nested branches inherit that); `]` resumes the cylinder.
            if (x.cylinder >= 0) x.branchFrom = x.cylinder;
            x.cylinder = -1;
          }
          break;
        case Op::kPop:
          if (stack.empty()) {  // cpfg's interpret.c: "unmatched ] ignored"
            strayClose.Add(i);
            break;
          }
          t = stack.back();
          stack.pop_back();
          if constexpr (kCpfg) {
            if (x.spline >= 0 && splines[size_t(x.spline)].opened &&
                splines[size_t(x.spline)].depth == stack.size() + 1)
              neverEnded.Add(splines[size_t(x.spline)].module);
            x = xstack.back();
            xstack.pop_back();
          }
          break;
        case Op::kWidth:
          if (np) {
            t.width = p[0];
            if constexpr (kCpfg) t.width *= x.scale;
          } else if (def.widthIncrement > 0) {
            double inc = def.widthIncrement;
            if constexpr (kCpfg) inc *= x.scale;
            t.width = std::max(t.width - inc, 0.0);
          } else {
            t.width *= def.widthFactor;
          }
          break;
        case Op::kWidthUp:
          if (np) {
            t.width = p[0];
            if constexpr (kCpfg) t.width *= x.scale;
          } else if (def.widthIncrement > 0) {
            double inc = def.widthIncrement;
            if constexpr (kCpfg) inc *= x.scale;
            t.width += inc;
          } else if (def.widthFactor != 0) {
            t.width /= def.widthFactor;
          }
          break;
        case Op::kColor:
          t.color = uint16_t(np ? std::clamp(p[0], 0.0, 65535.0)
                                : std::clamp(t.color + colorStep, 0, 65535));
          break;
        case Op::kColorDown:
          t.color = uint16_t(np ? std::clamp(p[0], 0.0, 65535.0)
                                : std::clamp(t.color - colorStep, 0, 65535));
          break;
        case Op::kSplineBegin:
          if constexpr (kCpfg) {
            if (p[0] != 0) {
              // {(type, rings): cpfg general.c InitializeSpline. A spline
              // already open is dropped (what it drew stays).
              const double type = std::trunc(p[0]);
              if (!(type >= 1 && type <= 4)) {
                badSplineType.Add(i);
                break;
              }
              Spline sp;
              sp.closed = int(type - 1) % 2 == 1;
              sp.bspline = int(type - 1) / 2 == 1;
              sp.rings = int(std::min(SplineRings(np >= 2 ? p[1] : 0, kSplineRings), 1e9));
              sp.module = uint32_t(i);
              sp.depth = uint32_t(stack.size());
              x.spline = int32_t(splines.size());
              splines.push_back(sp);
              break;
            }
          }
          [[fallthrough]];
        case Op::kPolygonBegin: {
          Polygon poly;
          poly.color = t.color;
          poly.module = uint32_t(i);
          openPolygons.push_back(std::move(poly));
          break;
        }
        case Op::kVertex:
          if (!openPolygons.empty()) {
            openPolygons.back().vertices.push_back(t.pos);
          } else if constexpr (kCpfg) {
            // `.(n)` in a spline: a control point whose piece has n rings.
            if (x.spline >= 0) {
              const double rings = splines[size_t(x.spline)].rings;
              splinePoint({t.pos, t.frame.heading, t.frame.left, t.width, t.color, x.shape},
                          np ? SplineRings(p[0], rings) : rings, i);
            }
          }
          break;
        case Op::kSplineEnd:
          if constexpr (kCpfg) {
            if (p[0] != 0) {
              // }(type): cpfg general.c FinishSpline. A closed spline ends
              // with its first point (Hermite) or first 3 (B-spline) again.
              if (x.spline < 0) {
                strayEnd.Add(i);
                break;
              }
              Spline& sp = ownSpline();
              const uint32_t least = sp.bspline ? (sp.closed ? 3 : 4) : 2;
              if (sp.count < least) {
                fewPoints.Add(sp.module);
              } else if (sp.closed) {
                const ControlPoint first[3] = {sp.first[0], sp.first[1], sp.first[2]};
                for (uint32_t k = 0; k < (sp.bspline ? 3u : 1u); ++k)
                  splinePoint(first[k], sp.rings, i);
                // Its tube ends where it began: joined, not capped.
                if (sp.branch != kNoBranch) g.loops.push_back(sp.branch);
              }
              x.spline = -1;
              break;
            }
          }
          [[fallthrough]];
        case Op::kPolygonEnd:
          ClosePolygon(openPolygons, i, g);
          break;
        case Op::kSurface: {
          SurfaceInstance si;
          si.name = symbols.name(sym).substr(1);
          si.position = t.pos;
          si.frame = t.frame;
          // ~name(s): uniform; ~name(sx, sy, sz): along L, H, U (cpfg).
          if (np >= 3) {
            si.scale = Vec3(p[0], p[1], p[2]);
          } else if (np) {
            si.scale = Vec3(p[0], p[0], p[0]);
          }
          if constexpr (kCpfg) si.scale *= x.scale;
          si.color = t.color;
          si.module = uint32_t(i);
          g.surfaces.push_back(std::move(si));
          break;
        }
        case Op::kSphere: {
          Sphere sp;
          sp.center = t.pos;
          sp.radius = (np ? p[0] : t.width * def.widthScale) * 0.5;
          sp.color = t.color;
          sp.module = uint32_t(i);
          g.spheres.push_back(sp);
          break;
        }
        case Op::kMoveTo:
          // @M(x,y,z): cpfg's move-to, drawing nothing. Other arities are
          // warned about by the parser and do nothing.
          if (np >= 3) {
            t.pos = Vec3(p[0], p[1], p[2]);
            visit(t.pos);
          }
          break;
        case Op::kDisc:
        case Op::kCircle: {
          // As cpfg draws them (irisGL.c): @c(d) (iGlCircle3D) in the
          // turtle's frame, local x = L, y = H, z = U, a circle in the
          // local xy plane: the plane of H and L, facing U; @o(d)
          // (iGlCircle2D: circf at the turtle's x, y) in the world's xy
          // plane, facing +z, the screen of a 2D figure. d defaults to
          // the width.
          const double d = (np ? p[0] : t.width) * def.widthScale;
          if (op == Op::kDisc) {
            AddDisc(t.pos, Vec3(1, 0, 0), Vec3(0, 1, 0), d, t.color, uint32_t(i), g);
          } else {
            AddDisc(t.pos, t.frame.left, t.frame.heading, d, t.color, uint32_t(i), g);
          }
          break;
        }
        case Op::kGcStart:
        case Op::kGcPoint:
        case Op::kGcEnd: {
          ControlPoint here{t.pos, t.frame.heading, t.frame.left, t.width, t.color, x.shape};
          here.up = t.frame.up;
          here.contour = x.contour;
          here.sides = x.sides;
          if (x.cylinder < 0 && x.branchFrom >= 0 && op != Op::kGcStart) {
            // The branch's first piece starts where its parent cylinder was.
            const ControlPoint from = cylinders[size_t(x.branchFrom)].last;
            branchParent.push_back(t.branch);
            x.cylinder = int32_t(cylinders.size());
            cylinders.push_back({from, uint32_t(branchParent.size() - 1)});
          }
          x.branchFrom = -1;
          if (x.cylinder < 0) {
            if (op == Op::kGcEnd) break;  // nothing open: nothing to end
            branchParent.push_back(t.branch);
            x.cylinder = int32_t(cylinders.size());
            cylinders.push_back({here, uint32_t(branchParent.size() - 1)});
            if (op == Op::kGcStart) break;
          }
          Cylinder& cyl = cylinders[size_t(x.cylinder)];
          if (op == Op::kGcStart) {  // @Gs inside an open cylinder restarts it here
            cyl.last = here;
            break;
          }
          const int rings = int(CylinderRings(p, np));
          if (contours && !contours->twist) {
            // cpfg without `twist of cylinders: on`: the cross-section's up
            // is carried from the previous control point, not the turtle's.
            here.up = Carry(cyl.last.up, cyl.last.heading, here.heading);
          }
          if (contours && (cyl.last.contour != kCircle || here.contour != kCircle)) {
            const auto& ringA = ringOf(cyl.last.contour, cyl.last.sides);
            const auto& ringB = ringOf(here.contour, cyl.last.sides);
            const bool closed =
                (cyl.last.contour == kCircle || contours->byId.at(cyl.last.contour).closed) &&
                (here.contour == kCircle || contours->byId.at(here.contour).closed);
            tubePoints += uint64_t(rings + 1) * ringA.size();
            if (tubePoints > options.maxPrimitives) {
              Diagnostic d;
              d.kind = ErrorKind::kRuntime;
              d.message = "the generalized cylinders with contours draw more than " +
                          std::to_string(options.maxPrimitives) +
                          " ring points (the limit of primitives); lower the derivation "
                          "length (-n) or the contour sides, or raise --max-triangles";
              g = PlantGeometry();
              return d;
            }
            AddContourPiece(cyl.last, here, ringA, ringB, closed, rings, def.widthScale,
                            contours->twist, uint32_t(i), cyl.tube, g);
          } else {
            AddCylinderPiece(cyl.last, here, rings, def.widthScale, cyl.branch, t.branch, t.depth,
                             uint32_t(i), g);
            cyl.tube = -1;
          }
          cyl.last = here;
          if (op == Op::kGcEnd) x.cylinder = -1;
          break;
        }
        case Op::kTropismSet:
        case Op::kTropismUp:
        case Op::kTropismDown: {
          // @Ts(i, e) sets the elasticity of tropism i to e (0 without e);
          // @Ti(i, d) and @Td(i, d) add and subtract d (default: the
          // movement's step S, or the elasticity increment).
          if (movements) {
            // cpfg blackbox.c 'T': nothing without parameters; i truncated
            // toward zero; one out of range changes nothing.
            if (np == 0) break;
            const double at = p[0] - 1;
            const int64_t k = std::isfinite(at) && std::abs(at) < 1e9 ? int64_t(at) : -1;
            if (k < 0 || k >= int64_t(movementCount)) {
              if (warnedMovements.insert({sym, k < 0 ? int64_t(-1) : k}).second) {
                char index[32];
                std::snprintf(index, sizeof index, "%g", p[0]);
                g.moduleWarnings.push_back(
                    {symbols.name(sym), "'" + ModuleText(word, symbols, i) + "' (module " +
                                            std::to_string(i + 1) + ") names tropism " + index +
                                            ", but the view file defines " +
                                            std::to_string(movementCount) +
                                            " ('tropism:' and 'torque:' lines): it changes "
                                            "nothing, as in cpfg"});
              }
              break;
            }
            double& e = x.movement[size_t(k)];
            const double step = np >= 2 ? p[1] : def.movements[size_t(k)].elasticityStep;
            if (op == Op::kTropismSet) e = np >= 2 ? p[1] : 0;
            if (op == Op::kTropismUp) e += step;
            if (op == Op::kTropismDown) e -= step;
            break;
          }
          if (np >= 1 && p[0] != 1) {
            g.warnings.push_back("module " + std::to_string(i + 1) + " (" +
                                 ModuleText(word, symbols, i) +
                                 ") names a tropism other than 1; Sylva has one tropism: ignored");
            break;
          }
          const double v = np >= 2 ? p[1] : (op == Op::kTropismSet ? 0 : def.elasticityIncrement);
          if (op == Op::kTropismSet) x.elasticity = v;
          if (op == Op::kTropismUp) x.elasticity += v;
          if (op == Op::kTropismDown) x.elasticity -= v;
          break;
        }
        case Op::kElasticity:
          // _(e) sets the elasticity to e, _ adds the elasticity increment
          // (cpfg interpret.c, '_'; the view file's `elasticity increment:`).
          x.elasticity = np ? p[0] : x.elasticity + def.elasticityIncrement;
          break;
        case Op::kTwistForce:
          // @Tf: cpfg records the frame so its next cylinder does not twist;
          // Sylva's tubes follow rotation-minimizing frames and never twist.
          // The frame recorded is also the one @R turns from.
          if constexpr (kCpfg) {
            x.prevHeading = t.frame.heading;
            x.prevUp = t.frame.up;
          }
          break;
        case Op::kLabel: {
          // @L(text, values...) (blackbox.c 'L', irisGL.c iGlLabel): the
          // file's text number p[0] formatted with the other numbers, at
          // the turtle's position in its colour; no text number, or one
          // beyond the texts, takes the last text, as cpfg does.
          const std::vector<std::string>* texts = def.grammar ? &def.grammar->strings : nullptr;
          if (!texts || texts->empty()) {
            noText.Add(i);
            break;
          }
          size_t k = texts->size() - 1;
          if (np >= 1 && p[0] >= 0 && p[0] < double(texts->size()))
            k = size_t(p[0]);
          else
            badLabel.Add(i);
          g.labels.push_back(
              {t.pos,
               FormatCpfgLabel((*texts)[k], np > 1 ? p + 1 : nullptr, np > 1 ? size_t(np - 1) : 0),
               t.color, uint32_t(i)});
          break;
        }
        case Op::kSetHeading:
          if constexpr (kCpfg) {
            if (np >= 2) SetHeading(p, np, x.prevHeading, x.prevUp, t.frame);
          }
          break;
        case Op::kGcTangent:  // @Gt(a[, b]): blackbox.c, 't'
          if (np >= 1) {
            x.shape.arriving = p[0];
            x.shape.leaving = np >= 2 ? p[1] : p[0];
          }
          break;
        case Op::kGcRadius: {  // @Gr(k) or @Gr(a, l[, a2, l2]): blackbox.c, 'r'
          if (np == 1) {
            x.shape.scaleRadiusTangents = p[0] != 0;
            break;
          }
          if (np < 2) break;
          double sa, ca;
          SinCosRadians(p[0] * kDegToRad, &sa, &ca);
          x.shape.radiusArriving = x.shape.radiusLeaving = Vec2(ca, sa) * p[1];
          if (np >= 4) {
            SinCosRadians(p[2] * kDegToRad, &sa, &ca);
            x.shape.radiusLeaving = Vec2(ca, sa) * p[3];
          }
          break;
        }
        case Op::kContour: {  // @#(n): blackbox.c, '#'
          if (!np) {
            x.contour = kCircle;
            break;
          }
          const double id = p[0];
          const bool known = contours && id == std::floor(id) && std::abs(id) < 2e9 &&
                             contours->byId.count(int(id));
          x.contour = known ? int32_t(id) : kCircle;
          const int32_t key = std::isfinite(id) ? int32_t(std::clamp(id, -2e9, 2e9)) : kCircle;
          if (!known && warnedContours.insert(key).second) {
            char text[32];
            std::snprintf(text, sizeof text, "%g", id);
            g.warnings.push_back(
                "module " + std::to_string(i + 1) + " (" + ModuleText(word, symbols, i) +
                ") selects contour " + std::string(text) + ", which " +
                (contours ? "the view file does not give (no 'contour: " + std::string(text) +
                                " FILE.con' line, or its file is missing or bad)"
                          : std::string("is not in use (no view file gives contours with "
                                        "'line style: cylinder')")) +
                ": its generalized cylinders are drawn round, as cpfg does");
          }
          break;
        }
        case Op::kContourSides: {  // @!(s): blackbox.c, '!': at least 3, 8 without s
          double sides = np ? p[0] : 8;
          if (!(sides >= 3)) sides = 3;
          if (sides > mesh::kMaxContourSides) {
            sides = mesh::kMaxContourSides;
            if (!warnedSides) {
              warnedSides = true;
              g.warnings.push_back(
                  "module " + std::to_string(i + 1) + " (" + ModuleText(word, symbols, i) +
                  ") asks for more than " + std::to_string(mesh::kMaxContourSides) +
                  " contour sides: drawn with " + std::to_string(mesh::kMaxContourSides));
            }
          }
          x.sides = int32_t(sides);
          break;
        }
        case Op::kSubStart:  // ?(id, scale): cpfg's interpret.c UpdateCurrentLsystem
          if constexpr (kCpfg) {
            const double outer = x.scale;
            subScales.push_back(outer);
            x.scale = outer * (np >= 2 ? p[1] : 1.0);
            if (outer != 0) t.width *= x.scale / outer;
          }
          break;
        case Op::kSubEnd:
          if constexpr (kCpfg) {
            if (subScales.empty()) {
              g.warnings.push_back("unmatched '$' (end of a sub-L-system) at module " +
                                   std::to_string(i + 1) + " ignored");
              break;
            }
            const double inner = x.scale;
            x.scale = subScales.back();
            subScales.pop_back();
            if (inner != 0) t.width *= x.scale / inner;
          }
          break;
        case Op::kNone:
          break;
      }
      if (turnsSinceOrtho >= 64) {
        Orthonormalise(t.frame);
        turnsSinceOrtho = 0;
      }
      if (options.recordModules) {
        g.modulePosition[i] = t.pos;
        g.moduleFrame[i] = t.frame;
      }
    }
    return {};
  };
  if (Status st = cpfgState ? run(std::true_type{}) : run(std::false_type{}); !st.ok()) return st;
  if (x.spline >= 0) neverEnded.Add(splines[size_t(x.spline)].module);
  auto report = [&](const Problem& pr, const std::string& what) {
    if (pr.count == 0) return;
    std::string text = "module " + std::to_string(pr.module + 1) + " (" +
                       ModuleText(word, symbols, pr.module) + ")" + what;
    if (pr.count > 1) text += " (and " + std::to_string(pr.count - 1) + " more like it)";
    g.warnings.push_back(std::move(text));
  };
  report(badSplineType,
         ": a spline's type is 1 to 4 (1 open and 2 closed Hermite curve, 3 open and 4 closed "
         "B-spline); nothing is drawn for it");
  report(strayEnd, ": ends no spline; ignored");
  report(strayClose, ": a ']' with no '[' open; ignored, as cpfg's turtle does");
  report(badLabel,
         ": a label ('@L') whose first parameter is no text of the file; it shows the "
         "file's last text, as cpfg does");
  report(noText, ": a label ('@L') in a file with no text (\"...\") parameters; nothing is drawn");
  if (!g.labels.empty() && !options.drawsLabels) {
    g.warnings.push_back(
        std::to_string(g.labels.size()) + (g.labels.size() == 1 ? " label" : " labels") +
        " ('@L') not drawn: only 'sylva render' of the grammar draws text (scenes, the "
        "viewer and mesh files have none)");
  }
  report(fewPoints,
         " opens a spline with too few control points to draw (a Hermite curve needs 2, an open "
         "B-spline 4, a closed one 3): nothing is drawn for it");
  report(neverEnded,
         " opens a spline that is never ended with '}(n)'; drawn up to its last control point "
         "(a closed one is not closed)");
  if (x.cylinder >= 0) {
    g.warnings.push_back(
        "generalized cylinder (@Gs) is never ended with @Ge; drawn up to its last "
        "control point");
  }
  for (const Polygon& poly : openPolygons) {
    g.warnings.push_back("polygon opened at module " + std::to_string(poly.module + 1) +
                         " is never closed; skipped");
  }
  if (Status s = CheckRange(g, word, symbols, def.grammar); !s.ok()) {
    g = PlantGeometry();
    return s;
  }
  for (const mesh::ContourTube& tube : g.tubes) {
    for (const Vec3& v : tube.points) visit(v);
  }
  g.boundsMin = lo;
  g.boundsMax = hi;
  g.planar = planar;
  g.widthInPixels = options.widthInPixels;
  g.cylinderStyle = options.cylinderStyle;
  g.branchCount = uint32_t(branchParent.size());
  return {};
}

}  // namespace sylva::turtle
