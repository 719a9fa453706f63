// cpfg background scenes: reading and placing their primitives (see
// cpfg_background.h; vlab cpfg/background.c).
#include "app/cpfg_background.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <optional>

#include "mesh/color.h"
#include "turtle/interpreter.h"

namespace sylva::app {
namespace {

struct Token {
  std::string text;
  int line = 0, column = 0;
};

Diagnostic At(const std::string& path, int line, int column, std::string message,
              Severity severity = Severity::kError) {
  Diagnostic d;
  d.severity = severity;
  d.loc.file = path;
  d.loc.line = line;
  d.loc.column = column;
  d.message = std::move(message);
  return d;
}

bool IsNameStart(char c) {
  return std::isalpha(static_cast<unsigned char>(c)) || c == '_';
}
bool IsNameChar(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
}

// The file's words after cpfg's preprocessor: comments removed, `#define
// NAME value` substituted (a value of several words is pasted whole).
Expected<std::vector<Token>> Tokens(const std::string& text, const std::string& path) {
  std::vector<Token> out;
  std::map<std::string, std::vector<std::string>> defines;
  bool inComment = false;
  int commentLine = 0, commentColumn = 0;  // where the open comment starts
  int number = 0;
  size_t start = 0;
  while (start <= text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(start, end - start);
    start = end + 1;
    ++number;
    // Blank out comments, keeping columns.
    for (size_t i = 0; i < line.size(); ++i) {
      if (inComment) {
        if (line.compare(i, 2, "*/") == 0) {
          line[i] = line[i + 1] = ' ';
          ++i;
          inComment = false;
        } else {
          line[i] = ' ';
        }
      } else if (line.compare(i, 2, "/*") == 0) {
        commentLine = number;
        commentColumn = int(i) + 1;
        line[i] = line[i + 1] = ' ';
        ++i;
        inComment = true;
      } else if (line.compare(i, 2, "//") == 0) {
        line.replace(i, line.size() - i, line.size() - i, ' ');
        break;
      }
    }
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::vector<Token> words;
    for (size_t i = 0; i < line.size();) {
      if (std::isspace(static_cast<unsigned char>(line[i]))) {
        ++i;
        continue;
      }
      size_t e = i;
      while (e < line.size() && !std::isspace(static_cast<unsigned char>(line[e]))) ++e;
      words.push_back({line.substr(i, e - i), number, int(i) + 1});
      i = e;
    }
    if (words.empty()) continue;
    if (words[0].text[0] == '#') {
      const std::string directive = words[0].text.size() > 1
                                        ? words[0].text.substr(1)
                                        : (words.size() > 1 ? words[1].text : std::string());
      const size_t first = words[0].text.size() > 1 ? 1 : 2;  // `# define` too
      if (directive == "define" || directive == "undef") {
        if (words.size() <= first || !IsNameStart(words[first].text[0]) ||
            !std::all_of(words[first].text.begin(), words[first].text.end(), IsNameChar))
          return At(path, number, words[0].column, "expected '#" + directive + " NAME'");
        if (directive == "undef") {
          defines.erase(words[first].text);
          continue;
        }
        if (words[first].text.find('(') != std::string::npos)
          return At(path, number, words[first].column,
                    "a #define with arguments is not supported in a background scene");
        std::vector<std::string> value;
        for (size_t k = first + 1; k < words.size(); ++k) value.push_back(words[k].text);
        defines[words[first].text] = std::move(value);
        continue;
      }
      return At(path, number, words[0].column,
                "preprocessor line '" + words[0].text +
                    "' is not supported in a background scene (#define and #undef are)");
    }
    for (Token& w : words) {
      auto it = defines.find(w.text);
      if (it == defines.end()) {
        if (out.size() >= kMaxBackgroundWords)
          return At(path, w.line, w.column,
                    "the file has more than " + std::to_string(kMaxBackgroundWords) + " words");
        out.push_back(std::move(w));
        continue;
      }
      if (it->second.size() > kMaxBackgroundWords - out.size())
        return At(path, w.line, w.column,
                  "the file has more than " + std::to_string(kMaxBackgroundWords) +
                      " words once '" + w.text + "' (" + std::to_string(it->second.size()) +
                      " words) is substituted here");
      for (const std::string& v : it->second) out.push_back({v, w.line, w.column});
    }
  }
  // cpfg's preprocessor (cpp) stops at a comment that is never closed.
  if (inComment)
    return At(path, commentLine, commentColumn, "a '/*' comment that is never closed with '*/'");
  return out;
}

std::optional<double> NumberOf(const std::string& s) {
  char* end = nullptr;
  const double x = std::strtod(s.c_str(), &end);
  if (end != s.c_str() + s.size() || !std::isfinite(x)) return std::nullopt;
  return x;
}

struct Builder {
  const std::string& path;
  DiagnosticList& warnings;
  BackgroundScene scene;
  std::vector<Eigen::Matrix4d> stack{Eigen::Matrix4d::Identity()};
  uint16_t color = 0;
  bool warnedTranslucent = false;

  Vec3 Point(double x, double y, double z) const {
    const Eigen::Vector4d p = stack.back() * Eigen::Vector4d(x, y, z, 1);
    return Vec3(p.x(), p.y(), p.z());
  }
  void Polygon(std::vector<Vec3> v) {
    mesh::Polygon p;
    p.vertices = std::move(v);
    p.color = color;
    scene.polygons.push_back(std::move(p));
  }
  void Quad(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) { Polygon({a, b, c, d}); }
  // A capped frustum along the matrix's y axis: cpfg's cylinder and cone
  // (position and axis from the matrix, radii as given).
  void Frustum(double r0, double r1, double h) {
    const Vec3 base = Point(0, 0, 0), top = Point(0, h, 0);
    Vec3 axis = top - base;
    if (axis.norm() == 0) axis = Vec3(0, 1, 0);
    axis.normalize();
    const Vec3 any = std::abs(axis.x()) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 0, 1);
    const Vec3 u = axis.cross(any).normalized(), w = axis.cross(u);
    constexpr int kSides = 24;
    std::vector<Vec3> bottom, upper;
    for (int i = 0; i < kSides; ++i) {
      const double a = 2 * kPi * i / kSides;
      const Vec3 dir = std::cos(a) * u + std::sin(a) * w;
      bottom.push_back(base + r0 * dir);
      upper.push_back(top + r1 * dir);
    }
    for (int i = 0; i < kSides; ++i) {
      const int j = (i + 1) % kSides;
      Quad(bottom[size_t(i)], bottom[size_t(j)], upper[size_t(j)], upper[size_t(i)]);
    }
    if (r0 > 0) Polygon(std::vector<Vec3>(bottom.rbegin(), bottom.rend()));
    if (r1 > 0) Polygon(upper);
  }
};

}  // namespace

Expected<BackgroundScene> ParseBackgroundScene(const std::string& text, const std::string& path,
                                               DiagnosticList& warnings) {
  auto tokens = Tokens(text, path);
  if (!tokens) return tokens.error();
  Builder b{path, warnings, {}};  // the rest: the members' defaults
  b.scene.path = path;
  const std::vector<Token>& t = *tokens;
  size_t vertices = 0;  // in the polygons so far
  for (size_t i = 0; i < t.size();) {
    const Token& key = t[i++];
    const size_t polygonsBefore = b.scene.polygons.size();
    const size_t spheresBefore = b.scene.spheres.size();
    std::vector<double> n;
    while (i < t.size()) {
      auto x = NumberOf(t[i].text);
      if (!x) break;
      n.push_back(*x);
      ++i;
    }
    auto need = [&](size_t count, const char* form) -> std::optional<Diagnostic> {
      if (n.size() >= count) return std::nullopt;
      return At(path, key.line, key.column,
                "'" + key.text + "' needs " + std::to_string(count) + " numbers (" + form +
                    "), given " + std::to_string(n.size()));
    };
    // The first `count` numbers are radii: 0 or more.
    auto radii = [&](size_t count) -> std::optional<Diagnostic> {
      for (size_t j = 0; j < count; ++j) {
        if (n[j] >= 0) continue;
        char v[32];
        std::snprintf(v, sizeof v, "%g", n[j]);
        return At(path, key.line, key.column,
                  "'" + key.text + "' has a negative radius (" + v + "): a radius is 0 or more");
      }
      return std::nullopt;
    };
    const std::string& k = key.text;
    if (k == "material") {
      if (auto e = need(8, "ambient RGBA, diffuse RGBA, ...")) return *e;
      // cpfg: translucent when any given alpha is below 1.
      bool translucent = n[7] < 1 || (n.size() >= 12 && n[11] < 1) || (n.size() >= 16 && n[15] < 1);
      if (translucent && !b.warnedTranslucent) {
        b.warnedTranslucent = true;
        warnings.Add(At(path, key.line, key.column,
                        "translucent background materials (alpha below 1) are drawn opaque",
                        Severity::kWarning));
      }
      if (b.scene.colors.size() >= kMaxBackgroundMaterials)
        return At(path, key.line, key.column,
                  "more than " + std::to_string(kMaxBackgroundMaterials) +
                      " materials in a background scene");
      b.scene.colors.push_back({float(n[4]), float(n[5]), float(n[6])});
      b.color = uint16_t(b.scene.colors.size());
    } else if (k == "polygon" || k == "polygonuv") {
      const size_t per = k == "polygon" ? 3 : 6;
      if (auto e = need(3 * per, "three points or more")) return *e;
      std::vector<Vec3> v;
      for (size_t j = 0; j + 2 < n.size(); j += per) v.push_back(b.Point(n[j], n[j + 1], n[j + 2]));
      b.Polygon(std::move(v));
    } else if (k == "rectangle") {
      if (auto e = need(2, "width and height")) return *e;
      const double x = n.size() >= 4 ? n[2] : 0, y = n.size() >= 4 ? n[3] : 0;
      b.Quad(b.Point(x, y, 0), b.Point(x + n[0], y, 0), b.Point(x + n[0], y + n[1], 0),
             b.Point(x, y + n[1], 0));
    } else if (k == "mesh") {
      if (auto e = need(12, "two rows of two points")) return *e;
      for (size_t j = 0; j + 12 <= n.size(); j += 6) {
        auto p = [&](size_t o) { return b.Point(n[j + o], n[j + o + 1], n[j + o + 2]); };
        b.Quad(p(0), p(6), p(9), p(3));
      }
    } else if (k == "prism" || k == "box") {
      if (auto e = need(3, "x y z")) return *e;
      Vec3 c[2][2][2];
      for (int x = 0; x < 2; ++x)
        for (int y = 0; y < 2; ++y)
          for (int z = 0; z < 2; ++z) c[x][y][z] = b.Point(x * n[0], y * n[1], z * n[2]);
      b.Quad(c[0][0][0], c[0][0][1], c[0][1][1], c[0][1][0]);
      b.Quad(c[1][0][0], c[1][1][0], c[1][1][1], c[1][0][1]);
      b.Quad(c[0][0][0], c[0][1][0], c[1][1][0], c[1][0][0]);
      b.Quad(c[0][0][1], c[1][0][1], c[1][1][1], c[0][1][1]);
      b.Quad(c[0][0][0], c[0][0][1], c[1][0][1], c[1][0][0]);
      b.Quad(c[0][1][0], c[1][1][0], c[1][1][1], c[0][1][1]);
    } else if (k == "cylinder") {
      if (auto e = need(2, "radius and height")) return *e;
      if (auto e = radii(1)) return *e;
      b.Frustum(n[0], n[0], n[1]);
    } else if (k == "cone") {
      if (auto e = need(3, "two radii and height")) return *e;
      if (auto e = radii(2)) return *e;
      b.Frustum(n[0], n[1], n[2]);
    } else if (k == "sphere") {
      if (auto e = need(1, "radius")) return *e;
      if (auto e = radii(1)) return *e;
      mesh::Sphere s;
      s.center = b.Point(0, 0, 0);
      s.radius = n[0];
      s.color = b.color;
      b.scene.spheres.push_back(s);
    } else if (k == "pushmatrix") {
      b.stack.push_back(b.stack.back());
    } else if (k == "popmatrix") {
      if (b.stack.size() == 1)
        return At(path, key.line, key.column, "'popmatrix' without its 'pushmatrix'");
      b.stack.pop_back();
    } else if (k == "translate") {
      if (auto e = need(3, "x y z")) return *e;
      b.stack.back() *= Eigen::Affine3d(Eigen::Translation3d(n[0], n[1], n[2])).matrix();
    } else if (k == "rotate") {
      if (auto e = need(4, "angle in degrees and axis x y z")) return *e;
      const Vec3 axis(n[1], n[2], n[3]);
      if (axis.norm() == 0) return At(path, key.line, key.column, "'rotate' about the zero vector");
      b.stack.back() *=
          Eigen::Affine3d(Eigen::AngleAxisd(n[0] * kPi / 180, axis.normalized())).matrix();
    } else if (k == "scale") {
      if (auto e = need(3, "x y z")) return *e;
      b.stack.back() *= Eigen::Affine3d(Eigen::Scaling(n[0], n[1], n[2])).matrix();
    } else if (k == "multmatrix") {
      if (auto e = need(16, "a 4x4 matrix")) return *e;
      Eigen::Matrix4d m;
      for (int j = 0; j < 16; ++j) m(j % 4, j / 4) = n[size_t(j)];  // column by column
      b.stack.back() *= m;
    } else {
      return At(path, key.line, key.column,
                NumberOf(k) ? "a number where a background keyword was expected"
                            : "unknown background scene keyword '" + k + "'");
    }
    // What this primitive added: finite, within the turtle's range, and
    // within the limit on vertices.
    auto within = [](const Vec3& p) {
      return (p.array().abs() <= turtle::kMaxCoordinate).all();  // false for NaN
    };
    for (size_t j = polygonsBefore; j < b.scene.polygons.size(); ++j) {
      const auto& v = b.scene.polygons[j].vertices;
      vertices += v.size();
      if (vertices > kMaxBackgroundVertices)
        return At(path, key.line, key.column,
                  "the background scene has more than " + std::to_string(kMaxBackgroundVertices) +
                      " vertices at this '" + k + "'");
      for (const Vec3& p : v) {
        if (!within(p))
          return At(path, key.line, key.column,
                    "'" + k +
                        "' places a point that is not a finite number within +-1e+15 "
                        "units (the matrix or the numbers are too large)");
      }
    }
    for (size_t j = spheresBefore; j < b.scene.spheres.size(); ++j) {
      const mesh::Sphere& sp = b.scene.spheres[j];
      if (!within(sp.center) || !(std::abs(sp.radius) <= turtle::kMaxCoordinate))
        return At(path, key.line, key.column,
                  "'sphere' has a centre or radius that is not a finite number within +-1e+15 "
                  "units");
    }
  }
  return std::move(b.scene);
}

void AddBackgroundScene(const BackgroundScene& scene, mesh::PlantGeometry& geometry,
                        mesh::Palette& palette) {
  // The palette keeps its meaning for indices below 256 (it wraps, as
  // before); the scene's colours follow.
  const mesh::Palette old = palette.empty() ? mesh::DefaultPalette() : palette;
  const size_t base = std::max<size_t>(old.size(), 256);
  palette.clear();
  for (size_t i = 0; i < base; ++i) palette.push_back(old[i % old.size()]);
  for (const auto& c : scene.colors) palette.push_back(mesh::Srgb(c[0], c[1], c[2]));
  auto colorOf = [&](uint16_t c) { return c == 0 ? uint16_t(0) : uint16_t(base + c - 1); };
  auto grow = [&](const Vec3& lo, const Vec3& hi) {
    geometry.boundsMin = geometry.boundsMin.cwiseMin(lo);
    geometry.boundsMax = geometry.boundsMax.cwiseMax(hi);
  };
  for (mesh::Polygon p : scene.polygons) {
    p.color = colorOf(p.color);
    for (const Vec3& v : p.vertices) grow(v, v);
    geometry.polygons.push_back(std::move(p));
  }
  for (mesh::Sphere s : scene.spheres) {
    s.color = colorOf(s.color);
    grow(s.center - Vec3::Constant(s.radius), s.center + Vec3::Constant(s.radius));
    geometry.spheres.push_back(s);
  }
  if (!scene.polygons.empty() || !scene.spheres.empty()) geometry.planar = false;
}

}  // namespace sylva::app
