// cpfg function files: reading and evaluating (see cpfg_function.h).
#include "lsys/cpfg_function.h"

#include <cmath>
#include <cstdio>
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

}  // namespace

void CpfgFunction::Point(double d, double* x, double* y) const {
  const int n = int(px_.size()) - 1;
  const double u = d * (n - 2);
  *x = *y = 0;
  for (int k = 0; k <= n; ++k) {
    const double b = ClampedBasis(k, 4, u, n + 1);
    *x += px_[size_t(k)] * b;
    *y += py_[size_t(k)] * b;
  }
}

double CpfgFunction::Exact(double v) const {
  double low = 0, high = 1, x = 0, y = 0;
  for (int i = 0; i < 64; ++i) {  // cpfg: until |x - v| <= 0.001
    const double mid = (low + high) / 2;
    Point(mid, &x, &y);
    if (std::fabs(x - v) <= 0.001) break;
    (x > v ? high : low) = mid;
  }
  return y;
}

double CpfgFunction::Value(double v) const {
  v = v < 0 ? 0 : (v > 1 ? 1 : v);
  if (samples_.empty()) return Exact(v);
  const double index = v * double(samples_.size() - 1);
  const size_t i = size_t(std::floor(index));
  if (i + 1 >= samples_.size()) return samples_.back();
  const double w = index - double(i);
  return (1 - w) * samples_[i] + w * samples_[i + 1];
}

Expected<CpfgFunction> CpfgFunction::Parse(const std::string& text, const std::string& path) {
  std::istringstream in(text);
  std::string line;
  int number = 0;
  auto next = [&]() {
    if (!std::getline(in, line)) return false;
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return true;
  };
  auto starts = [&](const char* word) { return line.rfind(word, 0) == 0; };
  CpfgFunction f;
  int samples = 0;
  bool multiplicity = false;
  if (!next()) return FileError(path, 1, "empty function file");
  if (starts("fver")) {
    int major = 0, minor = 0;
    if (std::sscanf(line.c_str(), "fver %d %d", &major, &minor) != 2 || major != 1 || minor != 1)
      return FileError(path, number, "unsupported function file version (Sylva reads 'fver 1 1')");
    if (!next() || !starts("name:")) return FileError(path, number, "expected 'name:'");
    {
      // cpfg: the name up to its last '.' (a file name's suffix), blanks trimmed.
      std::string n = line.substr(5);
      const size_t b = n.find_first_not_of(" \t");
      const size_t e = n.find_last_not_of(" \t");
      n = b == std::string::npos ? std::string() : n.substr(b, e - b + 1);
      if (const size_t dot = n.rfind('.'); dot != std::string::npos) n.resize(dot);
      f.name_ = std::move(n);
    }
    if (!next() || std::sscanf(line.c_str(), "samples: %d", &samples) != 1)
      return FileError(path, number, "expected 'samples: N'");
    if (!next()) return FileError(path, number, "expected 'points: N'");
    if (starts("b")) {  // background: the line and the one after it
      if (!next() || !next()) return FileError(path, number, "expected 'points: N'");
    }
    if (starts("markers:")) {
      int markers = 0;
      if (std::sscanf(line.c_str(), "markers: %d", &markers) != 1 || markers < 0)
        return FileError(path, number, "expected 'markers: N'");
      for (int i = 0; i < markers; ++i) {
        if (!next()) return FileError(path, number, "missing marker line");
      }
      if (!next()) return FileError(path, number, "expected 'points: N'");
    }
    // The flip line, whatever it says (cpfg skips it unread).
    if (!next()) return FileError(path, number, "expected 'points: N'");
    multiplicity = true;
  } else if (starts("range:")) {
    if (!next()) return FileError(path, number, "expected 'points: N'");
  } else {
    return FileError(path, number, "not a cpfg function file (expected 'fver 1 1' or 'range:')");
  }
  long count = 0;
  if (std::sscanf(line.c_str(), "points: %ld", &count) != 1)
    return FileError(path, number, "expected 'points: N'");
  if (count < 4 || count > 100000)
    return FileError(path, number, "a function needs from 4 to 100000 points");
  for (long i = 0; i < count; ++i) {
    if (!next()) return FileError(path, number, "missing point " + std::to_string(i + 1));
    std::istringstream p(line);
    double x = 0, y = 0, m = 1;
    if (!(p >> x >> y) || !std::isfinite(x) || !std::isfinite(y))
      return FileError(path, number, "expected a point 'x y'");
    if (multiplicity && (p >> m) && (m < 1 || m > 100 || m != std::floor(m)))
      return FileError(path, number, "point multiplicity must be a whole number from 1 to 100");
    for (int k = 0; k < int(m); ++k) {
      f.px_.push_back(x);
      f.py_.push_back(y);
    }
  }
  if (samples > 2) {
    if (samples > 1000000) return FileError(path, 3, "more than 1000000 samples");
    f.samples_.resize(size_t(samples));
    for (int i = 0; i < samples; ++i) f.samples_[size_t(i)] = f.Exact(double(i) / (samples - 1));
  }
  return f;
}

Expected<std::vector<CpfgFunction>> CpfgFunction::ParseSet(const std::string& text,
                                                           const std::string& path) {
  // The lines, and where each `fver` function starts.
  std::vector<std::string> lines;
  {
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line)) {
      if (!line.empty() && line.back() == '\r') line.pop_back();
      lines.push_back(std::move(line));
    }
  }
  int major = 0, minor = 0;
  if (lines.empty() || std::sscanf(lines[0].c_str(), "funcgalleryver %d %d", &major, &minor) != 2)
    return FileError(path, 1, "not a cpfg function set (expected 'funcgalleryver 1 1')");
  if (major != 1 || minor != 1)
    return FileError(path, 1,
                     "unsupported function set version (Sylva reads 'funcgalleryver 1 1')");
  long items = -1;
  if (lines.size() < 2 || std::sscanf(lines[1].c_str(), "items: %ld", &items) != 1 || items < 0)
    return FileError(path, 2, "expected 'items: N'");
  std::vector<size_t> starts;
  for (size_t i = 2; i < lines.size(); ++i)
    if (lines[i].rfind("fver", 0) == 0) starts.push_back(i);
  if (long(starts.size()) != items) {
    return FileError(path, 2,
                     "'items: " + std::to_string(items) + "' but the set has " +
                         std::to_string(starts.size()) + " functions ('fver' lines)");
  }
  std::vector<CpfgFunction> set;
  for (size_t k = 0; k < starts.size(); ++k) {
    const size_t end = k + 1 < starts.size() ? starts[k + 1] : lines.size();
    std::string one;
    for (size_t i = starts[k]; i < end; ++i) one += lines[i] + "\n";
    auto f = Parse(one, path);
    if (!f) {
      Diagnostic d = f.error();
      d.loc.line += int(starts[k]);  // the line in the set
      return d;
    }
    set.push_back(std::move(*f));
  }
  return set;
}

}  // namespace sylva::lsys
