#include "app/view_file.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <set>
#include <string_view>

#include "core/atomic_file.h"

namespace sylva::app {
namespace {

namespace fs = std::filesystem;

// A view file is a few hundred bytes; colour files are 768 bytes and at most
// a few kilobytes of materials.
constexpr size_t kMaxViewBytes = size_t(1) << 20;
constexpr size_t kMaxColorBytes = size_t(64) << 10;
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
    "lighting and shading: Sylva's renderer lights every plant with its own key and fill lights";
constexpr std::string_view kSurfaces =
    "Sylva reads cpfg's .s surfaces from 'surface:', not line or triangle surfaces "
    "(docs/cpfg.md)";
constexpr std::string_view kNotActed = "Sylva does not act on it";

constexpr Ignored kIgnored[] = {
    {"front distance:", "clipping planes: Sylva frames the plant"},
    {"back distance:", "clipping planes: Sylva frames the plant"},
    {"shade mode:", kLighting},
    {"light direction:", kLighting},
    {"diffuse reflection:", kLighting},
    {"surface ambient:", kLighting},
    {"surface diffuse:", kLighting},
    {"ambient light:", kLighting},
    {"light:", kLighting},
    {"render mode:", kLighting},
    {"shadow map:", kLighting},
    {"line:", kSurfaces},
    {"tsurface:", kSurfaces},
    {"box:", "a fixed bounding box: Sylva frames the plant"},
    {"background color:", kNotActed},
    {"font:", kNotActed},
    {"winfont:", kNotActed},
    {"polygonization level:", "the detail of tubes is --sides or --lod-eps"},
    {"contour sides:", "the detail of tubes is --sides or --lod-eps"},
    {"contour:", "generalized cylinder contours are circles in Sylva"},
    {"twist of cylinders:", "Sylva's tubes follow rotation-minimizing frames"},
    {"blob:", kNotActed},
    {"torque:", "torque tropism is not implemented"},
    {"texture:", "textures are not implemented"},
    {"line style:", "Sylva draws 2D figures as lines and 3D plants as tubes"},
    {"tapered lines:", "Sylva's tubes taper to the width of the next segment"},
    {"viewing angle:", "Sylva's perspective uses a 35 degree field of view"},
    {"background scene:", kNotActed},
    {"interpretation step:", kNotActed},
    {"interpretation past %:", kNotActed},
    {"rayshade objects:", kNotActed},
    {"rayshade scale:", kNotActed},
    {"initial scale:", "@D scaling is not implemented"},
    {"scale multiplier:", "@D scaling is not implemented"},
    {"environment display:", kNotActed},
    {"function set:", "cpfg function sets (.fset) are not read; name .func files with 'function:'"},
    {"curve:", "cpfg curve files are not read"},
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
  Reader(ViewFile& v, const std::string& path) : v_(v), path_(path) {}

  void Read(const app::Line& line);

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
  void Tropism();
  void Surface();

  ViewFile& v_;
  std::string path_;
  std::string current_;  // the line as read (comments blanked)
  int line_ = 0;
  std::string label_;
  int labelColumn_ = 1;
  std::vector<Token> tokens_;
  std::set<std::string> warned_;
  bool tropismSeen_ = false;
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
      if (*x == 0)
        Error(tokens_[0].column, "'angle factor:' must not be 0");
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
    // `pixels`, `polygons`, `cylinder`: how cpfg draws lines; Sylva draws
    // tubes (lines for 2D figures) of this width in world units.
    ExtraValues(
        tokens_.size() > 1 && std::isalpha(static_cast<unsigned char>(tokens_[1].text[0])) ? 2 : 1);
  } else if (L == "line width increment:") {
    if (auto x = Number(0, "a width")) v_.widthIncrement = *x;
    ExtraValues(1);
  } else if (L == "viewpoint:" || L == "view reference point:") {
    if (auto p = Vector(0, "x,y,z")) (L == "viewpoint:" ? v_.viewpoint : v_.target) = *p;
    ExtraValues(3);
  } else if (L == "scale factor:") {
    if (auto x = Number(0, "a scale")) {
      if (*x > 0)
        v_.scale = *x;
      else if (*x < 0)
        Error(tokens_[0].column, "'scale factor:' must be positive");
      // 0: cpfg reads it as 1
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
    if (tokens_.empty() || tokens_[0].text.rfind("perspective", 0) != 0)
      NotActed("Sylva draws 3D plants in perspective (2D figures in parallel projection)");
  } else if (L == "tropism direction:") {
    if (auto p = Vector(0, "x,y,z")) {
      // 0,0,0: no direction, so no bending (as in cpfg, whose tropism is
      // the cross product with it).
      if (p->norm() > 0) v_.tropism = p->normalized();
    }
    ExtraValues(3);
  } else if (L == "initial elasticity:") {
    if (auto x = Number(0, "an elasticity")) v_.elasticity = *x;
    ExtraValues(1);
  } else if (L == "elasticity increment:") {
    if (auto x = Number(0, "an elasticity")) v_.elasticityIncrement = *x;
    ExtraValues(1);
  } else if (L == "tropism:") {
    Tropism();
  } else if (L == "surface:") {
    Surface();
  } else if (L == "function:") {
    // `function: FILE.func [samples]`: func(1, x) is the first such line.
    // cpfg tabulates the curve at `samples` points; Sylva evaluates it
    // (docs/cpfg.md), so the number is not needed.
    if (tokens_.empty()) {
      Error(int(current_.size()) + 1, "expected 'function: FILE.func [samples]'");
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
    v_.functions.push_back(std::move(f));
    if (tokens_.size() > 1) Number(1, "a number of samples");
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

// `tropism: T x,y,z A angle E elasticity S step I intensity` (cpfg's
// movements.c): Sylva has one tropism, towards T (A 0).
void Reader::Tropism() {
  if (tropismSeen_) {
    Warn(labelColumn_, "a second 'tropism:': Sylva has one tropism; this one is ignored");
    return;
  }
  tropismSeen_ = true;
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
  std::optional<Vec3> dir;
  double elasticity = 0, intensity = 1;
  for (size_t k = 0; k < tokens_.size();) {
    const std::string& t = tokens_[k].text;
    const char c = t[0];
    if (t.size() != 1 || !std::strchr("TAESI", c)) {
      Error(tokens_[k].column, "expected T, A, E, S or I in 'tropism:', not '" + t + "'");
      return;
    }
    if (c == 'T') {
      dir = Vector(k + 1, "x,y,z");
      if (!dir) return;
      if (dir->norm() == 0) {
        Error(tokens_[k + 1].column, "the tropism vector must not be 0,0,0");
        return;
      }
      k += 4;
      continue;
    }
    auto x = Number(k + 1, "a number");
    if (!x) return;
    if (c == 'A' && *x != 0)
      Warn(
          tokens_[k + 1].column,
          "a tropism at an angle A to its vector (plagiotropism) is not implemented: drawn as A 0");
    if (c == 'E') elasticity = *x;
    if (c == 'S') v_.elasticityIncrement = *x;
    if (c == 'I') intensity = std::clamp(*x, -1.0, 1.0);
    k += 2;
  }
  if (!dir) {
    Error(labelColumn_, "'tropism:' needs its vector: T x,y,z");
    return;
  }
  v_.tropism = dir->normalized();
  v_.elasticity = elasticity * intensity;
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
  for (auto& old : v_.surfaces) {
    if (old.name == def.name) {
      Warn(tokens_[0].column, "surface '" + def.name + "' is named again: this line wins");
      old = def;
      return;
    }
  }
  v_.surfaces.push_back(std::move(def));
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

ViewFile ParseViewFile(const std::string& text, const std::string& path) {
  ViewFile v;
  v.path = path;
  Reader r(v, path);
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

std::shared_ptr<const ViewFile> LoadViewFiles(const std::string& grammarPath,
                                              const std::string& explicitView) {
  auto v = std::make_shared<ViewFile>();
  fs::path viewPath;
  if (!explicitView.empty()) {
    viewPath = explicitView;
  } else if (!grammarPath.empty()) {
    fs::path beside = fs::path(grammarPath).replace_extension(".v");
    if (IsFile(beside)) viewPath = beside;
  }
  if (!viewPath.empty()) {
    auto text = ReadRegular(viewPath.string(), kMaxViewBytes);
    if (!text) {
      Diagnostic d = text.error();
      d.message = "view file: " + d.message;
      v->diagnostics.Add(std::move(d));
      return v;
    }
    *v = ParseViewFile(*text, viewPath.string());
  }
  // Colours: NAME.mat, then NAME.map, beside the grammar, then beside the view file.
  std::vector<fs::path> stems;
  if (!grammarPath.empty()) stems.push_back(fs::path(grammarPath));
  if (!viewPath.empty()) stems.push_back(viewPath);
  for (const fs::path& stem : stems) {
    for (const char* ext : {".mat", ".map"}) {
      fs::path candidate = fs::path(stem).replace_extension(ext);
      if (!IsFile(candidate)) continue;
      auto bytes = ReadRegular(candidate.string(), kMaxColorBytes);
      if (!bytes) {
        v->diagnostics.Add(bytes.error());
        return v;
      }
      auto colors = std::string(ext) == ".mat"
                        ? ParseMaterials(*bytes, candidate.string())
                        : ParseColormap(*bytes, candidate.string(), v->diagnostics);
      if (!colors) {
        v->diagnostics.Add(colors.error());
        return v;
      }
      v->colorsPath = candidate.string();
      v->palette = std::move(*colors);
      return v;
    }
  }
  if (v->path.empty() && v->colorsPath.empty()) return nullptr;
  return v;
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
    lsys::Tropism t = g.tropism.value_or(lsys::Tropism{});
    if (v.tropism) {
      t.x = v.tropism->x();
      t.y = v.tropism->y();
      t.z = v.tropism->z();
    }
    if (v.elasticity) t.susceptibility = *v.elasticity;
    g.tropism = t;
  }
  if (v.elasticityIncrement) g.elasticityIncrement = *v.elasticityIncrement;
  if (!v.palette.empty()) g.palette = v.palette;
}

void AttachViewFile(std::shared_ptr<const ViewFile> view, plant::PlantSpec& spec) {
  if (!view) return;
  spec.cpfgSurfaces = view->surfaces;
  spec.cpfgFunctions = view->functions;
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
