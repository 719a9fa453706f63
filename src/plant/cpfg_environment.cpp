#include "plant/cpfg_environment.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "core/atomic_file.h"
#include "plant/chiba_environment.h"
#include "plant/clover_environment.h"
#include "plant/density_environment.h"

namespace sylva::plant {
namespace {

using Reader = std::function<std::optional<std::string>(const std::string&)>;

constexpr size_t kMaxEnvFileBytes = size_t(1) << 20;

std::optional<std::string> ReadText(const std::string& path, const Reader& readFile) {
  if (readFile) return readFile(path);
  auto text = ReadFile(path, kMaxEnvFileBytes);
  if (!text) return std::nullopt;
  return std::move(*text);
}

std::string ParentOf(const std::string& path) {
  const size_t slash = path.rfind('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

std::string BaseOf(const std::string& path) {
  const size_t slash = path.rfind('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

std::string Join(const std::string& dir, const std::string& file) {
  if (!file.empty() && file[0] == '/') return file;
  if (dir.empty() || dir == ".") return file;
  return dir.back() == '/' ? dir + file : dir + "/" + file;
}

struct Line {
  int number = 0;
  std::string text;
};

std::vector<Line> LinesOf(const std::string& text) {
  std::vector<Line> out;
  size_t start = 0;
  int n = 0;
  while (start <= text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(start, end - start);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    out.push_back(Line{++n, std::move(line)});
    if (end == text.size()) break;
    start = end + 1;
  }
  return out;
}

// Words separated by any of `seps`, each with its 0-based column.
std::vector<std::pair<std::string, int>> Split(const std::string& s, const char* seps) {
  std::vector<std::pair<std::string, int>> out;
  size_t i = 0;
  const std::string delims(seps);
  while (i < s.size()) {
    while (i < s.size() && delims.find(s[i]) != std::string::npos) ++i;
    if (i >= s.size()) break;
    size_t j = i;
    while (j < s.size() && delims.find(s[j]) == std::string::npos) ++j;
    out.emplace_back(s.substr(i, j - i), int(i));
    i = j;
  }
  return out;
}

std::string Trim(const std::string& s) {
  size_t a = s.find_first_not_of(" \t"), b = s.find_last_not_of(" \t");
  return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
}

// A "keyword: value" line as cpfg and its programs read it (strtok on tab
// and colon): the keyword, trimmed, and what follows the delimiters after it.
struct Directive {
  std::string key;
  std::string value;
  int valueColumn = 0;  // 0-based
};

std::optional<Directive> DirectiveOf(const std::string& line) {
  size_t i = line.find_first_not_of("\t:");
  if (i == std::string::npos) return std::nullopt;
  size_t j = line.find_first_of("\t:", i);
  Directive d;
  d.key = Trim(line.substr(i, j == std::string::npos ? std::string::npos : j - i));
  if (d.key.empty() || d.key[0] == '#') return std::nullopt;
  if (j != std::string::npos) {
    size_t k = line.find_first_not_of("\t:", j);
    if (k != std::string::npos) {
      d.value = line.substr(k);
      d.valueColumn = int(k);
    }
  }
  return d;
}

Diagnostic Warning(const std::string& file, const Line& line, int column0, int length,
                   std::string message) {
  Diagnostic d = MakeError(SourceLoc{file, line.number, column0 + 1}, std::move(message),
                           std::max(1, length), line.text);
  d.severity = Severity::kWarning;
  return d;
}

// A printf conversion of cpfg's `turtle position:` format.
struct Conversion {
  char kind = 'f';    // f, e or g (their upper-case forms print the same digits)
  int precision = 6;  // printf's default
};

// The conversions of a format, at most 3 as cpfg counts them; nullopt when
// one is not a floating-point conversion Sylva can reproduce.
std::optional<std::vector<Conversion>> ConversionsOf(const std::string& format) {
  std::vector<Conversion> out;
  for (size_t i = 0; i < format.size(); ++i) {
    if (format[i] != '%') continue;
    if (i + 1 < format.size() && format[i + 1] == '%') {
      ++i;
      continue;
    }
    size_t j = i + 1;
    while (j < format.size() && std::string("-+ #0").find(format[j]) != std::string::npos) ++j;
    while (j < format.size() && std::isdigit(static_cast<unsigned char>(format[j]))) ++j;
    Conversion c;
    if (j < format.size() && format[j] == '.') {
      ++j;
      int p = 0;
      while (j < format.size() && std::isdigit(static_cast<unsigned char>(format[j])))
        p = std::min(40, p * 10 + (format[j++] - '0'));
      c.precision = p;
    }
    if (j < format.size() && format[j] == 'l') ++j;
    if (j >= format.size()) return std::nullopt;
    const char k = char(std::tolower(static_cast<unsigned char>(format[j])));
    if (k != 'f' && k != 'e' && k != 'g') return std::nullopt;
    c.kind = k;
    if (out.size() < 3) out.push_back(c);
    i = j;
  }
  return out;
}

// x as the program reads it back after `c` printed it.
double ThroughFormat(double x, const Conversion& c) {
  char buf[512];
  const char* fmt = c.kind == 'f' ? "%.*f" : c.kind == 'e' ? "%.*e" : "%.*g";
  std::snprintf(buf, sizeof buf, fmt, c.precision, x);
  return std::strtod(buf, nullptr);
}

enum class Program { kHonda81, kEcosystem, kClover, kChiba };

// Sends each query's position through the .e file's format (the first
// coordinates; the rest are not sent) before the program reads it.
class FormattedPositions final : public Environment {
 public:
  FormattedPositions(std::unique_ptr<Environment> program, std::vector<Conversion> format)
      : program_(std::move(program)), format_(std::move(format)) {}
  Status Answer(std::span<EnvQuery> queries) override {
    std::vector<EnvQuery> sent(queries.begin(), queries.end());
    for (EnvQuery& q : sent) {
      for (size_t c = 0; c < 3; ++c)
        q.position[int(c)] = c < format_.size() ? ThroughFormat(q.position[int(c)], format_[c]) : 0;
    }
    return program_->Answer(sent);
  }

 private:
  std::unique_ptr<Environment> program_;
  std::vector<Conversion> format_;
};

// honda81 and ecosystem: both need x, y and z; with fewer coordinates sent
// they store no query and answer nothing (as in cpfg).
class DensityProgram final : public Environment {
 public:
  DensityProgram(Program program, int coordinates, Honda81Def honda, EcosystemDef eco)
      : program_(program), coordinates_(coordinates), honda_(honda), eco_(eco) {}

  Status Answer(std::span<EnvQuery> queries) override {
    if (coordinates_ < 3) return {};
    std::vector<DensityQuery> in;
    std::vector<size_t> which;
    in.reserve(queries.size());
    // ecosystem with `vigor: on` needs 2 parameters, the others 1.
    const size_t need = program_ == Program::kEcosystem && eco_.vigor ? 2 : 1;
    for (size_t i = 0; i < queries.size(); ++i) {
      const EnvQuery& q = queries[i];
      if (q.params.size() < need) continue;
      in.push_back(DensityQuery{q.position, {q.params.data(), q.params.size()}});
      which.push_back(i);
    }
    const std::vector<double> answers =
        program_ == Program::kHonda81 ? Honda81Answers(honda_, in) : EcosystemAnswers(eco_, in);
    for (size_t k = 0; k < which.size(); ++k) queries[which[k]].params[0] = answers[k];
    return {};
  }

 private:
  Program program_;
  int coordinates_;
  Honda81Def honda_;
  EcosystemDef eco_;
};

// The spec file of honda81 or ecosystem: `keyword: value` lines.
void ReadDensitySpec(Program program, const std::string& path, const std::string& text,
                     Honda81Def& honda, EcosystemDef& eco, DiagnosticList& diags) {
  const char* name = program == Program::kHonda81 ? "honda81" : "ecosystem";
  for (const Line& line : LinesOf(text)) {
    auto d = DirectiveOf(line.text);
    if (!d) continue;
    const auto words = Split(d->value, "x,; \t:");
    const std::string first = words.empty() ? std::string() : words[0].first;
    const int col = words.empty() ? d->valueColumn : d->valueColumn + words[0].second;
    const bool on = first == "on" || (program == Program::kEcosystem && first == "yes");
    if (d->key == "verbose") continue;  // the program's log on stderr: nothing to draw
    if (d->key == "3d case") {
      (program == Program::kHonda81 ? honda.is3d : eco.is3d) = on;
      continue;
    }
    if (program == Program::kHonda81 && d->key == "radius") {
      char* end = nullptr;
      const double r = std::strtod(first.c_str(), &end);
      if (first.empty() || end == first.c_str() || !std::isfinite(r)) {
        diags.Add(Warning(path, line, col, int(first.size()) + 1,
                          "honda81's 'radius:' needs a number; the radius stays 0"));
        continue;
      }
      honda.radius = r;
      continue;
    }
    if (program == Program::kEcosystem && d->key == "vigor") {
      eco.vigor = first == "on";
      continue;
    }
    if (program == Program::kEcosystem && d->key == "grid size") continue;  // speed only
    diags.Add(Warning(path, line, line.text.find_first_not_of("\t:"), int(d->key.size()),
                      std::string("unknown directive '") + d->key + "' in " + name +
                          "'s specification file: ignored, as " + name + " does"));
  }
}

// clover's spec file. False when the grid is too large to hold (then a
// warning says so and ?E is not answered).
bool ReadCloverSpec(const std::string& path, const std::string& text, const Reader& readFile,
                    CloverDef& def, std::optional<CloverImage>& image, DiagnosticList& diags) {
  std::optional<std::pair<Line, int>> imageAt;
  std::string imageName;
  for (const Line& line : LinesOf(text)) {
    auto d = DirectiveOf(line.text);
    if (!d) continue;
    const int keyCol = int(line.text.find_first_not_of("\t:"));
    const auto pair = Split(d->value, "x,; \t:");
    const auto words = Split(d->value, ",; \t:");
    const std::string first = words.empty() ? std::string() : words[0].first;
    auto two = [&](auto& out, auto convert) {
      if (pair.size() < 2) {
        diags.Add(Warning(path, line, keyCol, int(d->key.size()),
                          "clover's '" + d->key + ":' takes two numbers; ignored"));
        return;
      }
      out[0] = convert(pair[0].first);
      out[1] = convert(pair[1].first);
    };
    if (d->key == "grid size") {
      two(def.size, [](const std::string& w) {
        // Out of int's range (or NaN) reads 0: the size check below warns.
        const double v = std::atof(w.c_str());
        return v >= 1 && v <= double(1 << 30) ? int(v) : 0;
      });
    } else if (d->key == "grid position") {
      two(def.pos, [](const std::string& w) { return float(std::atof(w.c_str())); });
    } else if (d->key == "grid range") {
      two(def.range, [](const std::string& w) { return float(std::atof(w.c_str())); });
    } else if (d->key == "transmittance") {
      def.transmittance = float(std::atof(first.c_str()));
      if (def.transmittance == 0) def.transmittance = 0.0001f;  // as clover does
    } else if (d->key == "input image") {
      imageName = first;
      imageAt = std::make_pair(line, d->valueColumn + (words.empty() ? 0 : words[0].second));
    } else if (d->key == "remove old leaves") {
      def.removeOldLeaves = first == "on" || first == "yes";
    } else if (d->key == "z is up") {
      if (first == "no" || first == "off") def.zIsUp = false;
    } else if (d->key != "verbose") {
      diags.Add(Warning(path, line, keyCol, int(d->key.size()),
                        "unknown directive '" + d->key +
                            "' in clover's specification file: ignored, as clover does"));
    }
  }
  const Line specLine{1, {}};
  if (def.size[0] < 1 || def.size[1] < 1 || double(def.size[0]) * def.size[1] > double(1 << 26) ||
      !(def.range[0] != 0 && def.range[1] != 0)) {
    diags.Add(Warning(path, specLine, 0, 1,
                      "clover's grid of " + std::to_string(def.size[0]) + "x" +
                          std::to_string(def.size[1]) +
                          " cells over a range of zero or more than 2^26 cells cannot be held: "
                          "?E is not answered"));
    return false;
  }
  if (imageAt) {
    const std::string imagePath = Join(ParentOf(path), imageName);
    std::optional<std::string> bytes;
    if (readFile) {
      bytes = readFile(imagePath);
    } else if (auto b = ReadFile(imagePath, size_t(256) << 20)) {
      bytes = std::move(*b);
    }
    std::string why;
    if (bytes) {
      auto img = ReadCloverImage(*bytes, imagePath);
      if (img)
        image = std::move(*img);
      else
        why = img.error().message;
    } else {
      why = "cannot read " + imagePath;
    }
    if (!image) {
      diags.Add(Warning(path, imageAt->first, imageAt->second, int(imageName.size()),
                        why + ": clover's light is taken as full (255) everywhere"));
    }
  }
  return true;
}

// chiba's spec file.
void ReadChibaSpec(const std::string& path, const std::string& text, ChibaDef& def,
                   DiagnosticList& diags) {
  for (const Line& line : LinesOf(text)) {
    auto d = DirectiveOf(line.text);
    if (!d) continue;
    const int keyCol = int(line.text.find_first_not_of("\t:"));
    const auto xs = Split(d->value, "x,; \t:");
    const auto words = Split(d->value, ",; \t:");
    const std::string first = words.empty() ? std::string() : words[0].first;
    const std::string firstX = xs.empty() ? std::string() : xs[0].first;
    auto number = [](const std::string& w) { return float(std::atof(w.c_str())); };
    if (d->key == "grid size" || d->key == "verbose") {
      // cpfg's acceleration grid (the answers do not depend on it); a log.
    } else if (d->key == "lower to upper ratio") {
      def.lowerToUpper = number(first);
    } else if (d->key == "transmittance") {
      def.transmittance = number(first);
    } else if (d->key == "number of samples") {
      def.samples = std::atoi(firstX.c_str());
    } else if (d->key == "radius") {
      def.radius = number(first);
    } else if (d->key == "beam radius") {
      def.beamRadius = number(first);
    } else if (d->key == "source direction") {
      if (def.sources.size() >= 100) {
        diags.Add(Warning(path, line, keyCol, int(d->key.size()),
                          "chiba takes at most 100 light sources; this one is ignored"));
        continue;
      }
      ChibaDef::Source src;
      src.dir[1] = 0;
      for (size_t i = 0; i < 3 && i < words.size(); ++i) src.dir[i] = number(words[i].first);
      if (words.size() > 3) src.intensity = number(words[3].first);
      def.sources.push_back(src);
    } else if (d->key == "estimate intersection area") {
      def.estimateArea = firstX == "on";
    } else if (d->key == "use CIE formula") {
      def.cie = firstX == "yes";
    } else {
      diags.Add(Warning(path, line, keyCol, int(d->key.size()),
                        "unknown directive '" + d->key +
                            "' in chiba's specification file: ignored, as chiba does"));
    }
  }
}

}  // namespace

std::optional<CpfgEnvironmentRef> FindCpfgEnvironment(const std::string& grammarPath,
                                                      const Reader& readFile) {
  const std::string dir = ParentOf(grammarPath);
  const std::string base = BaseOf(grammarPath);
  for (const char* specName : {"specifications", "LSspecifications"}) {
    const std::string specPath = Join(dir, specName);
    auto text = ReadText(specPath, readFile);
    if (!text) continue;
    for (const Line& line : LinesOf(*text)) {
      const auto words = Split(line.text, " \t");
      size_t cpfg = words.size();
      for (size_t i = 0; i < words.size(); ++i) {
        if (BaseOf(words[i].first).rfind("cpfg", 0) == 0) {
          cpfg = i;
          break;
        }
      }
      if (cpfg == words.size()) continue;
      bool namesGrammar = false;
      size_t e = 0;
      for (size_t i = cpfg + 1; i < words.size(); ++i) {
        if (words[i].first == base) namesGrammar = true;
        if (words[i].first == "-e" && i + 1 < words.size() && e == 0) e = i + 1;
      }
      if (!namesGrammar || e == 0) continue;
      CpfgEnvironmentRef ref;
      ref.file = Join(dir, words[e].first);
      ref.namedAt = SourceLoc{specPath, line.number, words[e].second + 1};
      ref.namedLine = line.text;
      ref.namedLength = int(words[e].first.size());
      return ref;
    }
  }
  const size_t dot = base.rfind('.');
  const std::string beside =
      Join(dir, (dot == std::string::npos ? base : base.substr(0, dot)) + ".e");
  if (ReadText(beside, readFile)) return CpfgEnvironmentRef{beside, {}, {}, 1};
  return std::nullopt;
}

std::unique_ptr<Environment> LoadCpfgEnvironment(const CpfgEnvironmentRef& ref,
                                                 const Reader& readFile, DiagnosticList& diags) {
  auto text = ReadText(ref.file, readFile);
  if (!text) {
    Diagnostic d = MakeError(ref.namedAt,
                             "the environment file " + ref.file +
                                 " named here cannot be read: ?E is not answered, its parameters "
                                 "keep the values written in the grammar",
                             ref.namedLength, ref.namedLine);
    d.severity = Severity::kWarning;
    diags.Add(std::move(d));
    return nullptr;
  }
  std::optional<Line> executableLine;
  std::string executable;
  int executableColumn = 0;
  std::optional<std::vector<Conversion>> position;
  for (const Line& line : LinesOf(*text)) {
    auto d = DirectiveOf(line.text);
    if (!d) continue;
    const int keyCol = int(line.text.find_first_not_of("\t:"));
    if (d->key == "executable") {
      executableLine = line;
      executable = d->value;
      executableColumn = d->valueColumn;
    } else if (d->key == "turtle position") {
      position = ConversionsOf(d->value);
      if (!position) {
        diags.Add(Warning(ref.file, line, d->valueColumn, int(d->value.size()),
                          "this 'turtle position:' format has a conversion other than %f, %e "
                          "or %g: no position is sent, so the program answers no ?E"));
        position = std::vector<Conversion>{};
      }
    } else if (d->key == "communication type" || d->key == "verbose" || d->key == "remote host" ||
               d->key == "strings only" || d->key == "binary data" || d->key == "turtle heading" ||
               d->key == "turtle left" || d->key == "turtle up" || d->key == "turtle line width" ||
               d->key == "turtle scale factor" || d->key == "following module") {
      // How cpfg talks to the process, or turtle data that Sylva's built-in
      // programs do not read (none of them uses more than the position).
    } else if (d->key == "interpreted modules" || d->key == "when interpret") {
      diags.Add(Warning(ref.file, line, keyCol, int(d->key.size()),
                        "'" + d->key +
                            ":' is read but not acted on: Sylva sends only ?E modules to "
                            "the environment"));
    } else {
      diags.Add(Warning(
          ref.file, line, keyCol, int(d->key.size()),
          "unknown directive '" + d->key + "' in the environment file: ignored, as cpfg does"));
    }
  }
  if (!executableLine) {
    Diagnostic d = MakeError(SourceLoc{ref.file, 1, 0},
                             "the environment file has no 'executable:' line: ?E is not "
                             "answered");
    d.severity = Severity::kWarning;
    diags.Add(std::move(d));
    return nullptr;
  }
  const auto args = Split(executable, " \t");
  if (args.empty()) {
    diags.Add(Warning(ref.file, *executableLine, executableColumn, 1,
                      "'executable:' names no program: ?E is not answered"));
    return nullptr;
  }
  const std::string program = BaseOf(args[0].first);
  const int programCol = executableColumn + args[0].second;
  Program kind;
  if (program == "honda81") {
    kind = Program::kHonda81;
  } else if (program == "ecosystem") {
    kind = Program::kEcosystem;
  } else if (program == "clover") {
    kind = Program::kClover;
  } else if (program == "chiba") {
    kind = Program::kChiba;
  } else {
    diags.Add(
        Warning(ref.file, *executableLine, programCol, int(args[0].first.size()),
                "the environment program '" + program +
                    "' is not built into Sylva (it has honda81, ecosystem, clover and chiba): "
                    "?E "
                    "is not answered, its parameters keep the values written in the "
                    "grammar"));
    return nullptr;
  }
  // The program's arguments: `-e FILE` (the .e itself), then its spec file.
  std::string specFile;
  int specCol = programCol;
  for (size_t i = 1; i < args.size(); ++i) {
    const std::string& a = args[i].first;
    if (a == "-e" || a == "-k" || a == "-ext" || a == "-host") {
      ++i;
      continue;
    }
    if (a == "&" || a[0] == '-') continue;
    specFile = a;
    specCol = executableColumn + args[i].second;
    break;
  }
  const char* defaults = kind == Program::kHonda81     ? " (radius 0, 2D)"
                         : kind == Program::kEcosystem ? " (2D, no vigor)"
                         : kind == Program::kClover    ? " (a 2x2 grid from (-1, -1), full light)"
                                                       : " (radius 25, transmittance 0.6, 32 sky "
                                                         "samples)";
  Honda81Def honda;
  EcosystemDef eco;
  CloverDef clover;
  std::optional<CloverImage> image;
  ChibaDef chiba;
  if (specFile.empty()) {
    diags.Add(
        Warning(ref.file, *executableLine, programCol, int(args[0].first.size()),
                program + " is given no specification file: it runs with its defaults" + defaults));
  } else {
    const std::string specPath = Join(ParentOf(ref.file), specFile);
    auto spec = ReadText(specPath, readFile);
    if (!spec) {
      diags.Add(Warning(ref.file, *executableLine, specCol, int(specFile.size()),
                        "cannot read " + program + "'s specification file " + specPath +
                            ": it runs with its defaults" + defaults));
    } else if (kind == Program::kClover) {
      if (!ReadCloverSpec(specPath, *spec, readFile, clover, image, diags)) return nullptr;
    } else if (kind == Program::kChiba) {
      ReadChibaSpec(specPath, *spec, chiba, diags);
    } else {
      ReadDensitySpec(kind, specPath, *spec, honda, eco, diags);
    }
  }
  const int need = kind == Program::kClover && clover.zIsUp ? 2 : 3;
  if (!position) {
    diags.Add(Warning(ref.file, *executableLine, programCol, int(args[0].first.size()),
                      "the environment file has no 'turtle position:' line, so cpfg sends no "
                      "position and " +
                          program + " answers no ?E"));
    position = std::vector<Conversion>{};
  } else if (int(position->size()) < need) {
    diags.Add(Warning(ref.file, *executableLine, programCol, int(args[0].first.size()),
                      "'turtle position:' sends " + std::to_string(position->size()) +
                          " coordinates and " + program + " needs " + std::to_string(need) +
                          ": it answers no ?E"));
  }
  const int coordinates = int(position->size());
  std::unique_ptr<Environment> env;
  if (kind == Program::kClover)
    env = std::make_unique<CloverEnvironment>(clover, image ? &*image : nullptr, coordinates);
  else if (kind == Program::kChiba)
    env = std::make_unique<ChibaEnvironment>(chiba, coordinates);
  else
    env = std::make_unique<DensityProgram>(kind, coordinates, honda, eco);
  return std::make_unique<FormattedPositions>(std::move(env), std::move(*position));
}

}  // namespace sylva::plant
