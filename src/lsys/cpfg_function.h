// cpfg's function files (`.func`, made with vlab's funcedit): a curve
// y = f(x) for x in [0, 1], used in expressions as `func(id, x)`.
//
// The curve is the cubic B-spline of the file's control points (x, y) with
// a clamped uniform knot vector, as cpfg evaluates it (cpfg/splinefun.cpp
// in vlab): u runs over [0, n - 2] for n + 1 points. f(x) is y at the
// parameter where the curve's x is the given x (found by bisection to
// 0.001 in x, as cpfg does), or, when the file asks for `samples: S` with
// S > 2, the linear interpolation of S values precomputed at x = i/(S-1).
// x outside [0, 1] is clamped.
//
// Formats read (the first line tells which):
//   range: 0 1            (old format; the range is read as [0, 1])
//   points: N
//   x y                   (N lines)
// and
//   fver 1 1
//   name: NAME
//   samples: S
//   [background: ... and one more line]   [markers: K, then K lines]
//   flip: on|off          (ignored, as in cpfg)
//   points: N
//   x y [multiplicity]    (N lines; a point repeated `multiplicity` times)
// At least 4 points.
//
// A function set (`.fset`, vlab's function gallery; a view file's
// `function set: functions.fset` line) is several functions in one file:
//   funcgalleryver 1 1
//   items: N
//   then N functions in the `fver 1 1` format above, one after the other.
// cpfg numbers them 1..N in file order and defines each one's name (up to
// its last '.') as that number for the preprocessor (generate.c,
// PreprocessLsystem: `-DNAME=i+1`), so `func(BR_ANGLE, x)` is func(4, x).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "core/status.h"

namespace sylva::lsys {

class CpfgFunction {
 public:
  // Reads a function file's text; errors name `path` and the line.
  static Expected<CpfgFunction> Parse(const std::string& text, const std::string& path);

  // Reads a function set's text (the functions in file order, each with
  // its `name:`); errors name `path` and the line in the set.
  static Expected<std::vector<CpfgFunction>> ParseSet(const std::string& text,
                                                      const std::string& path);

  double Value(double x) const;  // f(x), x clamped to [0, 1]
  size_t points() const { return px_.size(); }
  // The `name:` of an `fver` file, without a '.' suffix (cpfg's); empty for
  // the `range:` format.
  const std::string& name() const { return name_; }

 private:
  void Point(double u, double* x, double* y) const;  // the curve at parameter u in [0, n-2]
  double Exact(double x) const;

  std::vector<double> px_, py_;  // control points
  std::vector<double> samples_;  // precomputed values, when the file asks for them
  std::string name_;
};

}  // namespace sylva::lsys
