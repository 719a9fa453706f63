#include "app/view_file.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <set>
#include <string_view>

#include "app/cpfg_specifications.h"
#include "core/atomic_file.h"
#include "lsys/deriver.h"
#include "mesh/contour.h"

namespace sylva::app {
namespace {

namespace fs = std::filesystem;

// A view file is a few hundred bytes; colour files are 768 bytes and at most
// a few kilobytes of materials.
constexpr size_t kMaxViewBytes = size_t(1) << 20;
constexpr size_t kMaxColorBytes = size_t(64) << 10;
constexpr size_t kMaxBackgroundBytes = size_t(16) << 20;  // a background scene file
constexpr size_t kMapBytes = 768;
constexpr size_t kMaterialBytes = 15;
// A file that is not a view file (a binary one) stops here, not after a
// diagnostic for each of its million lines.
constexpr size_t kMaxViewErrors = 50;

// What Sylva says about a label it reads but does not act on.
struct Ignored {
  std::string_view label;
  std::string_view why;
};

constexpr std::string_view kLighting =
    "shading: Sylva's renderer shades every plant with its own materials, fill and ambient "
    "light (the key light takes the direction of 'light direction:' or the first 'light:')";
constexpr std::string_view kSurfaces =
    "Sylva reads cpfg's .s surfaces from 'surface:', not line or triangle surfaces "
    "(docs/cpfg.md)";
constexpr std::string_view kNotActed = "Sylva does not act on it";

constexpr Ignored kIgnored[] = {
    {"front distance:", "clipping planes: Sylva sets its own near and far planes around the plant"},
    {"back distance:", "clipping planes: Sylva sets its own near and far planes around the plant"},
    {"shade mode:", kLighting},
    {"diffuse reflection:", kLighting},
    {"surface ambient:", kLighting},
    {"surface diffuse:", kLighting},
    {"ambient light:", "cpfg's OpenGL renderer does not use it either"},
    {"render mode:", kLighting},
    {"shadow map:", kLighting},
    {"line:", kSurfaces},
    {"tsurface:", kSurfaces},
    {"background color:", kNotActed},
    {"font:", kNotActed},
    {"winfont:", kNotActed},
    {"blob:", kNotActed},
    {"texture:", "textures are not implemented"},
    {"tapered lines:", "Sylva's tubes taper to the width of the next segment"},
    {"interpretation step:", kNotActed},
    {"interpretation past %:", kNotActed},
    {"rayshade objects:", kNotActed},
    {"rayshade scale:", kNotActed},
    {"initial scale:", "@D scaling is not implemented"},
    {"scale multiplier:", "@D scaling is not implemented"},
    {"environment display:", kNotActed},
    {"antialiasing:", "use render --supersample"},
    {"min zoom:", kNotActed},
    {"max zoom:", kNotActed},
    {"generate on view change:", kNotActed},
    {"concave polygons:", "Sylva triangulates concave polygons always"},
    {"PS linecap:", kNotActed},
};

// One line of the file after comments are removed, with the column where
// each byte of it was.
struct Line {
  int number = 0;
  std::string text;
};

// Splits `text` into lines, blanking /* */ (across lines) and // comments
// with spaces so columns stay true.
std::vector<Line> Lines(const std::string& text) {
  std::vector<Line> lines;
  bool inBlock = false;
  size_t start = 0;
  int number = 1;
  while (start <= text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string s = text.substr(start, end - start);
    if (!s.empty() && s.back() == '\r') s.pop_back();
    for (size_t i = 0; i < s.size(); ++i) {
      if (inBlock) {
        if (s.compare(i, 2, "*/") == 0) {
          s[i] = s[i + 1] = ' ';
          ++i;
          inBlock = false;
        } else {
          s[i] = ' ';
        }
      } else if (s.compare(i, 2, "/*") == 0) {
        s[i] = s[i + 1] = ' ';
        ++i;
        inBlock = true;
      } else if (s.compare(i, 2, "//") == 0) {
        s.resize(i);
        break;
      }
    }
    lines.push_back({number++, std::move(s)});
    if (end == text.size()) break;
    start = end + 1;
  }
  return lines;
}

class Reader {
 public:
  Reader(ViewFile& v, const std::string& path, bool checkFiles)
      : v_(v), path_(path), checkFiles_(checkFiles) {}

  void Read(const app::Line& line);
  // What the file says, with cpfg's defaults (InitializeParameters): line
  // style pixel, width 1, parallel projection.
  void Finish() {
    if (!v_.width) v_.width = 1;
    v_.widthInPixels = lineStyle_ != LineStyle::kWorld;
    v_.parallel = parallel_;
    // cpfg's OpenGL renderer: the `light:` lines, else one directional
    // light toward `light direction:`.
    v_.lightToward = firstLight_ ? firstLight_ : lightDirection_;
    v_.cylinderStyle = cylinder_;
    // cpfg's camera looks from the viewpoint toward the view reference
    // point (a perspective view's eye at vrp + (viewpoint - vrp) / scale):
    // where the two coincide, or lie too far apart for double precision,
    // it has no direction or distance, and Sylva frames the plant instead.
    if (v_.viewpoint || v_.target) {
      const Vec3 eye = v_.viewpoint.value_or(Vec3(0, 0, 1));
      const Vec3 at = v_.target.value_or(Vec3(0, 0, 0));
      const double n = (eye - at).norm();
      const double d = parallel_ ? n : n / v_.scale.value_or(1);
      if (!(n > 0 && std::isfinite(n) && d > 0 && std::isfinite(d))) {
        current_ = cameraText_;
        v_.diagnostics.Add(At(v_.cameraLine, 1, Severity::kWarning,
                              eye == at ? "the viewpoint is the view reference point: cpfg's "
                                          "camera looks in no direction: Sylva frames the plant "
                                          "itself"
                                        : "the eye's distance from the view reference point "
                                          "under- or overflows a double: Sylva frames the plant "
                                          "itself"));
      }
    }
    if (contourLine_ && !cylinder_) {
      current_ = contourText_;
      v_.diagnostics.Add(At(contourLine_, contourColumn_, Severity::kWarning,
                            "cpfg draws contours with its line style cylinder only ('line style: "
                            "cylinder', or 'initial line width: W s'); this file's is not: its "
                            "generalized cylinders are drawn round"));
    } else if (sidesLine_ && !contourLine_) {
      current_ = sidesText_;
      v_.diagnostics.Add(At(sidesLine_, sidesColumn_, Severity::kWarning,
                            "'" + sidesLabel_ +
                                "' is read but not acted on: the file has no 'contour:' line, "
                                "and round tubes take their detail from --sides or --lod-eps"));
    }
  }

 private:
  // The values after the label: numbers and words split at blanks and
  // commas (cpfg writes `viewpoint: 0,0,1`), with their columns.
  struct Token {
    std::string text;
    int column = 0;
  };

  Diagnostic At(int line, int column, Severity severity, std::string message) const {
    Diagnostic d;
    d.severity = severity;
    d.loc.file = path_;
    d.loc.line = line;
    d.loc.column = column;
    d.message = std::move(message);
    SetExcerpt(d, current_);
    return d;
  }
  void Warn(int column, const std::string& message) {
    v_.diagnostics.Add(At(line_, column, Severity::kWarning, message));
  }
  void Error(int column, const std::string& message) {
    v_.diagnostics.Add(At(line_, column, Severity::kError, message));
  }
  // The number in token k (finite); an error at the token, or at the end of
  // the line when it is missing.
  std::optional<double> Number(size_t k, const char* what) {
    if (k >= tokens_.size()) {
      Error(int(current_.size()) + 1, std::string("expected ") + what + " after '" + label_ + "'");
      return std::nullopt;
    }
    const Token& t = tokens_[k];
    char* end = nullptr;
    const double x = std::strtod(t.text.c_str(), &end);
    if (end != t.text.c_str() + t.text.size() || !std::isfinite(x)) {
      Error(t.column, std::string("expected ") + what + ", not '" + t.text + "'");
      return std::nullopt;
    }
    return x;
  }
  std::optional<Vec3> Vector(size_t k, const char* what) {
    auto x = Number(k, what), y = x ? Number(k + 1, what) : std::nullopt,
         z = y ? Number(k + 2, what) : std::nullopt;
    if (!z) return std::nullopt;
    return Vec3(*x, *y, *z);
  }
  // Warns once per label that Sylva does not act on the line.
  void NotActed(std::string_view why) {
    if (!warned_.insert(label_).second) return;
    Warn(labelColumn_, "'" + label_ + "' is read but not acted on: " + std::string(why));
  }
  void ExtraValues(size_t used) {
    if (tokens_.size() > used)
      Warn(tokens_[used].column, "'" + label_ + "': Sylva uses " + std::to_string(used) +
                                     (used == 1 ? " value" : " values") + "; the rest is ignored");
  }
  void Movement(bool torque);
  void Surface();
  void Light();
  void ContourLine();

  ViewFile& v_;
  std::string path_;
  bool checkFiles_ = false;  // whether the files the lines name are looked for
  std::string current_;      // the line as read (comments blanked)
  int line_ = 0;
  std::string label_;
  int labelColumn_ = 1;
  std::vector<Token> tokens_;
  std::set<std::string> warned_;
  enum class LineStyle { kUnset, kPixel, kWorld };
  LineStyle lineStyle_ = LineStyle::kUnset;
  bool cylinder_ = false;                    // cpfg's line style cylinder
  int contourLine_ = 0, contourColumn_ = 0;  // the first `contour:` line
  int sidesLine_ = 0, sidesColumn_ = 0;      // `contour sides:`
  std::string contourText_, sidesText_;      // those lines, for the excerpts
  std::string cameraText_;                   // the camera's line (ViewFile::cameraLine)
  std::string sidesLabel_;                   // `contour sides:` or `polygonization level:`
  bool parallel_ = true;
  std::optional<Vec3> lightDirection_, firstLight_;
  int lights_ = 0;
};

void Reader::Read(const app::Line& line) {
  current_ = line.text;
  line_ = line.number;
  const std::string& s = current_;
  size_t i = s.find_first_not_of(" \t");
  if (i == std::string::npos) return;
  labelColumn_ = int(i) + 1;
  if (s[i] == '#') {
    label_ = "#";
    Warn(labelColumn_,
         "preprocessor lines are not run in a view file (cpfg runs the C preprocessor): ignored");
    return;
  }
  const size_t colon = s.find(':', i);
  if (colon == std::string::npos) {
    Error(labelColumn_, "expected 'label: values' (a cpfg view file line)");
    return;
  }
  // The label with its blanks collapsed, as cpfg spells it.
  label_.clear();
  for (size_t k = i; k <= colon; ++k) {
    const char c = s[k];
    if (c == ' ' || c == '\t') {
      if (!label_.empty() && label_.back() != ' ') label_ += ' ';
    } else {
      label_ += c;
    }
  }
  if (label_.size() >= 2 && label_[label_.size() - 2] == ' ') label_.erase(label_.size() - 2, 1);
  tokens_.clear();
  for (size_t k = colon + 1; k < s.size();) {
    if (s[k] == ' ' || s[k] == '\t' || s[k] == ',') {
      ++k;
      continue;
    }
    size_t e = k;
    while (e < s.size() && s[e] != ' ' && s[e] != '\t' && s[e] != ',') ++e;
    tokens_.push_back({s.substr(k, e - k), int(k) + 1});
    k = e;
  }
  const std::string& L = label_;
  if (L == "angle factor:") {
    if (auto x = Number(0, "a number of steps in a full turn")) {
      if (*x == 0)  // cpfg divides 360 by it; a file whose turns all give their angle runs
        Warn(tokens_[0].column,
             "'angle factor: 0' gives no angle increment (cpfg divides 360 by it): ignored, "
             "the angle increment stays as it was (L-studio's dynamic3 turns only by "
             "explicit angles)");
      else
        v_.angle = 360.0 / *x;
    }
    ExtraValues(1);
  } else if (L == "angle increment:") {
    if (auto x = Number(0, "an angle in degrees")) v_.angle = *x;
    ExtraValues(1);
  } else if (L == "initial color:" || L == "color increment:") {
    if (auto x = Number(0, "a colour index")) {
      if (*x < 0 || *x > 65535 || *x != std::floor(*x)) {
        Error(tokens_[0].column,
              "expected a whole number from 0 to 65535, not '" + tokens_[0].text + "'");
      } else {
        (L == "initial color:" ? v_.initialColor : v_.colorIncrement) = int(*x);
      }
    }
    if (tokens_.size() > 1)
      Warn(tokens_[1].column, "'" + L + "': the back-side colour is not implemented: ignored");
  } else if (L == "initial line width:") {
    if (auto x = Number(0, "a width")) {
      if (*x < 0)
        Error(tokens_[0].column, "a width must not be negative");
      else
        v_.width = *x;
    }
    // cpfg (interpret.c, ReadViewData): a word after the width starting
    // with `p` makes it pixels, with `s` a cylinder; otherwise (nothing
    // after the number, or another word) polygons: world units. cpfg looks
    // at the first letter only, so its `polygons` would be pixels too;
    // Sylva reads `po...` as the polygons the word names.
    const bool word =
        tokens_.size() > 1 && std::isalpha(static_cast<unsigned char>(tokens_[1].text[0]));
    const bool pixels = word && tokens_[1].text[0] == 'p' && tokens_[1].text.rfind("po", 0) != 0;
    lineStyle_ = pixels ? LineStyle::kPixel : LineStyle::kWorld;
    cylinder_ = word && tokens_[1].text[0] == 's';
    ExtraValues(word ? 2 : 1);
  } else if (L == "line width increment:") {
    if (auto x = Number(0, "a width")) v_.widthIncrement = *x;
    ExtraValues(1);
  } else if (L == "viewpoint:" || L == "view reference point:") {
    if (auto p = Vector(0, "x,y,z")) {
      (L == "viewpoint:" ? v_.viewpoint : v_.target) = *p;
      if (L == "viewpoint:" || !v_.viewpoint) {
        v_.cameraLine = line_;
        cameraText_ = current_;
      }
    }
    ExtraValues(3);
  } else if (L == "box:") {
    // cpfg's fixed view volume, `box: x: x0,x1 y: y0,y1 z: z0,z1` (its
    // automatic window off): a parallel view frames it, not the plant.
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    int seen = 0;
    // cpfg reads it with scanf, so `z:-4,4` (no blank after the colon) too.
    for (size_t k = 0; k < tokens_.size(); ++k) {
      Token& t = tokens_[k];
      if (t.text.size() > 2 && t.text[1] == ':' && std::strchr("xyz", t.text[0])) {
        Token rest{t.text.substr(2), t.column + 2};
        t.text.resize(2);
        tokens_.insert(tokens_.begin() + std::ptrdiff_t(k) + 1, std::move(rest));
      }
    }
    for (size_t k = 0; k < tokens_.size();) {
      const std::string& t = tokens_[k].text;
      const int axis = t == "x:" ? 0 : t == "y:" ? 1 : t == "z:" ? 2 : -1;
      if (axis < 0) {
        Error(tokens_[k].column, "expected 'x:', 'y:' or 'z:' in 'box:', not '" + t + "'");
        return;
      }
      auto a = Number(k + 1, "a number"), b = a ? Number(k + 2, "a number") : std::nullopt;
      if (!b) return;
      lo[axis] = std::min(*a, *b);
      hi[axis] = std::max(*a, *b);
      seen |= 1 << axis;
      k += 3;
    }
    if (seen != 7) {
      Error(labelColumn_, "'box:' needs the ranges 'x: x0,x1 y: y0,y1 z: z0,z1'");
      return;
    }
    // The camera frames boxes within +-1e30 (render::Camera::Frame; a
    // larger one would be replaced by the unit cube, silently).
    for (int k = 0; k < 3; ++k) {
      if (!(std::abs(lo[k]) <= 1e30 && std::abs(hi[k]) <= 1e30)) {
        Warn(labelColumn_,
             "'box:' reaches beyond +-1e30, more than Sylva's camera frames: "
             "ignored (the plant is framed)");
        return;
      }
    }
    v_.box = {Vec3(lo[0], lo[1], lo[2]), Vec3(hi[0], hi[1], hi[2])};
    v_.boxLine = line_;
  } else if (L == "scale factor:") {
    if (auto x = Number(0, "a scale")) {
      if (*x > 0)
        v_.scale = *x;
      else if (*x < 0)
        Error(tokens_[0].column, "'scale factor:' must be positive");
      // 0: cpfg reads it as 1
    }
    ExtraValues(1);
  } else if (L == "viewing angle:") {
    // cpfg: the vertical field of view of the perspective projection.
    if (auto x = Number(0, "an angle in degrees")) {
      if (*x > 0 && *x < 180)
        v_.viewingAngle = *x;
      else
        Error(tokens_[0].column, "'viewing angle:' must be between 0 and 180 degrees");
    }
    ExtraValues(1);
  } else if (L == "twist:") {
    if (auto x = Number(0, "an angle")) {
      if (*x != 0) NotActed("a twisted view (the camera's up is +Y)");
    }
  } else if (L == "z buffer:") {
    if (tokens_.empty() || tokens_[0].text != "on") NotActed("Sylva always draws with a z buffer");
  } else if (L == "cue range:") {
    if (auto x = Number(0, "a range")) {
      if (*x != 0) NotActed("depth cueing is not implemented");
    }
  } else if (L == "projection:") {
    // cpfg: `parallel...` or `perspective...`; anything else is parallel
    // with a warning.
    if (tokens_.empty()) {
      Error(int(current_.size()) + 1, "expected 'parallel' or 'perspective'");
    } else if (tokens_[0].text.rfind("perspective", 0) == 0) {
      parallel_ = false;
    } else {
      parallel_ = true;
      if (tokens_[0].text.rfind("parallel", 0) != 0)
        Warn(tokens_[0].column,
             "unknown projection '" + tokens_[0].text + "': parallel, as cpfg assumes");
    }
    ExtraValues(1);
  } else if (L == "line style:") {
    // cpfg: pixel, polygon, cylinder, or their numbers 1, 2, 3.
    const std::string w = tokens_.empty() ? "" : tokens_[0].text;
    if (w == "pixel" || w == "1") {
      lineStyle_ = LineStyle::kPixel;
      cylinder_ = false;
    } else if (w == "polygon" || w == "cylinder" || w == "2" || w == "3") {
      lineStyle_ = LineStyle::kWorld;
      cylinder_ = w == "cylinder" || w == "3";
    } else {
      // cpfg keeps the line style it had (interpret.c ReadViewData).
      Warn(tokens_.empty() ? int(current_.size()) + 1 : tokens_[0].column,
           "'line style:' is 'pixel', 'polygon' or 'cylinder', not '" +
               (tokens_.empty() ? std::string() : tokens_[0].text) +
               "': the line style stays as it was, as in cpfg");
    }
    ExtraValues(1);
  } else if (L == "tropism direction:") {
    if (auto p = Vector(0, "x,y,z")) {
      // 0,0,0: no direction, so no bending (as in cpfg, whose tropism is
      // the cross product with it).
      v_.tropism = p->norm() > 0 ? Vec3(p->normalized()) : Vec3::Zero();
    }
    ExtraValues(3);
  } else if (L == "initial elasticity:") {
    if (auto x = Number(0, "an elasticity")) v_.elasticity = *x;
    ExtraValues(1);
  } else if (L == "elasticity increment:") {
    if (auto x = Number(0, "an elasticity")) v_.elasticityIncrement = *x;
    ExtraValues(1);
  } else if (L == "light direction:") {
    // cpfg: the direction toward the light (normalised); its OpenGL
    // renderer makes it a directional light when no `light:` line is given.
    if (auto d = Vector(0, "x,y,z")) {
      if (d->norm() == 0)
        Error(tokens_[0].column, "the light direction must not be 0,0,0");
      else
        lightDirection_ = d->normalized();
    }
    ExtraValues(3);
  } else if (L == "light:") {
    Light();
  } else if (L == "tropism:" || L == "torque:") {
    Movement(L == "torque:");
  } else if (L == "surface:") {
    Surface();
  } else if (L == "contour:") {
    ContourLine();
  } else if (L == "contour sides:" || L == "polygonization level:") {
    // cpfg (ReadViewData): fewer than 3 is 3, with a message; the older
    // `polygonization level: n` is 2^(n+1) sides.
    std::optional<double> x = Number(0, L == "contour sides:" ? "a number of sides" : "a level");
    if (x && L == "polygonization level:") {
      if (*x != std::floor(*x) || *x < 0 || *x > 10) {
        Error(tokens_[0].column, "expected a level from 0 to 10, not '" + tokens_[0].text + "'");
        return;
      }
      x = std::pow(2.0, *x + 1);
    }
    if (x) {
      if (*x != std::floor(*x)) {
        Error(tokens_[0].column, "expected a whole number of sides, not '" + tokens_[0].text + "'");
      } else if (*x < 3) {
        Warn(tokens_[0].column, "a contour has at least 3 sides (cpfg uses 3)");
        v_.contours.sides = 3;
      } else if (*x > mesh::kMaxContourSides) {
        Warn(tokens_[0].column, "more than " + std::to_string(mesh::kMaxContourSides) +
                                    " contour sides: Sylva draws " +
                                    std::to_string(mesh::kMaxContourSides));
        v_.contours.sides = mesh::kMaxContourSides;
      } else {
        v_.contours.sides = int(*x);
      }
      sidesLine_ = line_;
      sidesColumn_ = labelColumn_;
      sidesText_ = current_;
      sidesLabel_ = L;
    }
    ExtraValues(1);
  } else if (L == "twist of cylinders:") {
    // cpfg: `on...` turns the cross-sections with the turtle; anything else is off.
    if (tokens_.empty()) {
      Error(int(current_.size()) + 1, "expected 'on' or 'off'");
    } else {
      v_.contours.twist = tokens_[0].text.rfind("on", 0) == 0;
      if (!v_.contours.twist && tokens_[0].text != "off")
        Warn(tokens_[0].column, "'twist of cylinders:' is 'on' or 'off', not '" + tokens_[0].text +
                                    "': off, as cpfg reads it");
    }
    ExtraValues(1);
  } else if (L == "function:" || L == "function set:") {
    // `function: FILE.func [samples]`: func(1, x) is the first such line.
    // cpfg tabulates the curve at `samples` points; Sylva evaluates it
    // (docs/cpfg.md), so the number is not needed. `function set:
    // FILE.fset`: the functions of a set, in order, each also by its name.
    const bool set = L == "function set:";
    if (tokens_.empty()) {
      Error(int(current_.size()) + 1, set ? "expected 'function set: FILE.fset'"
                                          : "expected 'function: FILE.func [samples]'");
      return;
    }
    const fs::path file(tokens_[0].text);
    lsys::ParseOptions::FunctionFile f;
    f.file = file.is_absolute()
                 ? file.string()
                 : (fs::path(path_).parent_path() / file).lexically_normal().string();
    f.from = path_;
    f.line = line_;
    f.column = tokens_[0].column;
    f.set = set;
    v_.functions.push_back(std::move(f));
    if (set) {
      ExtraValues(1);
      return;
    }
    if (tokens_.size() > 1) Number(1, "a number of samples");
    ExtraValues(2);
  } else if (L == "background scene:") {
    // cpfg: the names are separated by blanks, commas or semicolons.
    if (tokens_.empty()) {
      Error(int(current_.size()) + 1, "expected 'background scene: FILE'");
      return;
    }
    for (const Token& t : tokens_) {
      size_t s = 0;
      while (s < t.text.size()) {
        size_t e = t.text.find_first_of(",;", s);
        if (e == std::string::npos) e = t.text.size();
        if (e > s) {
          const fs::path file(t.text.substr(s, e - s));
          ViewFile::NamedFile f;
          f.file = file.is_absolute()
                       ? file.string()
                       : (fs::path(path_).parent_path() / file).lexically_normal().string();
          f.line = line_;
          f.column = t.column + int(s);
          v_.backgroundFiles.push_back(std::move(f));
        }
        s = e + 1;
      }
    }
  } else if (L == "curve:") {
    // `curve: FILE.con [samples]`: curveX(1, t) reads the first; samples
    // is the size of cpfg's arc-length table (lsys/cpfg_curve.h).
    if (tokens_.empty()) {
      Error(int(current_.size()) + 1, "expected 'curve: FILE.con [samples]'");
      return;
    }
    const fs::path file(tokens_[0].text);
    lsys::ParseOptions::CurveFile c;
    c.file = file.is_absolute()
                 ? file.string()
                 : (fs::path(path_).parent_path() / file).lexically_normal().string();
    c.from = path_;
    c.line = line_;
    c.column = tokens_[0].column;
    // A bad number of samples is an error here, and the curve is still
    // counted: without it curveX(1, t) said the view file had no 'curve:'
    // line, and that error hid this one.
    if (tokens_.size() > 1) {
      const std::optional<double> n = Number(1, "a number of samples");
      if (n && (*n < 2 || *n > 1000000 || *n != std::floor(*n)))
        Error(tokens_[1].column, "a curve's samples must be a whole number from 2 to 1000000");
      else if (n)
        c.samples = int(*n);
    }
    v_.curves.push_back(std::move(c));
    ExtraValues(2);
  } else {
    for (const Ignored& ig : kIgnored) {
      if (L == ig.label) {
        NotActed(ig.why);
        return;
      }
    }
    if (warned_.insert(label_).second)
      Warn(labelColumn_, "'" + label_ + "' is not a cpfg view file setting Sylva knows: ignored");
  }
}

// `tropism: T x,y,z A angle E elasticity S step I intensity` and `torque:`
// with the same letters (vlab cpfg movements.c, read_movement): one
// lsys::Movement each, in the order given; @Ts(i, e) addresses the i-th.
void Reader::Movement(bool torque) {
  // cpfg writes the letters bare (`T 0,1,0 E 0.2`) or with a colon, the
  // value apart or attached (`T: 0 1 0  A:90`).
  std::vector<Token> split;
  for (const Token& t : tokens_) {
    if (t.text.size() >= 2 && t.text[1] == ':' &&
        std::isalpha(static_cast<unsigned char>(t.text[0]))) {
      split.push_back({t.text.substr(0, 1), t.column});
      if (t.text.size() > 2) split.push_back({t.text.substr(2), t.column + 2});
    } else {
      split.push_back(t);
    }
  }
  tokens_ = std::move(split);
  lsys::Movement m;
  m.torque = torque;
  std::optional<Vec3> dir;
  double scale = 0;  // cpfg: the inverse length of T, times I, within [-1, 1]
  for (size_t k = 0; k < tokens_.size();) {
    const std::string& t = tokens_[k].text;
    const char c = t[0];
    if (t.size() != 1 || !std::strchr("TAESI", c)) {
      Error(tokens_[k].column, "expected T, A, E, S or I in '" + label_ + "', not '" + t + "'");
      return;
    }
    if (c == 'T') {
      dir = Vector(k + 1, "x,y,z");
      if (!dir) return;
      if (dir->norm() == 0) {
        Error(tokens_[k + 1].column,
              "the " + std::string(torque ? "torque" : "tropism") + " vector must not be 0,0,0");
        return;
      }
      scale = 1 / dir->norm();
      k += 4;
      continue;
    }
    auto x = Number(k + 1, "a number");
    if (!x) return;
    if (c == 'I') {
      // cpfg multiplies the inverse length of T read so far: before T, or
      // 0, it drops the line ("Tropism with 0 intensity!").
      scale = std::clamp(scale * *x, -1.0, 1.0);
      if (scale == 0) {
        Warn(tokens_[k].column, std::string(dir ? "an intensity of 0" : "'I' before 'T'") +
                                    ": cpfg drops this '" + label_ + "' line, and so does Sylva");
        return;
      }
    }
    if (c == 'A') {
      if (torque && *x != 0)
        Warn(tokens_[k].column, "'torque:' does not use an angle A (cpfg reads it and ignores it)");
      m.angle = *x;
    }
    if (c == 'E') m.elasticity = *x;
    if (c == 'S') m.elasticityStep = *x;
    k += 2;
  }
  if (!dir) {
    Error(labelColumn_, "'" + label_ + "' needs its vector: T x,y,z");
    return;
  }
  if (v_.movements.size() >= size_t(lsys::kMaxMovements)) {
    Warn(labelColumn_, "cpfg keeps at most " + std::to_string(lsys::kMaxMovements) +
                           " 'tropism:' and 'torque:' lines: this one is ignored, as in cpfg");
    return;
  }
  const Vec3 d = *dir * scale;
  m.x = d.x();
  m.y = d.y();
  m.z = d.z();
  v_.movements.push_back(m);
}

// `light: V: x y z  D: r g b ...` (cpfg's irisGL.c read_light): an OpenGL
// light, V a direction toward it, O a position; A, D, S colours, P a
// spot, T attenuation. Sylva takes the direction of the first light (O
// seen from the origin) for its key light; the rest warns.
void Reader::Light() {
  ++lights_;
  if (lights_ == 2) {
    Warn(labelColumn_,
         "a second 'light:': Sylva draws with one key light (the first 'light:'), its own fill "
         "and ambient: this one is not used");
  }
  std::optional<Vec3> toward;
  std::string ignored;
  for (size_t k = 0; k < tokens_.size();) {
    std::string t = tokens_[k].text;
    const int column = tokens_[k].column;
    // The letter, bare or with a colon and maybe the first value attached.
    const char c = t[0];
    if (!std::strchr("ADSOVPT", c) || (t.size() > 1 && t[1] != ':')) {
      Error(column, "expected A, D, S, O, V, P or T in 'light:', not '" + t + "'");
      return;
    }
    const size_t values = c == 'P' ? 5 : 3;
    std::vector<Token> rest;
    if (t.size() > 2) rest.push_back({t.substr(2), column + 2});
    size_t next = k + 1;
    while (rest.size() < values && next < tokens_.size()) rest.push_back(tokens_[next++]);
    std::vector<double> x;
    for (const Token& r : rest) {
      char* end = nullptr;
      const double v = std::strtod(r.text.c_str(), &end);
      if (end != r.text.c_str() + r.text.size() || !std::isfinite(v)) {
        Error(r.column,
              "expected a number after '" + std::string(1, c) + "', not '" + r.text + "'");
        return;
      }
      x.push_back(v);
    }
    if (x.size() < values) {
      Error(int(current_.size()) + 1, std::string("expected ") + std::to_string(values) +
                                          " numbers after '" + std::string(1, c) + "'");
      return;
    }
    if (c == 'V' || c == 'O') {
      const Vec3 d(x[0], x[1], x[2]);
      if (d.norm() == 0) {
        Error(column, "the light's direction or position must not be 0,0,0");
        return;
      }
      toward = d.normalized();
    } else if (ignored.find(c) == std::string::npos) {
      ignored += (ignored.empty() ? "" : ", ") + std::string(1, c);
    }
    k = next;
  }
  if (lights_ == 1) {
    if (toward) firstLight_ = toward;
    if (!ignored.empty())
      Warn(labelColumn_,
           "'light:': Sylva uses the light's direction (V, or O seen from the "
           "origin) for its key light; " +
               ignored + " (colours, spot, attenuation) ignored");
  }
}

// `surface: l leaf.s size [s-precision t-precision]` (cpfg's
// ReadViewData): the surface `~l` is the patches of leaf.s, its file beside
// the view file.
void Reader::Surface() {
  if (tokens_.size() < 2) {
    Error(int(current_.size()) + 1, "expected 'surface: LETTER FILE.s size [s t]'");
    return;
  }
  plant::CpfgSurfaceDef def;
  def.name = tokens_[0].text;
  if (def.name.size() != 1 || !std::isalnum(static_cast<unsigned char>(def.name[0]))) {
    Error(tokens_[0].column, "a cpfg surface is named by one letter, not '" + def.name + "'");
    return;
  }
  const fs::path file(tokens_[1].text);
  def.file = file.is_absolute()
                 ? file.string()
                 : (fs::path(path_).parent_path() / file).lexically_normal().string();
  if (tokens_.size() > 2) {
    auto size = Number(2, "a size");
    if (!size) return;
    if (*size <= 0) {
      Error(tokens_[2].column, "a surface's size must be positive");
      return;
    }
    def.size = *size;
  }
  for (size_t k = 3; k < 5 && k < tokens_.size(); ++k) {
    auto n = Number(k, "a precision (subdivisions of a patch side)");
    if (!n) return;
    if (*n < 1 || *n > 64 || *n != std::floor(*n)) {
      Error(tokens_[k].column, "a precision is a whole number from 1 to 64");
      return;
    }
    (k == 3 ? def.sPrecision : def.tPrecision) = int(*n);
  }
  ExtraValues(5);
  def.viewFile = path_;
  def.line = line_;
  // A surface file that is not there (objects are often copied without
  // them): the surface is not drawn, with a warning here; --strict fails.
  std::error_code ec;
  if (checkFiles_ && !fs::exists(def.file, ec)) {
    def.missing = true;
    Warn(tokens_[1].column,
         "surface '" + def.name + "' is not drawn: its file " + def.file + " does not exist");
  }
  for (auto& old : v_.surfaces) {
    if (old.name == def.name) {
      Warn(tokens_[0].column, "surface '" + def.name + "' is named again: this line wins");
      old = def;
      return;
    }
  }
  v_.surfaces.push_back(std::move(def));
}

// `contour: n FILE.con` (cpfg's ReadViewData, store_contour): @#(n)
// draws the generalized cylinders with the contour in FILE.con, beside the
// view file. With checkFiles the file is read here: a missing one is a
// warning (@#(n) draws round); a file named in another case than the
// folder's (a model made on a case-insensitive file system) is found, with
// a warning; one that cannot be read, or is malformed, an error.
void Reader::ContourLine() {
  if (tokens_.size() < 2) {
    Error(int(current_.size()) + 1, "expected 'contour: ID FILE.con'");
    return;
  }
  auto id = Number(0, "a contour id (the n of @#(n))");
  if (!id) return;
  if (*id != std::floor(*id) || *id < 0 || *id > 1e9) {
    Error(tokens_[0].column,
          "a contour id is a whole number from 0 (the n of @#(n)), not '" + tokens_[0].text + "'");
    return;
  }
  ExtraValues(2);
  if (!contourLine_) {
    contourLine_ = line_;
    contourColumn_ = labelColumn_;
    contourText_ = current_;
  }
  if (!checkFiles_) return;
  const Token& name = tokens_[1];
  fs::path file(name.text);
  if (!file.is_absolute()) file = (fs::path(path_).parent_path() / file).lexically_normal();
  std::error_code ec;
  // A link that leads nowhere (dangling, or a loop) is a name that exists:
  // the reader below says what is wrong with it.
  if (!fs::exists(file, ec) && !fs::is_symlink(file, ec)) {
    // The same name in another case, if the folder has exactly one.
    fs::path found;
    int matches = 0;
    auto lower = [](std::string s) {
      for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
      return s;
    };
    const std::string want = lower(file.filename().string());
    for (const auto& e : fs::directory_iterator(file.parent_path(), ec)) {
      if (lower(e.path().filename().string()) == want) {
        found = e.path();
        ++matches;
      }
    }
    if (matches != 1) {
      Warn(name.column, "contour " + tokens_[0].text + " is not drawn: its file " + file.string() +
                            " does not exist; @#(" + tokens_[0].text + ") draws round cylinders");
      return;
    }
    Warn(name.column, "contour file " + file.string() + " does not exist; read " + found.string() +
                          ", whose name differs in case (cpfg finds it only on a "
                          "case-insensitive file system)");
    file = found;
  }
  auto text = ReadFile(file.string(), mesh::kMaxContourFileBytes);
  if (!text) {
    Error(name.column,
          "contour file " + file.string() + " cannot be read: " + text.error().message);
    return;
  }
  auto contour = mesh::ParseContour(*text, file.string(), &v_.diagnostics);
  if (!contour) {
    v_.diagnostics.Add(contour.error());
    return;
  }
  if (v_.contours.byId.count(int(*id)))
    Warn(tokens_[0].column, "contour " + tokens_[0].text + " is defined again: this line wins");
  v_.contours.byId[int(*id)] = std::move(*contour);
}

Expected<std::string> ReadRegular(const std::string& path, size_t maxBytes) {
  auto text = ReadFile(path, maxBytes);
  if (!text) {
    Diagnostic d = text.error();
    d.loc.file = path;
    return d;
  }
  return text;
}

std::array<float, 3> Rgb(const unsigned char* p) {
  return {float(p[0]) / 255.0f, float(p[1]) / 255.0f, float(p[2]) / 255.0f};
}

Diagnostic FileError(const std::string& path, std::string message) {
  Diagnostic d;
  d.loc.file = path;
  d.message = std::move(message);
  return d;
}

bool IsFile(const fs::path& p) {
  std::error_code ec;
  return fs::exists(p, ec);  // a directory or device is reported by the reader
}

}  // namespace

ViewFile ParseViewFile(const std::string& text, const std::string& path, bool checkFiles) {
  ViewFile v;
  v.path = path;
  Reader r(v, path, checkFiles);
  for (const Line& line : Lines(text)) {
    r.Read(line);
    if (v.diagnostics.ErrorCount() >= kMaxViewErrors ||
        v.diagnostics.items.size() >= 4 * kMaxViewErrors) {
      Diagnostic d;
      d.loc.file = path;
      d.loc.line = line.number;
      d.message = "too many errors or warnings in the view file (is it one?); the rest is not read";
      v.diagnostics.Add(std::move(d));
      break;
    }
  }
  r.Finish();
  return v;
}

Expected<std::vector<std::array<float, 3>>> ParseColormap(const std::string& bytes,
                                                          const std::string& path,
                                                          DiagnosticList& warnings) {
  if (bytes.size() < kMapBytes) {
    return FileError(path,
                     "a colour map (.map) has 256 colours of 3 bytes (768 bytes); this one "
                     "has " +
                         std::to_string(bytes.size()) + " bytes (truncated?)");
  }
  if (bytes.size() > kMapBytes) {
    Diagnostic d = FileError(path, "a colour map (.map) has 768 bytes; the " +
                                       std::to_string(bytes.size() - kMapBytes) +
                                       " bytes after them are ignored");
    d.severity = Severity::kWarning;
    warnings.Add(std::move(d));
  }
  std::vector<std::array<float, 3>> colors(256);
  const auto* p = reinterpret_cast<const unsigned char*>(bytes.data());
  for (size_t i = 0; i < 256; ++i) colors[i] = Rgb(p + 3 * i);
  return colors;
}

Expected<std::vector<std::array<float, 3>>> ParseMaterials(const std::string& bytes,
                                                           const std::string& path) {
  if (bytes.empty() || bytes.size() % kMaterialBytes != 0) {
    return FileError(path,
                     "a material file (.mat) is a list of 15-byte records (an index, then "
                     "transparency, ambient, diffuse, emissive, specular, shininess); this "
                     "one has " +
                         std::to_string(bytes.size()) + " bytes (truncated?)");
  }
  // cpfg's default material is white; its default colour-map entry grey.
  std::vector<std::array<float, 3>> colors(256, {200 / 255.0f, 200 / 255.0f, 200 / 255.0f});
  const auto* p = reinterpret_cast<const unsigned char*>(bytes.data());
  for (size_t r = 0; r < bytes.size() / kMaterialBytes; ++r) {
    const unsigned char* m = p + r * kMaterialBytes;
    colors[m[0]] = Rgb(m + 5);  // index, transparency, ambient[3], then diffuse[3]
  }
  return colors;
}

// L-studio finds an object's files by their extension (one `.v`, one
// `.map` or `.mat` in the object's folder), whatever their names: the one
// regular file of `dir` ending in `ext`; empty when there is none, and when
// there are several (their names in *several). At most 4096 entries are
// looked at (a folder that large is not an object's).
static fs::path OnlyFileWithExtension(const fs::path& dir, const std::string& ext,
                                      std::vector<std::string>* several = nullptr) {
  std::error_code ec;
  fs::directory_iterator it(dir.empty() ? fs::path(".") : dir, ec), end;
  std::vector<fs::path> found;
  for (int n = 0; !ec && it != end && n < 4096; it.increment(ec), ++n) {
    const fs::path& p = it->path();
    if (p.extension() == ext && IsFile(p)) found.push_back(p);
  }
  if (found.size() == 1) return found[0];
  if (several) {
    for (const fs::path& p : found) several->push_back(p.filename().string());
    std::sort(several->begin(), several->end());
  }
  return {};
}

std::shared_ptr<const ViewFile> LoadViewFiles(const std::string& grammarPath,
                                              const std::string& explicitView) {
  auto v = std::make_shared<ViewFile>();
  fs::path viewPath;
  bool lstudio = false;  // no NAME.v, no `specifications`: L-studio's rules
  // Colour files named by the object's cpfg command (`-M x.mat`, `-m x.map`).
  std::vector<std::pair<fs::path, bool>> named;  // path, is a material file
  if (!explicitView.empty()) {
    viewPath = explicitView;
  } else if (!grammarPath.empty()) {
    fs::path beside = fs::path(grammarPath).replace_extension(".v");
    if (IsFile(beside)) {
      viewPath = beside;
    } else {
      // No NAME.v: the files the cpfg command of vlab's `specifications` names.
      auto command = CpfgCommandFor(grammarPath);
      if (!command) {
        Diagnostic d = command.error();
        d.severity = Severity::kWarning;
        d.message += "; its files are not used";
        v->diagnostics.Add(std::move(d));
      } else if (command->has_value()) {
        const CpfgCommand& c = **command;
        const fs::path dir = fs::path(grammarPath).parent_path();
        auto warn = [&](std::string message) {
          Diagnostic d;
          d.severity = Severity::kWarning;
          d.loc = c.loc;
          d.message = std::move(message);
          v->diagnostics.Add(std::move(d));
        };
        if (!c.view.empty()) {
          if (IsFile(dir / c.view)) {
            viewPath = dir / c.view;
          } else {
            warn("the cpfg command names the view file '" + c.view +
                 "', which is not in the object's folder: drawn without a view file");
          }
        }
        auto add = [&](const std::string& f, bool material) {
          if (f.empty()) return;
          if (IsFile(dir / f)) {
            named.emplace_back(dir / f, material);
          } else {
            warn("the cpfg command names the " +
                 std::string(material ? "material file '" : "colour map '") + f +
                 "', which is not in the object's folder");
          }
        };
        add(c.materialWins ? c.material : c.colormap, c.materialWins);
        add(c.materialWins ? c.colormap : c.material, !c.materialWins);
        for (const std::string& o : c.unknownOptions)
          warn("the cpfg command's option '" + o + "' is not one cpfg has: ignored");
      } else {
        // No `specifications` either: an L-studio object, one folder with
        // one `.l`, whose view file is the folder's one `.v` (view.v beside
        // lsystem.l). A folder of several grammars is not an object: each
        // needs its own NAME.v (grammars/cpfg's sub_lsystem.l was drawn
        // with flower.v's camera).
        const fs::path dir = fs::path(grammarPath).parent_path();
        std::vector<std::string> grammars;
        OnlyFileWithExtension(dir, ".l", &grammars);
        std::vector<std::string> several;
        if (grammars.empty()) viewPath = OnlyFileWithExtension(dir, ".v", &several);
        if (!several.empty()) {
          std::string names;
          for (const std::string& n : several) names += (names.empty() ? "" : ", ") + n;
          Diagnostic d;
          d.severity = Severity::kWarning;
          d.loc = SourceLoc{grammarPath, 0, 0};
          d.message = "no " + beside.filename().string() + " beside the grammar and " +
                      std::to_string(several.size()) + " view files in its folder (" + names +
                      "): none is used; name one with --view";
          v->diagnostics.Add(std::move(d));
        }
        lstudio = grammars.empty();
      }
    }
  }
  if (!viewPath.empty()) {
    auto text = ReadRegular(viewPath.string(), kMaxViewBytes);
    if (!text) {
      Diagnostic d = text.error();
      d.message = "view file: " + d.message;
      v->diagnostics.Add(std::move(d));
      return v;
    }
    DiagnosticList before = std::move(v->diagnostics);
    *v = ParseViewFile(*text, viewPath.string(), /*checkFiles=*/true);
    before.items.insert(before.items.end(), v->diagnostics.items.begin(),
                        v->diagnostics.items.end());
    v->diagnostics.items = std::move(before.items);
    // The background scenes the view file names (app/cpfg_background.h),
    // their vertices within kMaxBackgroundVertices in all (the same file
    // named 200 times was read 200 times and exhausted memory).
    size_t backgroundVertices = 0;
    for (const ViewFile::NamedFile& f : v->backgroundFiles) {
      // A scene file that is not there (objects are copied without their
      // files; vlab's soil3d names `from_env.dat`, which its environment
      // program writes while cpfg runs) is not drawn, with a warning, as a
      // missing surface or contour; --strict fails. One that cannot be read
      // is an error.
      std::error_code ec;
      if (!fs::exists(f.file, ec) && !fs::is_symlink(f.file, ec)) {
        Diagnostic d =
            MakeError(SourceLoc{viewPath.string(), f.line, f.column},
                      "background scene " + f.file + " is not drawn: the file does not exist");
        d.severity = Severity::kWarning;
        v->diagnostics.Add(std::move(d));
        continue;
      }
      auto text = ReadRegular(f.file, kMaxBackgroundBytes);
      if (!text) {
        Diagnostic d = text.error();
        d.message = "background scene: " + d.message;
        d.loc = SourceLoc{viewPath.string(), f.line, f.column};
        v->diagnostics.Add(std::move(d));
        continue;
      }
      auto scene = ParseBackgroundScene(*text, f.file, v->diagnostics);
      if (!scene) {
        v->diagnostics.Add(scene.error());
        continue;
      }
      size_t vertices = 0;
      for (const mesh::Polygon& p : scene->polygons) vertices += p.vertices.size();
      if (vertices > kMaxBackgroundVertices - backgroundVertices) {
        v->diagnostics.Add(MakeError(SourceLoc{viewPath.string(), f.line, f.column},
                                     "background scene: the scenes have more than " +
                                         std::to_string(kMaxBackgroundVertices) +
                                         " vertices in all with this one"));
        break;
      }
      backgroundVertices += vertices;
      v->backgrounds.push_back(std::make_shared<const BackgroundScene>(std::move(*scene)));
    }
  }
  // cpfg's animation file beside the grammar (only its overlaid frames
  // change a still picture).
  if (!grammarPath.empty()) {
    const fs::path a = fs::path(grammarPath).replace_extension(".a");
    if (IsFile(a)) {
      auto text = ReadRegular(a.string(), kMaxViewBytes);
      if (!text) {
        v->diagnostics.Add(text.error());
        return v;
      }
      ParseAnimationFile(*text, a.string(), *v);
    }
  }
  // Colours: the command's files, then NAME.mat and NAME.map beside the
  // grammar, then beside the view file.
  std::vector<std::pair<fs::path, bool>> candidates = named;
  std::vector<fs::path> stems;
  if (!grammarPath.empty()) stems.push_back(fs::path(grammarPath));
  if (!viewPath.empty()) stems.push_back(viewPath);
  for (const fs::path& stem : stems) {
    candidates.emplace_back(fs::path(stem).replace_extension(".mat"), true);
    candidates.emplace_back(fs::path(stem).replace_extension(".map"), false);
  }
  if (lstudio) {  // and then the folder's one material file or colour map
    const fs::path dir = fs::path(grammarPath).parent_path();
    if (fs::path m = OnlyFileWithExtension(dir, ".mat"); !m.empty())
      candidates.emplace_back(m, true);
    if (fs::path m = OnlyFileWithExtension(dir, ".map"); !m.empty())
      candidates.emplace_back(m, false);
  }
  for (const auto& [candidate, material] : candidates) {
    if (!IsFile(candidate)) continue;
    auto bytes = ReadRegular(candidate.string(), kMaxColorBytes);
    if (!bytes) {
      v->diagnostics.Add(bytes.error());
      return v;
    }
    auto colors = material ? ParseMaterials(*bytes, candidate.string())
                           : ParseColormap(*bytes, candidate.string(), v->diagnostics);
    if (!colors) {
      v->diagnostics.Add(colors.error());
      return v;
    }
    v->colorsPath = candidate.string();
    v->palette = std::move(*colors);
    return v;
  }
  if (v->path.empty() && v->colorsPath.empty() && v->animationPath.empty() &&
      v->diagnostics.items.empty())
    return nullptr;
  return v;
}

void ParseAnimationFile(const std::string& text, const std::string& path, ViewFile& view) {
  view.animationPath = path;
  // Only an overlay (clear between frames: off) changes a still picture:
  // the frame numbers are read, and checked, for it alone.
  struct Value {
    std::string text;
    int line = 0, column = 0;
  };
  std::optional<Value> clear, doubleBuffer, first, last, step;
  for (const Line& line : Lines(text)) {
    const std::string& s = line.text;
    const size_t colon = s.find(':');
    if (colon == std::string::npos) continue;
    std::string label;
    for (size_t k = 0; k < colon; ++k) {
      const char c = s[k];
      if (c == ' ' || c == '\t') {
        if (!label.empty() && label.back() != ' ') label += ' ';
      } else {
        label += c;
      }
    }
    while (!label.empty() && label.back() == ' ') label.pop_back();
    const size_t v0 = s.find_first_not_of(" \t", colon + 1);
    Value value;
    value.line = line.number;
    value.column = v0 == std::string::npos ? int(s.size()) + 1 : int(v0) + 1;
    if (v0 != std::string::npos) value.text = s.substr(v0, s.find_first_of(" \t", v0) - v0);
    if (label == "clear between frames") clear = value;
    if (label == "double buffer") doubleBuffer = value;
    if (label == "first frame") first = value;
    if (label == "last frame") last = value;
    if (label == "step") step = value;
  }
  // With double buffering each of the two buffers keeps every second
  // frame: an artefact of the swap (vlab's growing sunflower and gaillardia
  // ask for it and show the last frame), not a picture built of frames.
  if (!clear || clear->text.rfind("off", 0) != 0) return;
  if (!doubleBuffer || doubleBuffer->text.rfind("off", 0) != 0) return;
  auto number = [&](const std::optional<Value>& v, const char* label, int lo, int fallback,
                    int* out) {
    if (!v) {
      *out = fallback;
      return true;
    }
    char* end = nullptr;
    const long x = std::strtol(v->text.c_str(), &end, 10);
    if (v->text.empty() || *end != '\0' || x < lo || x > lsys::kMaxAnimationSteps) {
      Diagnostic d;
      d.loc.file = path;
      d.loc.line = v->line;
      d.loc.column = v->column;
      d.message = std::string("'") + label + ":' expects a whole number from " +
                  std::to_string(lo) + " to " + std::to_string(lsys::kMaxAnimationSteps) +
                  ", not '" + v->text + "'";
      view.diagnostics.Add(std::move(d));
      return false;
    }
    *out = int(x);
    return true;
  };
  plant::FrameRange frames;
  // cpfg's `last frame: -1`: up to the derivation length.
  if (number(first, "first frame", 0, 0, &frames.first) &&
      number(last, "last frame", -1, -1, &frames.last) && number(step, "step", 1, 1, &frames.step))
    view.overlay = frames;
}

void ApplyViewFile(const ViewFile& v, lsys::Grammar& g) {
  if (v.angle) g.angle = *v.angle;
  if (v.width) g.width = *v.width;
  if (v.widthIncrement) {
    // cpfg: ! and # subtract and add the increment; an increment of 0
    // leaves the width alone (Sylva's factor 1).
    g.widthIncrement = std::max(*v.widthIncrement, 0.0);
    if (*v.widthIncrement <= 0) g.widthFactor = 1;
  }
  if (v.initialColor) g.initialColor = *v.initialColor;
  if (v.colorIncrement) g.colorIncrement = *v.colorIncrement;
  if (v.tropism || v.elasticity) {
    // cpfg's default `tropism direction:` is up (interpret.c InitializeParameters).
    lsys::Tropism t = g.tropism.value_or(lsys::Tropism{0, 1, 0, 0});
    if (v.tropism) {
      t.x = v.tropism->x();
      t.y = v.tropism->y();
      t.z = v.tropism->z();
    }
    if (v.elasticity) t.susceptibility = *v.elasticity;
    g.tropism = t;
  }
  if (v.elasticityIncrement) g.elasticityIncrement = *v.elasticityIncrement;
  if (!v.movements.empty()) g.movements = v.movements;
  if (!v.palette.empty()) g.palette = v.palette;
}

void AttachViewFile(std::shared_ptr<const ViewFile> view, plant::PlantSpec& spec) {
  if (!view) return;
  spec.draw.widthInPixels = view->widthInPixels;
  spec.draw.cylinderStyle = view->cylinderStyle && !view->widthInPixels;
  if (view->cylinderStyle && !view->widthInPixels)
    spec.draw.contours = std::make_shared<const turtle::CylinderContours>(view->contours);
  spec.cpfgSurfaces = view->surfaces;
  spec.cpfgFunctions = view->functions;
  spec.cpfgCurves = view->curves;
  if (!view->backgrounds.empty()) {
    spec.amendGeometry = [view](mesh::PlantGeometry& geometry, mesh::Palette& palette) {
      for (const auto& b : view->backgrounds) AddBackgroundScene(*b, geometry, palette);
    };
  }
  spec.cpfgViewFile = view->path;
  spec.amendGrammar = [view](lsys::Grammar& g, DiagnosticList& diagnostics) {
    for (const Diagnostic& d : view->diagnostics.items) diagnostics.Add(d);
    if (!view->diagnostics.HasErrors()) ApplyViewFile(*view, g);
  };
}

std::optional<std::array<double, 2>> ViewDirection(const ViewFile& v) {
  if (!v.viewpoint && !v.target) return std::nullopt;
  // cpfg's defaults: the eye at (0,0,1) looking at the origin.
  const Vec3 eye = v.viewpoint.value_or(Vec3(0, 0, 1));
  const Vec3 target = v.target.value_or(Vec3(0, 0, 0));
  const Vec3 d = eye - target;
  const double n = d.norm();
  if (!(n > 0) || !std::isfinite(n)) return std::nullopt;
  const Vec3 u = d / n;
  const double elevation =
      std::clamp(std::asin(std::clamp(u.y(), -1.0, 1.0)) * kRadToDeg, -89.0, 89.0);
  const double azimuth = std::atan2(u.x(), u.z()) * kRadToDeg;
  return std::array<double, 2>{azimuth, elevation};
}

}  // namespace sylva::app
