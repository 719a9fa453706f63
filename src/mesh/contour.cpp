#include "mesh/contour.h"

#include <algorithm>
#include <charconv>
#include <cmath>

#include "core/assert.h"

namespace sylva::mesh {
namespace {

// A blank-separated word of the file and where it starts.
struct Word {
  std::string text;
  int line = 0;
  int column = 0;
};

struct Lines {
  std::vector<std::string> text;  // without the line ends
  // The words of line i (0-based).
  std::vector<Word> WordsOf(size_t i) const {
    std::vector<Word> words;
    const std::string& s = text[i];
    for (size_t k = 0; k < s.size();) {
      if (s[k] == ' ' || s[k] == '\t') {
        ++k;
        continue;
      }
      size_t e = k;
      while (e < s.size() && s[e] != ' ' && s[e] != '\t') ++e;
      words.push_back({s.substr(k, e - k), int(i) + 1, int(k) + 1});
      k = e;
    }
    return words;
  }
};

Lines SplitLines(const std::string& text) {
  Lines l;
  size_t start = 0;
  while (start <= text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string s = text.substr(start, end - start);
    if (!s.empty() && s.back() == '\r') s.pop_back();
    l.text.push_back(std::move(s));
    if (end == text.size()) break;
    start = end + 1;
  }
  return l;
}

class Parser {
 public:
  Parser(const std::string& text, const std::string& path, DiagnosticList* warnings)
      : lines_(SplitLines(text)), path_(path), warnings_(warnings) {}

  Expected<Contour> Parse();

 private:
  Diagnostic At(int line, int column, std::string message, Severity s = Severity::kError) const {
    Diagnostic d = MakeError(SourceLoc{path_, line, column}, std::move(message), 1,
                             line >= 1 && size_t(line) <= lines_.text.size()
                                 ? std::string_view(lines_.text[size_t(line) - 1])
                                 : std::string_view());
    d.severity = s;
    return d;
  }
  // At the end of the last line with text.
  Diagnostic AtEnd(std::string message) const {
    size_t i = lines_.text.size();
    while (i > 1 && lines_.WordsOf(i - 1).empty()) --i;
    return At(int(i), int(lines_.text[i - 1].size()) + 1, std::move(message));
  }
  void Warn(int line, int column, std::string message) {
    if (warnings_) warnings_->Add(At(line, column, std::move(message), Severity::kWarning));
  }
  // Words from line `from` (0-based) to the end of the file, in order.
  std::vector<Word> WordsFrom(size_t from) const {
    std::vector<Word> all;
    for (size_t i = from; i < lines_.text.size(); ++i) {
      auto w = lines_.WordsOf(i);
      all.insert(all.end(), w.begin(), w.end());
    }
    return all;
  }
  static bool Number(const Word& w, double* x) {
    const char* b = w.text.data();
    const char* e = b + w.text.size();
    if (b != e && *b == '+') ++b;
    auto r = std::from_chars(b, e, *x);
    return r.ec == std::errc() && r.ptr == e && std::isfinite(*x);
  }
  // A whole number from lo to hi in word w, else an error.
  Expected<long> Whole(const Word& w, long lo, long hi, const char* what) const {
    double x;
    if (!Number(w, &x) || x != std::floor(x) || x < double(lo) || x > double(hi)) {
      return At(w.line, w.column,
                std::string("expected ") + what + " (a whole number from " + std::to_string(lo) +
                    " to " + std::to_string(hi) + "), not '" + w.text + "'");
    }
    return long(x);
  }
  Expected<Contour> Unversioned(const std::vector<Word>& header);
  Expected<Contour> Versioned(int version, const Word& at);
  Status Check(const Contour& c, int line, int column) const;
  void Trailing(const std::vector<Word>& words, size_t used) {
    if (used < words.size())
      Warn(words[used].line, words[used].column,
           "text after the contour's last point is not read (cpfg does not read it either)");
  }

  Lines lines_;
  std::string path_;
  DiagnosticList* warnings_;
  size_t lineAfterHeader_ = 0;  // 0-based index of the line after the header
};

Expected<Contour> Parser::Parse() {
  size_t first = 0;
  while (first < lines_.text.size() && lines_.WordsOf(first).empty()) ++first;
  if (first == lines_.text.size())
    return At(1, 1,
              "an empty contour file: expected 'N DIMENSION open|closed' or 'cver 1 3' "
              "(a cpfg .con file)");
  const std::vector<Word> header = lines_.WordsOf(first);
  if (header[0].text == "cver") {
    if (header.size() < 3) return AtEnd("expected 'cver MAJOR MINOR', as 'cver 1 3'");
    auto major = Whole(header[1], 0, 100, "a version number");
    if (!major) return major.error();
    auto minor = Whole(header[2], 0, 100, "a version number");
    if (!minor) return minor.error();
    const int version = int(100 * *major + *minor);
    if (version < 101 || version > 103) {
      return At(header[1].line, header[1].column,
                "contour format " + std::to_string(*major) + "." + std::to_string(*minor) +
                    " is not one cpfg reads (1.1, 1.2 and 1.3)");
    }
    lineAfterHeader_ = first + 1;
    return Versioned(version, header[0]);
  }
  if (header[0].text == "version:") {
    return At(header[0].line, header[0].column,
              "this is a cpfg curve file ('version:'), read by the view file's 'curve:' line, "
              "not a contour ('N DIMENSION open|closed' or 'cver 1 3')");
  }
  lineAfterHeader_ = first + 1;
  return Unversioned(header);
}

// `N DIMENSION open|closed`, then N points of DIMENSION numbers, free-form
// (cpfg's _ReadContour0000).
Expected<Contour> Parser::Unversioned(const std::vector<Word>& header) {
  const char* kForm = "a contour file starts 'N DIMENSION open|closed' or 'cver 1 3'";
  double x;
  if (!Number(header[0], &x)) {
    return At(header[0].line, header[0].column,
              std::string(kForm) + ", not '" + header[0].text + "'");
  }
  auto n = Whole(header[0], 1, long(kMaxContourPoints), "the number of points");
  if (!n) return n.error();
  if (header.size() < 3) return AtEnd(std::string("expected 'N DIMENSION open|closed': ") + kForm);
  auto dim = Whole(header[1], 2, 3, "the dimension");
  if (!dim) return dim.error();
  Contour c;
  if (header[2].text == "closed") {
    c.closed = true;
  } else if (header[2].text != "open") {
    return At(header[2].line, header[2].column,
              "expected 'open' or 'closed', not '" + header[2].text + "'");
  }
  if (header.size() > 3)
    Warn(header[3].line, header[3].column, "text after 'open' or 'closed' is not read");
  const std::vector<Word> words = WordsFrom(lineAfterHeader_);
  size_t k = 0;
  for (long i = 0; i < *n; ++i) {
    Vec3 p(0, 0, 0);
    for (int d = 0; d < *dim; ++d, ++k) {
      if (k >= words.size()) {
        return AtEnd("the file ends before point " + std::to_string(i + 1) + " of " +
                     std::to_string(*n));
      }
      if (!Number(words[k], &p[d])) {
        return At(words[k].line, words[k].column,
                  "expected a number (coordinate " + std::to_string(d + 1) + " of point " +
                      std::to_string(i + 1) + "), not '" + words[k].text + "'");
      }
    }
    c.points.push_back(p);
  }
  Trailing(words, k);
  if (Status s = Check(c, header[0].line, header[0].column); !s.ok()) return s.error();
  return c;
}

// cpfg's _ReadContour0101/0102/0103: `name:`, `points: LINES TOTAL`,
// `type:`, (1.3) `samples:` and an editor's optional `background` (two
// lines) and `markers: N` (N lines), then LINES lines `x y z multiplicity`.
Expected<Contour> Parser::Versioned(int version, const Word& at) {
  size_t i = lineAfterHeader_;
  // The next line's words (blank lines skipped); empty at the end.
  auto next = [&]() -> std::vector<Word> {
    while (i < lines_.text.size()) {
      auto w = lines_.WordsOf(i++);
      if (!w.empty()) return w;
    }
    return {};
  };
  auto expectLabel = [&](const std::vector<Word>& w, const char* label) -> Status {
    if (w.empty()) return AtEnd(std::string("the file ends before its '") + label + "' line");
    if (w[0].text != label)
      return At(w[0].line, w[0].column,
                std::string("expected '") + label + "', not '" + w[0].text + "'");
    return {};
  };
  std::vector<Word> w = next();
  if (Status s = expectLabel(w, "name:"); !s.ok()) return s.error();
  w = next();
  if (Status s = expectLabel(w, "points:"); !s.ok()) return s.error();
  if (w.size() < 3) return At(w[0].line, w[0].column, "expected 'points: LINES TOTAL'");
  auto rows = Whole(w[1], 1, long(kMaxContourPoints), "the number of point lines");
  if (!rows) return rows.error();
  auto total = Whole(w[2], 1, long(kMaxContourPoints), "the number of points");
  if (!total) return total.error();
  const Word totalAt = w[2];
  w = next();
  if (Status s = expectLabel(w, "type:"); !s.ok()) return s.error();
  if (w.size() < 2) return At(w[0].line, w[0].column, "expected 'type: or' (open or closed)");
  Contour c;
  const std::string& type = w[1].text;
  if (version == 101) {
    c.closed = type.rfind("open", 0) != 0;  // cpfg: anything but open is closed
  } else {
    if ((type[0] != 'o' && type[0] != 'c') || type.size() < 2 ||
        (type[1] != 'r' && type[1] != 'e')) {
      return At(w[1].line, w[1].column,
                "expected a type of two letters, o(pen) or c(losed) then r(egular) or e(nd "
                "points), not '" +
                    type + "'");
    }
    c.closed = type[0] == 'c';
    if (type[1] == 'e')
      Warn(w[1].line, w[1].column,
           "a contour with end point interpolation is drawn as a regular one (as cpfg does)");
  }
  if (version == 103) {
    w = next();
    if (Status s = expectLabel(w, "samples:"); !s.ok()) return s.error();
    // Optional lines of the contour editor: a background image (two lines)
    // and markers (a count, then that many lines).
    while (i < lines_.text.size()) {
      auto peek = lines_.WordsOf(i);
      if (peek.empty()) {
        ++i;
      } else if (peek[0].text.rfind("background", 0) == 0) {
        i += 2;
      } else if (peek[0].text == "markers:") {
        if (peek.size() < 2) return At(peek[0].line, peek[0].column, "expected 'markers: N'");
        auto m = Whole(peek[1], 0, long(kMaxContourPoints), "the number of markers");
        if (!m) return m.error();
        i += 1 + size_t(*m);
      } else {
        break;
      }
    }
  }
  const std::vector<Word> words = WordsFrom(std::min(i, lines_.text.size()));
  size_t k = 0;
  for (long r = 0; r < *rows; ++r) {
    Vec3 p;
    for (int d = 0; d < 4; ++d, ++k) {
      if (k >= words.size()) {
        return AtEnd("the file ends before point line " + std::to_string(r + 1) + " of " +
                     std::to_string(*rows) + " ('x y z multiplicity')");
      }
      if (d == 3) {
        auto m = Whole(words[k], 1, long(kMaxContourPoints), "a multiplicity");
        if (!m) return m.error();
        if (c.points.size() + size_t(*m) > size_t(*total)) {
          return At(totalAt.line, totalAt.column,
                    "the multiplicities add up to more than the " + std::to_string(*total) +
                        " points this line says");
        }
        c.points.insert(c.points.end(), size_t(*m), p);
      } else if (!Number(words[k], &p[d])) {
        return At(words[k].line, words[k].column,
                  "expected a number (coordinate " + std::to_string(d + 1) + " of point line " +
                      std::to_string(r + 1) + "), not '" + words[k].text + "'");
      }
    }
  }
  if (c.points.size() != size_t(*total)) {
    return At(totalAt.line, totalAt.column,
              "the multiplicities add up to " + std::to_string(c.points.size()) + " points, not " +
                  std::to_string(*total));
  }
  Trailing(words, k);
  if (Status s = Check(c, at.line, at.column); !s.ok()) return s.error();
  return c;
}

// The largest |x| or |y| of the points (1 when there is none, or it is not
// finite): dividing by it keeps squared lengths from under- or overflowing.
double XyScale(const Contour& c) {
  double m = 0;
  for (const Vec3& p : c.points) m = std::max({m, std::abs(p.x()), std::abs(p.y())});
  return m > 0 && std::isfinite(m) ? m : 1;
}

// Enough points for a cubic B-spline, and a curve with a length in (x, y).
Status Parser::Check(const Contour& c, int line, int column) const {
  const size_t need = c.closed ? 3 : 4;
  if (c.points.size() < need) {
    return At(line, column,
              std::string("a") + (c.closed ? " closed" : "n open") + " contour needs at least " +
                  std::to_string(need) + " points (a cubic B-spline); this one has " +
                  std::to_string(c.points.size()));
  }
  // Measured with the points scaled to at most 1 in x and y: a contour of
  // 1e-300 units (whose squared lengths underflow to 0) has a length too.
  const double scale = XyScale(c);
  double extent = 0;
  for (const Vec3& p : c.points)
    extent = std::max(extent, ((p.head<2>() - c.points[0].head<2>()) / scale).norm());
  if (!(extent > 0)) {
    return At(line, column,
              "every point of the contour is at the same (x, y): it has no length to draw");
  }
  return {};
}

// The uniform cubic B-spline at parameter t: span floor(t) uses points
// floor(t) .. floor(t) + 3 (indices wrap for a closed contour).
Vec3 Evaluate(const Contour& c, double t) {
  const size_t n = c.points.size();
  const size_t spans = c.closed ? n : n - 3;
  double f = std::floor(t);
  if (f >= double(spans)) f = double(spans) - 1;
  if (f < 0) f = 0;
  const double u = t - f;
  const double u2 = u * u, u3 = u2 * u;
  const double b[4] = {(1 - u) * (1 - u) * (1 - u) / 6, (3 * u3 - 6 * u2 + 4) / 6,
                       (-3 * u3 + 3 * u2 + 3 * u + 1) / 6, u3 / 6};
  Vec3 p(0, 0, 0);
  for (size_t k = 0; k < 4; ++k) p += b[k] * c.points[(size_t(f) + k) % n];
  return p;
}

}  // namespace

Expected<Contour> ParseContour(const std::string& text, const std::string& path,
                               DiagnosticList* warnings) {
  return Parser(text, path, warnings).Parse();
}

std::vector<Vec3> CircleContour(int sides) {
  SYLVA_ASSERT(sides >= 3);
  std::vector<Vec3> r(size_t(sides) + 1);
  for (int i = 0; i < sides; ++i) {
    const double a = 2 * kPi * i / sides;
    r[size_t(i)] = Vec3(std::cos(a), std::sin(a), 0);
  }
  r[size_t(sides)] = r[0];
  return r;
}

std::vector<Vec3> SampleContour(const Contour& contour, int sides) {
  SYLVA_ASSERT(sides >= 3 && sides <= kMaxContourSides);
  SYLVA_ASSERT(contour.points.size() >= (contour.closed ? 3u : 4u));
  // Sampled at unit scale (XyScale), then scaled back: the B-spline, its
  // arc length parameter and the turn below all commute with scaling.
  const double scale = XyScale(contour);
  Contour c = contour;
  for (Vec3& p : c.points) p /= scale;
  // Arc length in (x, y) tabulated at kPerSpan steps a span (cpfg: 10),
  // then inverted piecewise linearly. cpfg's table of an open contour
  // stops a tenth of a span before its end; this one runs to the end.
  constexpr int kPerSpan = 64;
  const size_t spans = c.closed ? c.points.size() : c.points.size() - 3;
  const size_t m = spans * kPerSpan;
  std::vector<double> length(m + 1, 0.0);
  Vec3 prev = Evaluate(c, 0);
  for (size_t s = 1; s <= m; ++s) {
    const Vec3 p = c.closed && s == m ? Evaluate(c, 0) : Evaluate(c, double(s) / kPerSpan);
    length[s] = length[s - 1] + (p.head<2>() - prev.head<2>()).norm();
    prev = p;
  }
  const double total = length[m];
  std::vector<Vec3> r(size_t(sides) + 1);
  const int count = c.closed ? sides : sides + 1;
  for (int i = 0; i < count; ++i) {
    const double want = total * i / sides;
    // The first table entry at or past `want`, and the one before it with
    // a shorter length (repeated points make runs of equal lengths).
    size_t hi = size_t(std::lower_bound(length.begin(), length.end(), want) - length.begin());
    if (hi > m) hi = m;
    double t;
    if (hi == 0) {
      t = 0;
    } else {
      size_t lo = hi - 1;
      while (lo > 0 && length[lo] >= length[hi]) --lo;
      const double span = length[hi] - length[lo];
      const double f = span > 0 ? std::clamp((want - length[lo]) / span, 0.0, 1.0) : 0.0;
      t = (double(lo) + f * double(hi - lo)) / kPerSpan;
    }
    r[size_t(i)] = Evaluate(c, t);
  }
  if (c.closed) {
    // cpfg turns a closed contour so that its first point is on +x.
    const Vec2 f = r[0].head<2>();
    const double n = f.norm();
    if (n > 1e-9) {
      const double cs = f.x() / n, sn = f.y() / n;
      for (int i = 0; i < sides; ++i) {
        const Vec3 p = r[size_t(i)];
        r[size_t(i)] = Vec3(p.x() * cs + p.y() * sn, -p.x() * sn + p.y() * cs, p.z());
      }
    }
    r[size_t(sides)] = r[0];
  }
  for (Vec3& p : r) p *= scale;
  return r;
}

}  // namespace sylva::mesh
