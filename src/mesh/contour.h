// cpfg's generalized-cylinder contours: the cross-sections that `@#(n)`
// gives the cylinders `@Gs ... @Gc ... @Ge` draw, read from the `.con`
// files a view file names (`contour: n leaf.con`).
//
// The reference is vlab's cpfg (src/cpfg, the generalized cylinders of
// Radomir Mech, 1994: process_contour_file, MakeContour, make_contour):
//
// A contour is a uniform cubic B-spline in the plane (x, y), with z an
// offset along the cylinder's axis; its control points are in the file,
// open (the curve runs from near the first point to near the last; a point
// written three times is interpolated) or closed (periodic). Two formats:
//
//   15 3 open                  N points, dimension 2 or 3, open or closed,
//   -1.07 -0.88 0.0            then the N points (free-form)
//   ...
//
//   cver 1 3                   version 1.1, 1.2 or 1.3
//   name: leaf.con             (skipped)
//   points: 11 15              lines of points, points with multiplicity
//   type: or                   o(pen) or c(losed), r(egular) or e(nd
//                              point: cpfg reads it as regular, and warns)
//   samples: 8                 (1.3 only; the editor's, not used)
//   -8.51 -0.40 0.0 3          x y z multiplicity, one a line
//
// A contour is drawn with S sides (the view file's `contour sides:`, cpfg's
// default 8, or `@!(S)`): S + 1 points spaced evenly by arc length in
// (x, y) (SampleContour). A closed contour's points are turned about the
// origin so that the first lies on +x, and its last point is its first. The
// drawing (turtle/interpreter.cpp) places point (x, y, z) of a ring of
// radius r at  centre + r (x U - y L) + (r z / chord) H,  cpfg's frame: the
// contour's x along the turtle's up, y along its right; the coordinates
// are not normalised, so a contour 2 units across draws twice the width.
#pragma once

#include <string>
#include <vector>

#include "core/diagnostic.h"
#include "core/math.h"
#include "core/status.h"

namespace sylva::mesh {

struct Contour {
  std::vector<Vec3> points;  // B-spline control points, multiplicities expanded
  bool closed = false;
};

// A .con file is a few kilobytes; larger is not a contour file.
inline constexpr size_t kMaxContourFileBytes = size_t(1) << 20;
inline constexpr size_t kMaxContourPoints = 100000;
// The most sides a contour is drawn with (cpfg warns above 1024 too).
inline constexpr int kMaxContourSides = 1024;

// Reads a .con file's text. Errors carry `path`, the line and the column:
// a header that is none of the formats above, a missing or non-finite
// number, multiplicities that do not add up to the `points:` total, too few
// points for a cubic B-spline (4 open, 3 closed), a curve of no length in
// (x, y). Warnings (an end-point-interpolated `type: oe`, text after the
// last point) go to `warnings`.
Expected<Contour> ParseContour(const std::string& text, const std::string& path,
                               DiagnosticList* warnings = nullptr);

// `sides` + 1 points of the contour, evenly spaced by arc length in (x, y);
// closed: turned so the first is on +x, and the last equals the first.
// sides in 3..kMaxContourSides.
std::vector<Vec3> SampleContour(const Contour& contour, int sides);

// cpfg's default contour, the unit circle: (cos a, sin a, 0) for a =
// 2 pi i / sides, i = 0..sides (the last equals the first).
std::vector<Vec3> CircleContour(int sides);

}  // namespace sylva::mesh
