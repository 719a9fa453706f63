// cpfg's curve files (`.con`, made with vlab's cuspy; a view file's
// `curve: FILE [samples]` line), read in expressions with
//   curveX(id, t), curveY(id, t), curveZ(id, t)   a coordinate of the point
//                                                 at arc length t (0..1)
//   curveGAL(id)                                  the curve's length
// id 1 is the first `curve:` line. The reference is vlab's cpfg
// (curveXYZ.cpp, curveXYZc.cpp: CurveCXS and CurveGAL; generate.c, Eval).
//
// The curve: each control point repeated as often as its multiplicity (the
// fourth column), then, by `type:`,
//   bspline (default)   the uniform cubic B-spline (integer knots) over
//                       parameter 3 .. n for n points: it does not pass
//                       through the end points unless they are tripled
//   bspline-endpoint    the clamped uniform cubic B-spline (ends interpolated)
//   bspline-closed      the first three points appended: a closed loop
//   bspline-phantom     a phantom point added at each end (2 P1 - P2)
//   bezier              cubic Bezier pieces sharing end points (4, 7, 10 ...)
// Arc length as cpfg measures it: the polyline through `samples` points at
// equal parameter steps (100 by default); curveGAL is its length, and
// curveX(id, t) finds the parameter where the polyline's length from the
// start is t times that, by bisection in the table and linear interpolation
// between its entries. t outside [0, 1] is clamped, as in cpfg.
//
// Format (one item a line; labels at the start of a line):
//   version: 1.4                      (read, not used)
//   contact: x y z / end: / heading: / up: / size: s   (cuspy's placement of
//                                      the curve as a surface; not used by
//                                      curveX, as in cpfg)
//   points: N
//   range: a b                        (not used, as in cpfg)
//   dimension: D                      (numbers per point: 2 x y, 3 x y z,
//                                      4 x y z multiplicity; default 2)
//   type: bspline | bspline-endpoint | bspline-closed | bspline-phantom | bezier
//   N lines of D numbers
// Not read (an error at its line): `type: bezier-surface`, a second
// `points:` (cpfg's curves within a curve), a point line with other than D
// numbers, more or fewer than N points, fewer than 4 points with their
// multiplicities.
#pragma once

#include <string>
#include <vector>

#include "core/math.h"
#include "core/status.h"

namespace sylva::lsys {

class CpfgCurve {
 public:
  static constexpr int kDefaultSamples = 100;  // cpfg's, without a number on the `curve:` line

  // Reads a curve file's text; samples (>= 2) is the arc-length table's size.
  // Errors name `path` and the line.
  static Expected<CpfgCurve> Parse(const std::string& text, const std::string& path,
                                   int samples = kDefaultSamples);

  // The point at arc length t (clamped to 0..1) times Length() from the start.
  Vec3 AtLength(double t) const;
  // The point at parameter t in 0..1 (cpfg's calcPValue).
  Vec3 AtParameter(double t) const;
  double Length() const { return length_; }    // curveGAL
  size_t points() const { return p_.size(); }  // with multiplicities and added points

 private:
  enum class Type { kBspline, kBsplineEndpoint, kBsplineClosed, kBsplinePhantom, kBezier };
  Type type_ = Type::kBspline;
  std::vector<Vec3> p_;      // the control points the curve is made of
  std::vector<double> arc_;  // normalized length at sample i (0 .. 1)
  double length_ = 0;
};

}  // namespace sylva::lsys
