// cpfg curve files: reading and evaluating (see cpfg_curve.h).
#include "lsys/cpfg_curve.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "lsys/clamped_bspline.h"

namespace sylva::lsys {
namespace {

Diagnostic FileError(const std::string& path, int line, const std::string& msg) {
  Diagnostic d;
  d.loc.file = path;
  d.loc.line = line;
  d.loc.column = 1;
  d.message = msg;
  return d;
}

// The uniform cubic B-spline's four weights at s in [0, 1) of a span.
void UniformWeights(double s, double w[4]) {
  const double s2 = s * s, s3 = s2 * s;
  w[0] = (1 - s) * (1 - s) * (1 - s) / 6;
  w[1] = (3 * s3 - 6 * s2 + 4) / 6;
  w[2] = (-3 * s3 + 3 * s2 + 3 * s + 1) / 6;
  w[3] = s3 / 6;
}

}  // namespace

Vec3 CpfgCurve::AtParameter(double t) const {
  t = t < 0 ? 0 : (t > 1 ? 1 : t);
  const int n = int(p_.size());
  Vec3 r = Vec3::Zero();
  switch (type_) {
    case Type::kBezier: {
      // cpfg: segment c of n_seg, its local t stretched by 1/1.000001.
      const int segments = 1 + (n - 4) / 3;
      int c = int(t / (1.000001 / segments));
      if (c > segments - 1) c = segments - 1;
      const double u = (t - double(c) / segments) * segments / 1.000001;
      const double v = 1 - u;
      const double w[4] = {v * v * v, 3 * u * v * v, 3 * u * u * v, u * u * u};
      for (int j = 0; j < 4; ++j) r += w[j] * p_[size_t(c * 3 + j)];
      return r;
    }
    case Type::kBsplineEndpoint: {
      // Only the four basis functions of u's knot span, k = floor(u) ..
      // floor(u) + 3, are non-zero (the others are exactly 0): summing all
      // n made a curve of 10^6 control points take 10^6 steps a sample.
      const double u = t * (n - 3.000001);
      const int first = std::clamp(int(u), 0, n - 4);
      for (int k = first; k < first + 4; ++k) r += ClampedBasis(k, 4, u, n) * p_[size_t(k)];
      return r;
    }
    default: {
      // Integer knots; parameter 3 .. n - 0.000001, the span [i, i + 1).
      const double u = 3.0 + t * (n - 3.000001);
      const int i = int(u);
      double w[4];
      UniformWeights(u - i, w);
      for (int j = 0; j < 4; ++j) r += w[j] * p_[size_t(i - 3 + j)];
      return r;
    }
  }
}

Vec3 CpfgCurve::AtLength(double t) const {
  t = t < 0 ? 0 : (t > 1 ? 1 : t);
  const size_t last = arc_.size() - 1;
  if (length_ == 0) return AtParameter(t);
  size_t lo = 0, hi = last;
  while (hi - lo > 1) {
    const size_t mid = (lo + hi) / 2;
    (arc_[mid] > t ? hi : lo) = mid;
  }
  const double span = arc_[hi] - arc_[lo];
  const double f = span > 0 ? (t - arc_[lo]) / span : 0;
  return AtParameter((double(lo) + f) / double(last));
}

Expected<CpfgCurve> CpfgCurve::Parse(const std::string& text, const std::string& path,
                                     int samples) {
  if (samples < 2 || samples > 1000000)
    return FileError(path, 1, "a curve's samples must be from 2 to 1000000");
  std::istringstream in(text);
  std::string line;
  int number = 0;
  CpfgCurve c;
  long declared = -1;
  int pointsLine = 0;
  int dimension = 2;
  std::vector<std::pair<Vec3, int>> read;  // point and multiplicity
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const size_t b = line.find_first_not_of(" \t");
    if (b == std::string::npos) continue;
    const std::string item = line.substr(b);
    auto starts = [&](const char* word) { return item.rfind(word, 0) == 0; };
    std::istringstream values(
        item.substr(item.find(':') == std::string::npos ? 0 : item.find(':') + 1));
    if (starts("//")) continue;
    if (starts("version:") || starts("range:")) continue;  // cpfg reads and drops them
    if (starts("contact:") || starts("end:") || starts("heading:") || starts("up:") ||
        starts("size:")) {
      // cuspy's placement of the curve as a surface: checked, not used.
      double x = 0;
      const int want = starts("size:") ? 1 : 3;
      for (int k = 0; k < want; ++k) {
        if (!(values >> x) || !std::isfinite(x))
          return FileError(path, number,
                           "expected " + std::string(want == 1 ? "a number" : "three numbers") +
                               " after '" + item.substr(0, item.find(':') + 1) + "'");
      }
      continue;
    }
    if (starts("points:")) {
      if (declared >= 0)
        return FileError(path, number,
                         "a second 'points:' (cpfg's curves within a curve) is not supported");
      if (!(values >> declared) || declared < 1 || declared > 100000)
        return FileError(path, number, "expected 'points: N' with N from 1 to 100000");
      pointsLine = number;
      continue;
    }
    if (starts("dim:") || starts("dimension:")) {
      if (!(values >> dimension) || dimension < 2 || dimension > 4)
        return FileError(path, number, "expected 'dimension: D' with D 2, 3 or 4");
      continue;
    }
    if (starts("type:")) {
      std::string type;
      values >> type;
      if (type == "bezier-surface")
        return FileError(path, number, "'type: bezier-surface' curves are not supported");
      c.type_ = type == "bezier"             ? Type::kBezier
                : type == "bspline-phantom"  ? Type::kBsplinePhantom
                : type == "bspline-endpoint" ? Type::kBsplineEndpoint
                : type == "bspline-closed"   ? Type::kBsplineClosed
                : type == "bspline"          ? Type::kBspline
                                             : Type::kBspline;
      if (type != "bspline" && c.type_ == Type::kBspline)
        return FileError(path, number,
                         "unknown curve type '" + type +
                             "' (bspline, bspline-endpoint, bspline-closed, bspline-phantom, "
                             "bezier)");
      continue;
    }
    if (item.find(':') != std::string::npos)
      return FileError(path, number, "unknown line in a curve file");
    // A point: exactly `dimension` numbers.
    if (declared < 0) return FileError(path, number, "a point before 'points: N'");
    if (long(read.size()) >= declared)
      return FileError(path, number,
                       "more points than 'points: " + std::to_string(declared) + "' declares");
    std::istringstream p(item);
    std::vector<double> v;
    std::string word;
    while (p >> word) {
      char* end = nullptr;
      const double x = std::strtod(word.c_str(), &end);
      if (*end != '\0' || !std::isfinite(x))
        return FileError(path, number, "'" + word + "' is not a number");
      // The turtle's range: larger coordinates made the length infinite.
      if (std::abs(x) > 1e15) return FileError(path, number, "'" + word + "' is beyond +-1e15");
      v.push_back(x);
    }
    if (int(v.size()) != dimension)
      return FileError(path, number,
                       "a point of " + std::to_string(v.size()) + " numbers where 'dimension: " +
                           std::to_string(dimension) + "' asks for " + std::to_string(dimension));
    int m = 1;
    if (dimension == 4) {
      if (v[3] < 1 || v[3] > 100 || v[3] != std::floor(v[3]))
        return FileError(path, number,
                         "a point's multiplicity must be a whole number from 1 to 100");
      m = int(v[3]);
    }
    read.emplace_back(Vec3(v[0], v[1], dimension > 2 ? v[2] : 0.0), m);
  }
  if (declared < 0) return FileError(path, number, "no 'points: N' line");
  if (long(read.size()) != declared)
    return FileError(path, pointsLine,
                     "'points: " + std::to_string(declared) + "' but the file gives " +
                         std::to_string(read.size()));
  // The control points with their multiplicities, then the type's extra points.
  const bool phantom = c.type_ == Type::kBsplinePhantom;
  if (phantom) c.p_.push_back(Vec3::Zero());
  for (const auto& [q, m] : read) c.p_.insert(c.p_.end(), size_t(m), q);
  if (c.type_ == Type::kBsplineClosed)
    for (size_t i = 0; i < 3 && i < c.p_.size(); ++i) c.p_.push_back(c.p_[i]);
  if (phantom) {
    c.p_.push_back(Vec3::Zero());
    const size_t n = c.p_.size();
    if (n >= 4) {
      c.p_[0] = 2 * c.p_[1] - c.p_[2];
      c.p_[n - 1] = 2 * c.p_[n - 2] - c.p_[n - 3];
    }
  }
  if (c.p_.size() < 4)
    return FileError(path, pointsLine,
                     "a curve needs at least 4 control points counting multiplicities (cpfg "
                     "draws nothing with fewer)");
  // cpfg's arc-length table: the polyline through `samples` points.
  c.arc_.resize(size_t(samples));
  Vec3 prev = c.AtParameter(0);
  for (int i = 1; i < samples; ++i) {
    const Vec3 q = c.AtParameter(double(i) / (samples - 1));
    c.length_ += (q - prev).norm();
    c.arc_[size_t(i)] = c.length_;
    prev = q;
  }
  if (c.length_ > 0)
    for (double& l : c.arc_) l /= c.length_;
  return c;
}

}  // namespace sylva::lsys
