#include "app/cpfg_specifications.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string_view>

#include "core/atomic_file.h"

namespace sylva::app {
namespace {

namespace fs = std::filesystem;

constexpr size_t kMaxSpecificationsBytes = size_t(1) << 20;
constexpr size_t kMaxCommands = 4096;
constexpr size_t kMaxWords = 64;

struct Word {
  std::string text;
  int column = 0;
};

// The words of one command: whitespace separates them, "..." quotes one.
std::vector<Word> Words(std::string_view s, int column0) {
  std::vector<Word> out;
  size_t i = 0;
  while (i < s.size() && out.size() < kMaxWords) {
    while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
    if (i >= s.size()) break;
    Word w;
    w.column = column0 + int(i);
    if (s[i] == '"') {
      size_t e = s.find('"', i + 1);
      if (e == std::string_view::npos) e = s.size();
      w.text = std::string(s.substr(i + 1, e - i - 1));
      i = std::min(s.size(), e + 1);
    } else {
      while (i < s.size() && !std::isspace(static_cast<unsigned char>(s[i]))) w.text += s[i++];
    }
    out.push_back(std::move(w));
  }
  return out;
}

// `cpfg` or `cpfg` and a version (`cpfg3.2`), as the program's name.
bool IsCpfg(const std::string& w) {
  if (w.rfind("cpfg", 0) != 0) return false;
  return std::all_of(w.begin() + 4, w.end(), [](char c) {
    return std::isdigit(static_cast<unsigned char>(c)) || c == '.';
  });
}

// cpfg's image and string output options (-rgb FILE, -str FILE, ...): each
// takes a file name.
bool IsOutputOption(const std::string& o) {
  static constexpr std::string_view kOutputs[] = {"rgb",  "ras", "tga", "ray",  "ps",  "str",
                                                  "strb", "gls", "vv",  "iv",   "obj", "png",
                                                  "bmp",  "jpg", "tif", "tiff", "pdf", "eps"};
  for (std::string_view x : kOutputs)
    if (o.compare(1, std::string::npos, x) == 0) return true;
  return false;
}

// The number of arguments option `o` (with its '-') takes, as cpfg's
// ParseCommand reads them; -1: cpfg has no such option.
int Arguments(const std::string& o) {
  if (IsOutputOption(o)) return 1;
  switch (o.size() > 1 ? o[1] : '\0') {
    case 'a':
    case 'c':
    case 'd':
    case 'g':
    case 'h':
    case 'p':
    case 's':
    case 'v':
    case 'V':
      return 0;
    case 'b':
    case 'C':
    case 'S':
    case 'e':
    case 'P':
    case 'M':
      return 1;
    case 'm':
      return o == "-mb" ? 0 : 1;
    case 'r':
      return o == "-rmode" ? 1 : 0;
    case 'w':
      if (o == "-wt") return 1;
      if (o == "-wnb" || o == "-wnm") return 0;
      return 2;  // -w, -wp, -wr, -wpr: two numbers
    default:
      return -1;
  }
}

// The map or material number of -m[n] / -M[n]: 1 without digits.
int MapNumber(const std::string& o) {
  if (o.size() <= 2) return 1;
  int n = 0;
  for (size_t i = 2; i < o.size() && i < 6; ++i) {
    if (!std::isdigit(static_cast<unsigned char>(o[i]))) return 1;
    n = n * 10 + (o[i] - '0');
  }
  return n;
}

CpfgCommand ReadCommand(const std::vector<Word>& w, const std::string& path, int line) {
  CpfgCommand c;
  c.loc = {path, line, w[0].column};
  int colormapN = 1 << 30, materialN = 1 << 30;
  int files = 0;
  for (size_t i = 1; i < w.size(); ++i) {
    const std::string& t = w[i].text;
    if (t.size() > 1 && t[0] == '-') {
      const int n = Arguments(t);
      if (n < 0) {
        c.unknownOptions.push_back(t);
        continue;
      }
      const std::string arg = i + 1 < w.size() && n >= 1 ? w[i + 1].text : std::string();
      if ((t[1] == 'm' && t != "-mb") || t[1] == 'M') {
        const int k = MapNumber(t);
        int& best = t[1] == 'm' ? colormapN : materialN;
        if (!arg.empty() && k <= best) {
          best = k;
          (t[1] == 'm' ? c.colormap : c.material) = arg;
        }
        c.materialWins = t[1] == 'M';
      } else if (t == "-e") {
        if (c.environment.empty()) c.environment = arg;  // cpfg keeps the first
      }
      i += size_t(n);
      continue;
    }
    ++files;
    if (files == 1) c.lsystem = t;
    if (files == 2) c.view = t;
    if (files == 3) c.animation = t;
  }
  return c;
}

}  // namespace

std::vector<CpfgCommand> ParseCpfgCommands(const std::string& text, const std::string& path) {
  std::vector<CpfgCommand> out;
  int line = 0;
  size_t start = 0;
  while (start <= text.size() && out.size() < kMaxCommands) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    ++line;
    std::string_view l(text.data() + start, end - start);
    // Commands on a line are separated by ';' (`loadmap x.map;cpfg ...`).
    size_t from = 0;
    while (from <= l.size()) {
      size_t to = l.find(';', from);
      if (to == std::string_view::npos) to = l.size();
      std::vector<Word> w = Words(l.substr(from, to - from), int(from) + 1);
      if (!w.empty() && IsCpfg(w[0].text)) {
        out.push_back(ReadCommand(w, path, line));
        if (out.size() >= kMaxCommands) break;
      }
      from = to + 1;
    }
    if (end == text.size()) break;
    start = end + 1;
  }
  return out;
}

Expected<std::optional<CpfgCommand>> CpfgCommandFor(const std::string& grammarPath) {
  const fs::path grammar(grammarPath);
  const fs::path spec = grammar.parent_path() / "specifications";
  std::error_code ec;
  if (!fs::exists(spec, ec)) return std::optional<CpfgCommand>();
  auto text = ReadFile(spec.string(), kMaxSpecificationsBytes);
  if (!text) {
    Diagnostic d = text.error();
    d.loc.file = spec.string();
    d.message = "vlab specifications (read for the cpfg command's files): " + d.message;
    return d;
  }
  const std::string name = grammar.filename().string();
  for (CpfgCommand& c : ParseCpfgCommands(*text, spec.string())) {
    if (fs::path(c.lsystem).filename().string() == name) return std::optional(std::move(c));
  }
  return std::optional<CpfgCommand>();
}

}  // namespace sylva::app
