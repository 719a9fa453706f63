// Grammar file reader. Two stages:
//   1. Preprocess: split lines, blank out comments (columns are kept), and
//      splice #include files in place, with recursion and depth checks.
//   2. Parse line by line: #define, header statements, section keywords,
//      productions. Each line is parsed on its own, so an error on one line
//      does not hide the errors on the next.
// Then: brackets, context skip tables and the warnings.
#include "lsys/parser.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <unordered_set>

#include "core/atomic_file.h"
#include "lsys/expr_parser.h"
#include "lsys/unsupported.h"

namespace sylva::lsys {
namespace {

struct Line {
  int file = 0;
  int number = 0;
  std::string text;           // comments blanked, same columns
  std::string_view original;  // for excerpts: points into Grammar::sources
  // Lines joined to this one (JoinContinuations): text from at + 1 on came
  // from line `number` of the same file, starting at its column `column`.
  struct Piece {
    int at = 0, number = 0, column = 1;
    std::string_view original;
  };
  std::vector<Piece> more;
  // Uses of text #defines substituted into `text` (ExpandTextMacros), in
  // column order: text[at, at + len) replaced text[from, from + fromLen) of
  // the line before (0-based).
  struct Expansion {
    int at = 0, len = 0, from = 0, fromLen = 0;
    std::string name;
    int defineLine = 0;
  };
  std::vector<Expansion> expansions;

  // The use of a text #define that column `col` (1-based) lies in; null: none.
  const Expansion* ExpansionAt(int col) const {
    for (const Expansion& e : expansions) {
      if (col - 1 < e.at) break;
      if (col - 1 < e.at + e.len) return &e;
    }
    return nullptr;
  }
  // Column `col` of `text` in the line before the #defines were substituted:
  // inside a substituted text, the column of the name that was replaced.
  int PreExpansionCol(int col) const {
    int shift = 0;
    for (const Expansion& e : expansions) {
      if (col - 1 < e.at) break;
      if (col - 1 < e.at + e.len) return e.from + 1;
      shift = (e.from + e.fromLen) - (e.at + e.len);
    }
    return col + shift;
  }

  // The piece that column `col` (1-based, of `text`) came from; null: the first line.
  const Piece* PieceAt(int col) const {
    // The last piece with at < col (pieces are in column order).
    auto it = std::upper_bound(more.begin(), more.end(), col,
                               [](int c, const Piece& q) { return c <= q.at; });
    return it == more.begin() ? nullptr : &*(it - 1);
  }
};

struct Define {
  SourceLoc loc;
  int length = 1;
  std::string text;  // what follows the name, blanks collapsed (a redefinition compares it)
};

// `text` with runs of blanks as one space and none at either end: C's rule
// for when two #defines of a name are the same (no warning).
std::string CollapseBlanks(std::string_view text) {
  std::string r;
  for (char c : text) {
    const bool blank = c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
    if (!blank) {
      r += c;
    } else if (!r.empty() && r.back() != ' ') {
      r += ' ';
    }
  }
  while (!r.empty() && r.back() == ' ') r.pop_back();
  return r;
}

// The first use of a module name with each number of parameters, in the
// order the names were first used with a second number.
struct ArityUse {
  std::map<int, SourceLoc> first;  // arity -> its first use
};

bool IsSpace(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}
bool IsIdentStart(char c) {
  return std::isalpha(static_cast<unsigned char>(c)) || c == '_';
}
bool IsIdentChar(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
}

// `maximum depth:` of a decomposition or interpretation section.
constexpr int kMaxSectionDepth = 100000;

// A line whose first text (at p) is `#` is a preprocessor directive only
// when a name, a number or the end of the line follows the `#` (and blanks):
// cpfg's preprocessor (vlab's cccp, handle_directive) passes any other line,
// such as a continued successor that begins with the width module `#(0.06)`,
// through as text.
bool StartsDirective(const std::string& t, size_t p) {
  if (p >= t.size() || t[p] != '#') return false;
  size_t q = p + 1;
  while (q < t.size() && IsSpace(t[q])) ++q;
  return q >= t.size() || IsIdentStart(t[q]) || std::isdigit(static_cast<unsigned char>(t[q]));
}

// Single-character module names besides letters and digits. cpfg's lexer
// (`lsys_input.l`, `symbol`) takes any character but `<>:*`, blanks and
// parentheses as a module; Sylva reads `~`, `@` and `?` as the start of
// longer names and leaves out `"` (a string in parameters).
constexpr std::string_view kModuleChars = "+-&^\\/|$[]!'{.}%_;,#=`";

// cpfg's @ commands, longest first where they share a prefix.
constexpr std::string_view kAtCommands[] = {
    "@Gs", "@Ge", "@Gc", "@Gr", "@Gt", "@Tf", "@PS", "@PD", "@Ts", "@Ti", "@Td", "@Sx", "@O", "@o",
    "@c",  "@v",  "@M",  "@m",  "@R",  "@D",  "@i",  "@L",  "@b",  "@Tx", "@#",  "@!",  "@;"};

std::string Lower(std::string_view s) {
  std::string r(s);
  for (char& c : r) c = char(std::tolower(static_cast<unsigned char>(c)));
  return r;
}

// "64 MiB" or "100 bytes".
std::string SizeText(size_t bytes) {
  if (bytes >= (size_t(1) << 20) && bytes % (size_t(1) << 20) == 0)
    return std::to_string(bytes >> 20) + " MiB";
  return std::to_string(bytes) + " bytes";
}

std::string Printable(char c) {
  auto u = static_cast<unsigned char>(c);
  if (u >= 32 && u < 127) return std::string(1, c);
  char buf[8];
  std::snprintf(buf, sizeof buf, "\\x%02x", u);
  return buf;
}

// Header statements and section keywords, longest first where they share a
// prefix ("width factor" before "width").
constexpr const char* kKeywords[] = {
    "derivation length", "width factor",   "width increment", "width scale", "maximum depth",
    "lsystem",           "axiom",          "angle",           "step",        "width",
    "tropism",           "seed",           "ignore",          "consider",    "module",
    "decomposition",     "interpretation", "homomorphism",    "endlsystem",  "palette",
    "starteach",         "endeach",        "start",           "end",         "define",
    "functions",         "environment"};

// cpfg's blocks of statements run around the derivation (global variables).
bool IsGlobalBlockKeyword(std::string_view k) {
  return k == "start" || k == "end" || k == "starteach" || k == "endeach";
}

// A production arrow (`->`, `-->`) in t from `from` on, outside
// parentheses, statement blocks and strings.
bool HasTopLevelArrow(const std::string& t, size_t from) {
  int depth = 0;
  for (size_t i = from; i < t.size(); ++i) {
    const char c = t[i];
    if (c == '"') {
      for (++i; i < t.size() && t[i] != '"'; ++i)
        if (t[i] == '\\') ++i;
    } else if (c == '(' || c == '{') {
      ++depth;
    } else if (c == ')' || c == '}') {
      --depth;
    } else if (depth == 0 && c == '-' && i + 1 < t.size() && t[i + 1] == '>') {
      return true;
    }
  }
  return false;
}

// The keyword that starts `t` at `pos` ("keyword:", or a bare section
// keyword alone on its line), case-insensitive; *after is just past it.
// A line with a production arrow after the colon is a production whose
// predecessor is spelled like a keyword (vlab's Lilac: `AXIOM : A_SW == 1
// --> ...`, the modules A X I O M): no statement holds an arrow, and cpfg's
// lexer reads `axiom:` only as `axiom` or `Axiom` with the colon right after.
const char* MatchKeyword(const std::string& t, size_t pos, size_t* after) {
  const std::string lower = Lower(t.substr(pos, 20));
  for (const char* k : kKeywords) {
    const size_t n = std::strlen(k);
    if (lower.compare(0, n, k) != 0) continue;
    size_t q = pos + n;
    while (q < t.size() && IsSpace(t[q])) ++q;
    const std::string_view kv = k;
    const bool bare = kv == "endlsystem" || kv == "decomposition" || kv == "interpretation" ||
                      kv == "homomorphism";
    if (q < t.size() && t[q] == ':') {
      if (HasTopLevelArrow(t, q + 1)) return nullptr;
      *after = q + 1;
      return k;
    }
    if (bare && q >= t.size()) {
      *after = q;
      return k;
    }
  }
  return nullptr;
}

class GrammarParser {
 public:
  explicit GrammarParser(const ParseOptions& options) : opt_(options) {}

  ParseResult Run(const std::string& text, const std::string& path);

 private:
  // --- diagnostics ---
  // The file position of column `col` of a (possibly joined) line, and the
  // text of the file line it is on.
  SourceLoc Loc(const Line& l, int col) const {
    col = l.PreExpansionCol(col);
    if (const Line::Piece* p = l.PieceAt(col))
      return SourceLoc{files_[l.file], p->number, p->column + (col - 1 - p->at)};
    return SourceLoc{files_[l.file], l.number, col};
  }
  static std::string_view OriginalAt(const Line& l, int col) {
    const Line::Piece* p = l.PieceAt(l.PreExpansionCol(col));
    return p ? p->original : l.original;
  }
  void Error(const Line& l, int col, std::string msg, int len = 1) {
    if (int(diags_.ErrorCount()) >= kMaxErrors) {
      ++diags_.droppedErrors;  // counted, so the report can say how many
      return;
    }
    if (msg.rfind("func(id, x)", 0) == 0 && functionFilesFailed_) return;  // reported at the file
    if (msg.rfind("func(id, x) needs cpfg function files", 0) == 0) msg += FunctionsHint();
    if (msg.rfind("curve", 0) == 0 && curveFilesFailed_) return;  // reported at the file
    if (msg.find(" needs cpfg curve files") != std::string::npos)
      msg += FunctionsHint("'curve:' line");
    if (const Line::Expansion* e = l.ExpansionAt(col)) {
      msg += " (in the text of '#define " + e->name + "' at line " + std::to_string(e->defineLine) +
             ")";
      len = int(e->name.size());
    }
    diags_.Add(MakeError(Loc(l, col), std::move(msg), len, OriginalAt(l, col)));
  }
  void Warn(SourceLoc loc, std::string_view line, std::string msg, int len = 1) {
    Diagnostic d = MakeError(std::move(loc), std::move(msg), len, line);
    d.severity = Severity::kWarning;
    warnings_.push_back(std::move(d));
  }

  // --- preprocessing ---
  // Reads an included file within the limits; on failure *why says why.
  std::optional<std::string> Read(const std::string& path, std::string* why);
  void Preprocess(std::shared_ptr<const std::string> text, const std::string& path, int depth,
                  std::vector<std::string>& stack);

  // --- parsing ---
  void ParseLine(const Line& l);
  bool ParseHeader(const Line& l, size_t pos);
  // The statements of ParseHeader with more than a line of work.
  void ParseAxiom(const Line& l, int col, size_t after, size_t end);
  void ParseContextNames(const Line& l, size_t after, size_t end, bool ignore);
  void ParsePalette(const Line& l, int col, size_t after, size_t end);
  void ParseEnvironment(const Line& l, int col, size_t after, size_t end);
  void ParseTropism(const Line& l, size_t after, size_t end);
  void ParseNumberStatement(const Line& l, const std::string& k, size_t after, size_t end);
  void ParseDefine(const Line& l, size_t pos);
  void Conditionals();
  void ParseGlobalBlock(const Line& l, const std::string& k, size_t after, size_t end);
  void ParseFunctions(const Line& l, size_t after, size_t end);
  void ParseArrays(const Line& l, size_t after, size_t end);
  // Arrays in the expressions of line l: each index written is a site of
  // the grammar's ArrayBounds (cpfg's clamped indices, warned about).
  void UseArrays(const Line& l, ExprScope& scope);
  void CollectGlobals();
  void CheckSubLsystemIds();
  void HiddenGlobalSlots(const std::string& t, size_t from, bool start, ExprScope* scope);
  bool ParseCondition(const Line& l, Production& p, const ExprScope& scope, size_t condAt,
                      size_t lhsEnd);
  void ParseMacro(const Line& l, const std::string& name, int col, size_t pos);
  // A second #define of `name` (text: what follows the name): in a cpfg
  // file the later one holds, as C's preprocessor has it, with a warning
  // naming the first unless both are the same (true: go on); in a .lsys
  // file an error (false).
  bool Redefine(const Line& l, const std::string& name, int col, const std::string& text);
  // In a cpfg file, the names #defined more than once or #undef'd: each of
  // their #defines is text, substituted in file order as C's preprocessor
  // does, so a line between two #defines reads the first.
  std::unordered_set<std::string> cppNames_;
  void FindCppNames();
  // cpfg's preprocessor substitutes text: a #define whose value is not an
  // expression (a piece of a word) is kept as text and substituted.
  struct TextMacro {
    bool function = false;  // NAME(a, b)
    std::vector<std::string> params;
    std::string body;
    int line = 0;
  };
  void ParseUndef(const Line& l, size_t after);
  void AddTextMacro(const Line& l, const std::string& name, int col, TextMacro m,
                    const std::string& text);
  bool ExpandText(std::string_view s, std::vector<std::string>& hiding, int depth, std::string* out,
                  std::vector<Line::Expansion>* uses, size_t* problemAt, std::string* problem);
  void ExpandTextMacros(Line& l);
  void ParseProduction(const Line& l, size_t pos, size_t arrow, size_t arrowLen);
  bool LexName(const Line& l, size_t& pos, size_t end, std::string* name);
  bool ParseActualWord(const Line& l, size_t pos, size_t end, const ExprScope& scope,
                       Successor* out);
  // ParseBlock with its errors reported, and cpfg's output calls in it
  // (printf, ...; ExprScope::outputCalls) warned about once per call name.
  bool ParseBlockAt(const Line& l, std::string_view view, size_t* pos, const ExprScope& scope,
                    Expr* out);
  struct Formal {
    std::string name;
    std::vector<std::string> params;
    int column = 0;
    bool wildcard = false;
  };
  bool ParseFormalWord(const Line& l, size_t& pos, size_t end, std::vector<Formal>* out);
  bool ParseConstExpr(const Line& l, size_t pos, size_t end, double* out, Expr* expr = nullptr);
  bool CheckBrackets(const Line& l, const std::vector<SymbolId>& syms, const std::vector<int>& cols,
                     const char* what);
  // opt_.isSurface, asked once per name; false without it.
  bool IsSurface(const std::string& name) {
    if (!opt_.isSurface) return false;
    auto it = isSurface_.find(name);
    if (it == isSurface_.end()) it = isSurface_.emplace(name, opt_.isSurface(name)).first;
    return it->second;
  }
  std::optional<SymbolId> Intern(const Line& l, int col, const std::string& name, int arity);
  void JoinContinuations();
  void LoadOptionFunctions();
  void LoadOptionCurves();
  // Where Sylva looked for function files outside the grammar, for the
  // error of a func() without any: the view file it read or looked for.
  std::string FunctionsHint(
      const std::string& lines = "'function:' or 'function set:' line") const {
    if (!opt_.viewFile.empty()) return "; the view file " + opt_.viewFile + " has no " + lines;
    if (files_.empty()) return "";
    std::filesystem::path v(files_[0]);
    v.replace_extension(".v");
    return "; no view file was read (sylva looks for " + v.lexically_normal().string() +
           ", or takes --view FILE)";
  }
  void WarnAfterEnd(const Line& l);
  void Finish();
  void WarnUnmatchable();
  void WarnMixedArity();

  const ParseOptions& opt_;
  std::vector<std::string> files_;
  std::vector<Line> lines_;
  DiagnosticList diags_;
  std::vector<Diagnostic> warnings_;
  Grammar g_;
  Section* section_ = &g_.main;
  bool haveAxiom_ = false;
  bool ended_ = false;
  bool warnedAfterEnd_ = false;
  // Sub-L-systems: the block being read (index into g_.lsystems), whether
  // the line being read may start a new one (it follows `endlsystem`), and
  // the ignore:/consider: names of each block before the current one.
  uint16_t lsystem_ = 0;
  bool blockMayStart_ = false;
  struct ContextNames {
    std::set<std::string> ignore, consider;
    bool haveIgnore = false, haveConsider = false;
  };
  std::vector<ContextNames> blockContext_;
  bool StartsLsystem(const Line& l) const;
  void BeginLsystem(const Line& l, int col, size_t after, size_t end);
  std::vector<uint8_t> SkipTable(const ContextNames& c) const;
  Successor axiom_;
  SourceLoc axiomLoc_;
  std::vector<int> axiomCols_;
  std::vector<std::string> declared_;  // module: names
  // The same names for lexing: their distinct lengths, longest first, and
  // the set to look a candidate of each length up in (O(lengths) a module,
  // not O(names)).
  std::vector<size_t> declaredLengths_;
  std::unordered_set<std::string_view> declaredSet_;
  std::unordered_map<std::string, Define> defines_;
  std::unordered_map<std::string, ExprMacro> macros_;  // #define NAME(params) body
  std::unordered_map<std::string, TextMacro> textMacros_;
  std::unordered_set<std::string> usedConstants_;
  std::set<std::string> usedOverrides_;
  // Names a function set defines as constants (cpfg's -DNAME=i): a #define
  // or #undef of one in the grammar replaces it.
  std::set<std::string> functionSetNames_;
  bool functionFilesFailed_ = false;  // a view file's function file could not be read
  bool curveFilesFailed_ = false;     // a view file's curve file could not be read
  std::unordered_map<std::string, ArityUse> arityUse_;
  std::vector<std::string> arityMixed_;  // names used with two or more arities, in that order
  std::unordered_set<std::string> unsupportedWarned_;  // name + reason
  bool unbalancedWarned_ = false;                      // CheckBrackets in a cpfg file
  int ringLine_ = 0;                                   // of the first `ring lsystem`
  // In a cpfg file (`.l`), a name nothing defines reads 0 with a warning
  // (once per name), as cpfg does; in Sylva's own `.lsys` files it stays an
  // error (a typo). Lenient() lets a scope note such names in undefined_;
  // WarnUndefined() warns about them after the parse succeeded.
  std::vector<ExprParseError> undefined_;
  std::unordered_set<std::string> undefinedWarned_;
  ExprScope Lenient(const ExprScope& scope) {
    ExprScope s = scope;
    undefined_.clear();
    if (g_.cpfgFile) s.undefinedNames = &undefined_;
    return s;
  }
  void WarnUndefined(const Line& l) {
    for (const ExprParseError& u : undefined_) {
      if (!undefinedWarned_.insert(u.message).second) continue;
      Warn(Loc(l, u.column), OriginalAt(l, u.column),
           "'" + u.message +
               "' is not defined (no parameter, variable, constant or #define of that name): it "
               "reads 0, as cpfg does (in a .lsys file this is an error)",
           u.length);
    }
    undefined_.clear();
  }
  std::unordered_map<std::string, bool> isSurface_;
  std::set<std::string> ignoreNames_, considerNames_;
  bool haveIgnore_ = false, haveConsider_ = false;
  size_t bytesRead_ = 0;  // all files, for kMaxGrammarBytes
  int filesIncluded_ = 0;
};

// ---------------------------------------------------------------------------
// Preprocessing

std::optional<std::string> GrammarParser::Read(const std::string& path, std::string* why) {
  std::optional<std::string> text;
  if (opt_.readFile) {
    text = opt_.readFile(path);
    if (!text) *why = "cannot read file";
  } else {
    auto r = ReadFile(path, opt_.maxFileBytes);
    if (r) {
      text = std::move(r).value();
    } else {
      *why = r.error().message;
    }
  }
  if (text && text->size() > opt_.maxFileBytes) {
    *why = "file is larger than the limit of " + SizeText(opt_.maxFileBytes);
    text.reset();
  }
  return text;
}

void GrammarParser::Preprocess(std::shared_ptr<const std::string> shared, const std::string& path,
                               int depth, std::vector<std::string>& stack) {
  int file = int(files_.size());
  files_.push_back(path);
  bytesRead_ += shared->size();
  // Lines (\n, \r\n) as offsets into the text, which the grammar keeps for
  // excerpts. A UTF-8 byte order mark at the start is skipped.
  const std::string_view text = *shared;
  Grammar::SourceFile source{path, shared, {}};
  const size_t bom = text.substr(0, 3) == "\xEF\xBB\xBF" ? 3 : 0;
  std::vector<std::string_view> raw;
  size_t start = bom;
  for (size_t i = bom; i <= text.size(); ++i) {
    if (i == text.size() || text[i] == '\n') {
      std::string_view s = text.substr(start, i - start);
      if (!s.empty() && s.back() == '\r') s.remove_suffix(1);
      raw.push_back(s);
      source.lineStarts.push_back(start);
      start = i + 1;
    }
  }
  if (!raw.empty() && raw.back().empty() && text.size() > bom) {
    raw.pop_back();
    source.lineStarts.pop_back();
  }
  g_.sources.push_back(std::move(source));

  bool inBlock = false;
  Line blockStart;  // text left empty: only for the error's location
  int blockCol = 0;
  for (size_t n = 0; n < raw.size(); ++n) {
    Line l;
    l.file = file;
    l.number = int(n) + 1;
    l.original = raw[n];
    l.text = std::string(raw[n]);
    std::string& t = l.text;
    for (size_t i = 0; i < t.size(); ++i) {
      if (inBlock) {
        if (t[i] == '*' && i + 1 < t.size() && t[i + 1] == '/') {
          t[i] = t[i + 1] = ' ';
          ++i;
          inBlock = false;
        } else {
          t[i] = ' ';
        }
      } else if (t[i] == '/' && i + 1 < t.size() && t[i + 1] == '*') {
        inBlock = true;
        blockStart.file = l.file;
        blockStart.number = l.number;
        blockStart.original = l.original;
        blockCol = int(i) + 1;
        t[i] = t[i + 1] = ' ';
        ++i;
      } else if (t[i] == '/' && i + 1 < t.size() && t[i + 1] == '/' &&
                 (i == 0 || IsSpace(t[i - 1]))) {
        // `//` opens a comment at the start of a line or after a space;
        // elsewhere it is two roll modules, as ABOP writes them (`S/////F`).
        for (size_t k = i; k < t.size(); ++k) t[k] = ' ';
        break;
      }
    }
    // #include splices another file here.
    size_t p = 0;
    while (p < t.size() && IsSpace(t[p])) ++p;
    if (t.compare(p, 8, "#include") == 0) {
      size_t q = p + 8;
      while (q < t.size() && IsSpace(t[q])) ++q;
      char close = q < t.size() && t[q] == '"' ? '"' : (q < t.size() && t[q] == '<' ? '>' : 0);
      size_t e = close ? t.find(close, q + 1) : std::string::npos;
      if (!close || e == std::string::npos) {
        Error(l, int(q) + 1, "expected a file name in quotes after #include");
        continue;
      }
      std::string name = t.substr(q + 1, e - q - 1);
      int col = int(q) + 1, len = int(e - q) + 1;
      if (name.empty() || name.find('\0') != std::string::npos) {
        Error(l, col,
              name.empty() ? "empty file name after #include"
                           : "#include file name contains a NUL byte",
              len);
        continue;
      }
      std::filesystem::path target(name);
      if (target.is_relative()) target = std::filesystem::path(path).parent_path() / target;
      std::string resolved = target.lexically_normal().string();
      if (std::find(stack.begin(), stack.end(), resolved) != stack.end()) {
        Error(l, col, "#include recursion: '" + name + "' is already being included", len);
        continue;
      }
      if (depth + 1 > kMaxIncludeDepth) {
        Error(l, col, "#include nested deeper than " + std::to_string(kMaxIncludeDepth), len);
        continue;
      }
      if (filesIncluded_ >= kMaxIncludedFiles) {
        Error(l, col,
              "more than " + std::to_string(kMaxIncludedFiles) + " #include files in one grammar",
              len);
        continue;
      }
      ++filesIncluded_;
      std::string why;
      auto content = Read(resolved, &why);
      if (!content) {
        Error(l, col, "cannot read included file '" + resolved + "': " + why, len);
        continue;
      }
      if (bytesRead_ + content->size() > opt_.maxTotalBytes) {
        Error(l, col,
              "#include of '" + resolved + "' goes past the limit of " +
                  SizeText(opt_.maxTotalBytes) + " read for one grammar",
              len);
        continue;
      }
      stack.push_back(resolved);
      Preprocess(std::make_shared<const std::string>(std::move(*content)), resolved, depth + 1,
                 stack);
      stack.pop_back();
      continue;
    }
    lines_.push_back(std::move(l));
  }
  if (inBlock) Error(blockStart, blockCol, "unterminated comment: '/*' has no '*/'", 2);
}

// ---------------------------------------------------------------------------
// Lexing module names and words

bool GrammarParser::LexName(const Line& l, size_t& pos, size_t end, std::string* name) {
  const std::string& t = l.text;
  char c = t[pos];
  for (size_t n : declaredLengths_) {
    if (pos + n > end) continue;
    auto it = declaredSet_.find(std::string_view(t).substr(pos, n));
    if (it != declaredSet_.end()) {
      *name = std::string(*it);
      pos += n;
      return true;
    }
  }
  if (c == '~') {
    size_t q = pos + 1;
    if (q < end && IsIdentStart(t[q])) {
      while (q < end && IsIdentChar(t[q])) ++q;
      if (q - pos > 2 && !IsSurface(t.substr(pos + 1, q - pos - 1)) &&
          IsSurface(t.substr(pos + 1, 1)))
        q = pos + 2;  // cpfg: a one-letter surface, then the next module
      *name = t.substr(pos, q - pos);
      pos = q;
      return true;
    }
    Error(l, int(pos) + 1, "expected a surface name after '~'");
    return false;
  }
  if (c == '@') {
    for (auto cmd : kAtCommands) {
      if (pos + cmd.size() <= end && t.compare(pos, cmd.size(), cmd) == 0) {
        *name = std::string(cmd);
        pos += cmd.size();
        return true;
      }
    }
    if (pos + 1 < end && std::isalpha(static_cast<unsigned char>(t[pos + 1]))) {
      *name = t.substr(pos, 2);
      pos += 2;
      return true;
    }
    Error(l, int(pos) + 1, "expected a command letter after '@'");
    return false;
  }
  if (c == '?') {
    if (pos + 1 < end && t[pos + 1] == '(') {  // cpfg: ?(id, scale) starts a sub-L-system
      *name = "?";
      pos += 1;
      return true;
    }
    if (pos + 1 < end && std::isupper(static_cast<unsigned char>(t[pos + 1]))) {
      *name = t.substr(pos, 2);
      pos += 2;
      return true;
    }
    Error(l, int(pos) + 1,
          "expected a query letter after '?' (?P, ?H, ?L, ?U) or '(' (?(id, scale): a "
          "sub-L-system)");
    return false;
  }
  if (std::isalnum(static_cast<unsigned char>(c)) ||
      kModuleChars.find(c) != std::string_view::npos) {
    *name = std::string(1, c);
    ++pos;
    return true;
  }
  if (c == '(') {
    Error(l, int(pos) + 1, "parameter list with no module name before it");
  } else if (c == ')') {
    Error(l, int(pos) + 1, "unbalanced ')'");
  } else {
    Error(l, int(pos) + 1, "unexpected character '" + Printable(c) + "' in a module word");
  }
  return false;
}

// cpfg's query modules: the turtle or the environment answers each with
// the parameters it has (cpfg's clover asks `?E(1)` at apices and
// `?E(2, area)` at leaves), and a production matches only the number of
// parameters it names, as cpfg's PredDiff does; so uses with different
// numbers of parameters are not warned about.
static bool IsQueryName(const std::string& name) {
  return name == "?E" || name == "?P" || name == "?H" || name == "?L" || name == "?U";
}

std::optional<SymbolId> GrammarParser::Intern(const Line& l, int col, const std::string& name,
                                              int arity) {
  if (arity > kMaxArity) {
    Error(l, col,
          "module '" + name + "' has more than " + std::to_string(kMaxArity) + " parameters");
    return std::nullopt;
  }
  if ((name == "[" || name == "]" || name == "%") && arity > 0) {
    Error(l, col, "'" + name + "' takes no parameters");
    return std::nullopt;
  }
  auto id = g_.symbols.Intern(name, arity);
  if (!id) {
    Error(l, col, "too many distinct modules (the limit is 65535)");
    return std::nullopt;
  }
  // What Sylva does not act on is said once, at its first use.
  if (auto why = UnsupportedModule(name, arity)) {
    if (unsupportedWarned_.insert(name + '\x01' + *why).second)
      Warn(Loc(l, col), OriginalAt(l, col), *why, int(name.size()));
  }
  // Numbers of parameters per name, for WarnMixedArity once every
  // production is known.
  if (name != "[" && name != "]" && !IsQueryName(name)) {
    ArityUse& use = arityUse_[name];
    if (use.first.emplace(arity, Loc(l, col)).second && use.first.size() == 2)
      arityMixed_.push_back(name);
  }
  return id;
}

// The turtle's commands, which read the parameters they have whatever their
// number (cpfg's `+(20,0)` turns as `+(20)` does).
static bool IsTurtleCommand(const std::string& name) {
  static const std::set<std::string> kCommands = {"F", "f",  "G", "g", "+", "-", "&", "^",
                                                  "/", "\\", "|", "$", "{", "}", ".", "!",
                                                  "#", ";",  ",", "%", "_", "'"};
  return name[0] == '@' || name[0] == '~' || kCommands.count(name) > 0;
}

// One name used with different numbers of parameters is two modules, to
// Sylva as to cpfg's matching (PredDiff compares the count): a production
// naming one does not match the other. That matters only where a
// production's predecessor or context names the module: a warning, at the
// first use with a number that no production names, says so. A name no
// production names (the turtle's `+(20,0)` beside `+(x)`, `{(4)` beside
// `{(2,8)`) is drawn the same either way: no warning.
void GrammarParser::WarnMixedArity() {
  // name -> arity -> the first production naming it so.
  std::unordered_map<std::string, std::map<int, SourceLoc>> named;
  for (const auto* sec : {&g_.main, &g_.decomposition, &g_.interpretation}) {
    for (const Production& p : sec->productions) {
      auto add = [&](SymbolId sym) {
        if (sym == kRestOfBranch) return;  // cpfg's `=`: no module
        named[g_.symbols.name(sym)].emplace(g_.symbols.arity(sym), p.loc);
      };
      add(p.pred.symbol);
      for (const FormalModule& m : p.predTail) add(m.symbol);
      for (const FormalModule& m : p.left) add(m.symbol);
      for (const FormalModule& m : p.right) add(m.symbol);
    }
  }
  auto params = [](int n) { return std::to_string(n) + " parameter" + (n == 1 ? "" : "s"); };
  for (const std::string& name : arityMixed_) {
    const auto found = named.find(name);
    if (found == named.end()) continue;  // no production looks at it
    const std::map<int, SourceLoc>& uses = arityUse_.at(name).first;
    // The first use with a number no production names.
    const std::pair<const int, SourceLoc>* odd = nullptr;
    for (const auto& use : uses) {
      if (found->second.count(use.first)) continue;
      if (!odd || std::make_pair(use.second.line, use.second.column) <
                      std::make_pair(odd->second.line, odd->second.column))
        odd = &use;
    }
    if (!odd) continue;  // a production for every number it is used with
    const auto& [arity, loc] = *found->second.begin();
    std::string msg = "module '" + name + "' is used with " + params(odd->first) +
                      " here, and the production at line " + std::to_string(loc.line) +
                      " names it with " + params(arity) +
                      ": a production matches only the number of parameters it names (as "
                      "cpfg's does), so no production matches this '" +
                      name + "'";
    if (IsTurtleCommand(name))
      msg +=
          " (the turtle draws it either way, reading its first "
          "parameters)";
    Warn(odd->second, g_.SourceLine(odd->second), msg, int(name.size()));
  }
}

// In a cpfg file an unbalanced bracket is a warning (the first one only):
// cpfg reads such a production, and its turtle ignores a `]` with no `[`
// open (interpret.c), as Sylva's does; a `[` never closed ends with the word.
bool GrammarParser::CheckBrackets(const Line& l, const std::vector<SymbolId>& syms,
                                  const std::vector<int>& cols, const char* what) {
  std::vector<int> open;
  auto problem = [&](int col, const std::string& msg) {
    if (!g_.cpfgFile) {
      Error(l, col, msg);
      return false;
    }
    if (!unbalancedWarned_) {
      unbalancedWarned_ = true;
      Warn(Loc(l, col), OriginalAt(l, col),
           msg +
               " (cpfg reads it: its turtle ignores a ']' with no '[' open, and so does "
               "Sylva's; said once)");
    }
    return true;
  };
  for (size_t i = 0; i < syms.size(); ++i) {
    if (syms[i] == kOpenBracket) {
      open.push_back(cols[i]);
    } else if (syms[i] == kCloseBracket) {
      if (open.empty()) {
        if (!problem(cols[i], std::string("unbalanced ']' in ") + what)) return false;
        continue;
      }
      open.pop_back();
    }
  }
  if (!open.empty())
    return problem(open.back(), std::string("unbalanced '[' in ") + what + ": no matching ']'");
  return true;
}

void GrammarParser::UseArrays(const Line& l, ExprScope& scope) {
  scope.arrays = &g_.arrays;
  if (g_.arrays.empty()) return;
  if (!g_.arrayBounds) g_.arrayBounds = std::make_shared<ArrayBounds>();
  scope.arrayBounds = g_.arrayBounds;
  scope.indexSite = [this, &l](int column, const ArrayShape& a, int dimension) {
    return g_.arrayBounds->AddSite(Loc(l, column), std::string(OriginalAt(l, column)), a.name,
                                   dimension, a.dims[size_t(dimension - 1)]);
  };
}

bool GrammarParser::ParseBlockAt(const Line& l, std::string_view view, size_t* pos,
                                 const ExprScope& scope, Expr* out) {
  ExprScope withOutput = Lenient(scope);
  std::vector<ExprParseError> calls;
  withOutput.outputCalls = &calls;
  if (!g_.dataFiles) {
    // cpfg's fopen(NAME, "r"): NAME relative to the grammar file's folder.
    const size_t limit = kMaxDataFileBytes;
    CpfgDataFiles::Reader reader = [this, limit](const std::string& path) -> Expected<std::string> {
      if (opt_.readFile) {
        auto text = opt_.readFile(path);
        if (!text) return MakeError(SourceLoc{path, 0, 0}, "cannot read file");
        if (text->size() > limit)
          return MakeError(SourceLoc{path, 0, 0}, "file is larger than the limit of 16 MiB");
        return std::move(*text);
      }
      return ReadFile(path, limit);
    };
    g_.dataFiles = std::make_shared<CpfgDataFiles>(
        std::filesystem::path(files_.empty() ? std::string() : files_[0]).parent_path().string(),
        std::move(reader));
  }
  withOutput.dataFiles = &g_.dataFiles;
  ExprParseError err;
  if (!ParseBlock(view, pos, withOutput, out, &err)) {
    Error(l, err.column, err.message, err.length);
    return false;
  }
  WarnUndefined(l);
  for (const ExprParseError& c : calls) {
    const std::string name(view.substr(size_t(c.column) - 1, size_t(c.length)));
    if (unsupportedWarned_.insert(name + "\x01output").second)
      Warn(Loc(l, c.column), OriginalAt(l, c.column), c.message, c.length);
  }
  return true;
}

bool GrammarParser::ParseActualWord(const Line& l, size_t pos, size_t end, const ExprScope& scope,
                                    Successor* out) {
  const std::string& t = l.text;
  std::vector<int> cols;
  std::string_view view(t.data(), end);
  for (;;) {
    while (pos < end && IsSpace(t[pos])) ++pos;
    if (pos >= end) break;
    int col = int(pos) + 1;
    if (t[pos] == '{' && IsStatementBlock(view, pos)) {
      if (!scope.locals) {
        Error(l, col, "a statement block belongs in a production, not here");
        return false;
      }
      Successor::Block b;
      b.before = uint32_t(out->symbols.size());
      if (!ParseBlockAt(l, view, &pos, scope, &b.code)) return false;
      out->blocks.push_back(std::move(b));
      out->allConstant = false;
      continue;
    }
    std::string name;
    if (!LexName(l, pos, end, &name)) return false;
    size_t q = pos;
    while (q < end && IsSpace(t[q])) ++q;
    int arity = 0;
    if (q < end && t[q] == '(') {
      pos = q + 1;
      for (;;) {
        Expr e;
        ExprParseError err;
        while (pos < end && IsSpace(t[pos])) ++pos;
        if (pos < end && t[pos] == '"') {
          // cpfg's text parameter (`@L("%.0f", n)`, a label): its value is
          // the string's number in the file, as cpfg's global string index.
          const size_t s0 = pos;
          for (++pos; pos < end && t[pos] != '"'; ++pos)
            if (t[pos] == '\\') ++pos;
          if (pos >= end) {
            Error(l, int(s0) + 1, "unclosed '\"' in parameters of '" + name + "'");
            return false;
          }
          ++pos;
          const std::string text = t.substr(s0 + 1, pos - s0 - 2);
          auto it = std::find(g_.strings.begin(), g_.strings.end(), text);
          const double index = double(it - g_.strings.begin());
          if (it == g_.strings.end()) g_.strings.push_back(text);
          e = Expr::Constant(index);
          if (unsupportedWarned_.insert(name + "\x01string").second && name != "@L")
            Warn(Loc(l, int(s0) + 1), OriginalAt(l, int(s0) + 1),
                 "a text parameter of '" + name + "' is read as the number of the text (" +
                     std::to_string(int(index)) + "), as cpfg does",
                 int(pos - s0));
        } else if (!ParseExpr(view, &pos, Lenient(scope), &e, &err)) {
          Error(l, err.column, err.message, err.length);
          return false;
        }
        WarnUndefined(l);
        if (!e.IsConstant()) out->allConstant = false;
        out->params.push_back(std::move(e));
        ++arity;
        while (pos < end && IsSpace(t[pos])) ++pos;
        if (pos < end && t[pos] == ',') {
          ++pos;
          continue;
        }
        if (pos < end && t[pos] == ')') {
          ++pos;
          break;
        }
        if (pos >= end) {
          Error(l, col + int(name.size()), "unclosed '(' in parameters of '" + name + "'");
        } else {
          Error(l, int(pos) + 1, "expected ',' or ')' in parameters of '" + name + "'");
        }
        return false;
      }
    }
    auto id = Intern(l, col, name, arity);
    if (!id) return false;
    out->symbols.push_back(*id);
    cols.push_back(col);
    if (g_.symbolLoc.find(name) == g_.symbolLoc.end())
      g_.symbolLoc.emplace(name, Grammar::Use{Loc(l, col)});
  }
  return CheckBrackets(l, out->symbols, cols, "word");
}

bool GrammarParser::ParseFormalWord(const Line& l, size_t& pos, size_t end,
                                    std::vector<Formal>* out) {
  const std::string& t = l.text;
  for (;;) {
    while (pos < end && IsSpace(t[pos])) ++pos;
    if (pos >= end || t[pos] == '<' || t[pos] == '>') return true;
    Formal f;
    f.column = int(pos) + 1;
    if (t[pos] == '*') {
      f.wildcard = true;
      ++pos;
      out->push_back(std::move(f));
      continue;
    }
    if (!LexName(l, pos, end, &f.name)) return false;
    size_t q = pos;
    while (q < end && IsSpace(t[q])) ++q;
    if (q < end && t[q] == '(') {
      pos = q + 1;
      for (;;) {
        while (pos < end && IsSpace(t[pos])) ++pos;
        if (pos >= end || !IsIdentStart(t[pos])) {
          Error(l, int(pos) + 1, "expected a formal parameter name in '" + f.name + "(...)'");
          return false;
        }
        size_t s = pos;
        while (pos < end && IsIdentChar(t[pos])) ++pos;
        f.params.push_back(t.substr(s, pos - s));
        while (pos < end && IsSpace(t[pos])) ++pos;
        if (pos < end && t[pos] == ',') {
          ++pos;
          continue;
        }
        if (pos < end && t[pos] == ')') {
          ++pos;
          break;
        }
        Error(l, int(pos) + 1,
              pos >= end ? "unclosed '(' in formal parameters"
                         : "expected ',' or ')' after a formal parameter");
        return false;
      }
    }
    out->push_back(std::move(f));
  }
}

bool GrammarParser::ParseConstExpr(const Line& l, size_t pos, size_t end, double* out,
                                   Expr* exprOut) {
  ExprScope scope{&g_.constants, &usedConstants_, nullptr, &macros_};
  scope.functions = &g_.functions;
  scope.curves = &g_.curves;
  std::string_view view(l.text.data(), end);
  Expr e;
  ExprParseError err;
  if (!ParseExpr(view, &pos, scope, &e, &err)) {
    Error(l, err.column, err.message, err.length);
    return false;
  }
  while (pos < end && IsSpace(l.text[pos])) ++pos;
  if (pos < end) {
    Error(l, int(pos) + 1, "unexpected text after expression");
    return false;
  }
  if (exprOut) {
    *exprOut = e;
    return true;
  }
  if (!e.IsConstant()) {
    Error(l, int(pos) + 1, "expected a constant expression here (no random functions)");
    return false;
  }
  *out = e.constant();
  return true;
}

// ---------------------------------------------------------------------------
// Lines

void GrammarParser::ParseDefine(const Line& l, size_t pos) {
  const std::string& t = l.text;
  pos += 7;  // #define
  while (pos < t.size() && IsSpace(t[pos])) ++pos;
  if (pos >= t.size() || !IsIdentStart(t[pos])) {
    Error(l, int(pos) + 1, "expected a name after #define");
    return;
  }
  size_t s = pos;
  while (pos < t.size() && IsIdentChar(t[pos])) ++pos;
  std::string name = t.substr(s, pos - s);
  int col = int(s) + 1;
  // The grammar's own #define of a function set's name replaces it.
  if (functionSetNames_.erase(name)) g_.constants.erase(name);
  if (pos < t.size() && t[pos] == '(') {
    ParseMacro(l, name, col, pos);
    return;
  }
  if (pos < t.size() && !IsSpace(t[pos])) {
    Error(l, int(pos) + 1, "expected a space after the name of #define '" + name + "'");
    return;
  }
  while (pos < t.size() && IsSpace(t[pos])) ++pos;
  size_t end = t.size();
  while (end > pos && IsSpace(t[end - 1])) --end;
  const std::string text = CollapseBlanks(std::string_view(t).substr(pos, end - pos));
  if (defines_.count(name) && !Redefine(l, name, col, text)) return;
  if (cppNames_.count(name)) {
    // Defined twice or #undef'd in a cpfg file: text, as C's preprocessor
    // (an empty one for `#define NAME` alone). -D replaces every value.
    TextMacro m;
    m.body = t.substr(pos, end - pos);
    auto ov = opt_.overrides.find(name);
    if (ov != opt_.overrides.end()) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "(%.17g)", ov->second);
      m.body = buf;
      usedOverrides_.insert(name);
    }
    m.line = Loc(l, col).line;
    textMacros_[name] = std::move(m);
    defines_[name] = Define{Loc(l, col), int(name.size()), text};
    return;
  }
  if (pos >= t.size()) {
    // `#define NAME` alone: defined for #ifdef, with no value.
    defines_[name] = Define{Loc(l, col), int(name.size()), text};
    return;
  }
  {
    // Not an expression (it does not parse, names what is not a constant,
    // or goes on after one), or one that draws random numbers (`nran(80,
    // 4)`: cpfg's preprocessor pastes the text, so each use draws anew):
    // text, substituted where the name is used.
    ExprScope scope{&g_.constants, nullptr, nullptr, &macros_};
    scope.functions = &g_.functions;
    scope.curves = &g_.curves;
    std::string_view view(t.data(), end);
    Expr e;
    ExprParseError err;
    size_t q = pos;
    bool isExpr = ParseExpr(view, &q, scope, &e, &err);
    while (isExpr && q < end && IsSpace(t[q])) ++q;
    if ((!isExpr && !err.evaluation) || (isExpr && q < end) || (isExpr && !e.IsConstant())) {
      TextMacro m;
      m.body = t.substr(pos, end - pos);
      AddTextMacro(l, name, col, std::move(m), text);
      return;
    }
  }
  double v;
  if (!ParseConstExpr(l, pos, t.size(), &v)) return;
  auto ov = opt_.overrides.find(name);
  if (ov != opt_.overrides.end()) {
    v = ov->second;
    usedOverrides_.insert(name);
  }
  g_.constants[name] = v;
  defines_[name] = Define{Loc(l, col), int(name.size()), text};
}

bool GrammarParser::Redefine(const Line& l, const std::string& name, int col,
                             const std::string& text) {
  const Define& first = defines_[name];
  const std::string where = first.loc.file + ":" + std::to_string(first.loc.line) + ":" +
                            std::to_string(first.loc.column);
  if (!g_.cpfgFile) {
    Error(l, col,
          "redefinition of '" + name + "' (first defined at line " +
              std::to_string(first.loc.line) + ")",
          int(name.size()));
    return false;
  }
  if (text != first.text) {
    Warn(Loc(l, col), OriginalAt(l, col),
         "'" + name +
             "' redefined: this definition holds from here on, as cpfg's C "
             "preprocessor has it (the first is at " +
             where + ")",
         int(name.size()));
  }
  // Every #define of a name in cppNames_ is text; forget the first.
  textMacros_.erase(name);
  macros_.erase(name);
  g_.constants.erase(name);
  defines_.erase(name);
  return true;
}

void GrammarParser::FindCppNames() {
  if (!g_.cpfgFile) return;
  std::unordered_map<std::string, int> defines;
  for (const Line& l : lines_) {
    const std::string& t = l.text;
    size_t p = 0;
    while (p < t.size() && IsSpace(t[p])) ++p;
    if (!StartsDirective(t, p)) continue;
    ++p;
    while (p < t.size() && IsSpace(t[p])) ++p;
    size_t e = p;
    while (e < t.size() && IsIdentChar(t[e])) ++e;
    const std::string_view word = std::string_view(t).substr(p, e - p);
    if (word != "define" && word != "undef") continue;
    while (e < t.size() && IsSpace(t[e])) ++e;
    size_t n = e;
    while (n < t.size() && IsIdentChar(t[n])) ++n;
    if (n == e) continue;
    std::string name = t.substr(e, n - e);
    if (word == "undef" || ++defines[name] > 1) cppNames_.insert(std::move(name));
  }
}

// `#define NAME(a, b) body` (the `(` right after the name, as in C): a
// function of its parameters, the body checked now with them as its only
// names besides constants and earlier macros.
void GrammarParser::ParseMacro(const Line& l, const std::string& name, int col, size_t pos) {
  const std::string& t = l.text;
  ExprMacro m;
  ++pos;  // '('
  for (;;) {
    while (pos < t.size() && IsSpace(t[pos])) ++pos;
    if (m.params.empty() && pos < t.size() && t[pos] == ')') {
      ++pos;
      break;
    }
    if (pos >= t.size() || !IsIdentStart(t[pos])) {
      Error(l, int(pos) + 1, "expected a parameter name in '#define " + name + "(...)'");
      return;
    }
    const size_t s = pos;
    while (pos < t.size() && IsIdentChar(t[pos])) ++pos;
    std::string param = t.substr(s, pos - s);
    if (std::find(m.params.begin(), m.params.end(), param) != m.params.end()) {
      Error(l, int(s) + 1, "parameter '" + param + "' appears twice", int(param.size()));
      return;
    }
    m.params.push_back(std::move(param));
    while (pos < t.size() && IsSpace(t[pos])) ++pos;
    if (pos < t.size() && t[pos] == ',') {
      ++pos;
      continue;
    }
    if (pos < t.size() && t[pos] == ')') {
      ++pos;
      break;
    }
    Error(l, int(pos) + 1, "expected ',' or ')' after a parameter of '#define " + name + "'");
    return;
  }
  while (pos < t.size() && IsSpace(t[pos])) ++pos;
  size_t end = t.size();
  while (end > pos && IsSpace(t[end - 1])) --end;
  std::string text = "(";
  for (const std::string& p : m.params) text += (text.size() > 1 ? "," : "") + p;
  text += ") " + CollapseBlanks(std::string_view(t).substr(pos, end - pos));
  if (defines_.count(name) && !Redefine(l, name, col, text)) return;
  if (pos >= end) {
    Error(l, col, "#define '" + name + "' has no body", int(name.size()));
    return;
  }
  if (cppNames_.count(name)) {  // defined twice or #undef'd in a cpfg file: text
    TextMacro tm;
    tm.function = true;
    tm.params = std::move(m.params);
    tm.body = t.substr(pos, end - pos);
    tm.line = Loc(l, col).line;
    textMacros_[name] = std::move(tm);
    defines_[name] = Define{Loc(l, col), int(name.size()), text};
    return;
  }
  // Check the body where it is written, its parameters standing as formals.
  ExprScope scope{&g_.constants, &usedConstants_, &m.params, &macros_};
  scope.functions = &g_.functions;
  scope.curves = &g_.curves;
  std::string_view view(t.data(), end);
  Expr body;
  ExprParseError err;
  size_t q = pos;
  bool isExpr = ParseExpr(view, &q, scope, &body, &err);
  while (isExpr && q < end && IsSpace(t[q])) ++q;
  if (!isExpr && err.evaluation) {
    Error(l, err.column, err.message, err.length);
    return;
  }
  if (!isExpr || q < end) {
    // Not an expression of its parameters: text, substituted where used
    // with the arguments in place of the parameters (cpfg's preprocessor).
    TextMacro tm;
    tm.function = true;
    tm.params = std::move(m.params);
    tm.body = t.substr(pos, end - pos);
    AddTextMacro(l, name, col, std::move(tm), text);
    return;
  }
  m.body = t.substr(pos, end - pos);
  macros_.emplace(name, std::move(m));
  defines_[name] = Define{Loc(l, col), int(name.size()), text};
}

// `#undef NAME`: a text #define is forgotten from here on (lines are
// substituted in order); a name never defined is no error, as in C. In a
// .lsys file a constant or an expression #define is read before any
// production, so it cannot be undone for the lines below only: an error
// (in a cpfg file every #define of a name #undef'd is text: cppNames_).
void GrammarParser::ParseUndef(const Line& l, size_t after) {
  const std::string& t = l.text;
  size_t q = after;
  while (q < t.size() && IsSpace(t[q])) ++q;
  size_t e = q;
  while (e < t.size() && IsIdentChar(t[e])) ++e;
  if (e == q) {
    Error(l, int(q) + 1, "expected a name after #undef");
    return;
  }
  const std::string name = t.substr(q, e - q);
  if (functionSetNames_.erase(name)) {  // a function set's name, as a -D of cpfg's
    g_.constants.erase(name);
    return;
  }
  if (textMacros_.erase(name)) {
    defines_.erase(name);
    return;
  }
  if (defines_.count(name)) {
    Error(l, int(q) + 1,
          "#undef of '" + name +
              "' is not supported: a #define that is a number or an expression holds for the "
              "whole file",
          int(name.size()));
  }
}

void GrammarParser::AddTextMacro(const Line& l, const std::string& name, int col, TextMacro m,
                                 const std::string& text) {
  if (opt_.overrides.count(name)) {
    usedOverrides_.insert(name);
    Error(l, col,
          "-D " + name + ": '#define " + name +
              "' is text (a piece of a word), not a number, and cannot be overridden",
          int(name.size()));
    return;
  }
  m.line = Loc(l, col).line;
  textMacros_[name] = std::move(m);
  defines_[name] = Define{Loc(l, col), int(name.size()), text};
}

namespace {

// The end of the "..." string literal that starts at s[i] (just past it).
size_t SkipString(std::string_view s, size_t i) {
  for (++i; i < s.size(); ++i) {
    if (s[i] == '\\') {
      ++i;
    } else if (s[i] == '"') {
      return i + 1;
    }
  }
  return s.size();
}

// `text` with every identifier in `params` replaced by the same-index `args`.
std::string SubstituteParams(std::string_view text, const std::vector<std::string>& params,
                             const std::vector<std::string>& args) {
  std::string r;
  for (size_t i = 0; i < text.size();) {
    if (text[i] == '"') {
      const size_t e = SkipString(text, i);
      r.append(text.substr(i, e - i));
      i = e;
      continue;
    }
    if (!IsIdentStart(text[i]) || (i > 0 && IsIdentChar(text[i - 1]))) {
      r += text[i++];
      continue;
    }
    size_t e = i;
    while (e < text.size() && IsIdentChar(text[e])) ++e;
    const std::string_view word = text.substr(i, e - i);
    auto it = std::find(params.begin(), params.end(), word);
    if (it != params.end()) {
      r += args[size_t(it - params.begin())];
    } else {
      r.append(word);
    }
    i = e;
  }
  return r;
}

}  // namespace

// Substitutes the text #defines in `s` as cpfg's (C's) preprocessor does:
// identifiers only, not inside "strings"; a NAME(a, b) #define only where
// its name is followed by '(' and its arguments (themselves expanded first);
// the result rescanned with the #define being expanded hidden, so a
// #define that names itself stops. `uses` (top level only) receives where
// each use was. On failure *problem says why and *problemAt is where in `s`.
// A line with its text #defines substituted is at most this long (nested
// #defines can double the text at each level).
constexpr size_t kMaxExpandedLine = size_t(1) << 20;

bool GrammarParser::ExpandText(std::string_view s, std::vector<std::string>& hiding, int depth,
                               std::string* out, std::vector<Line::Expansion>* uses,
                               size_t* problemAt, std::string* problem) {
  constexpr int kMaxDepth = 64;
  for (size_t i = 0; i < s.size();) {
    if (s[i] == '"') {
      const size_t e = SkipString(s, i);
      out->append(s.substr(i, e - i));
      i = e;
      continue;
    }
    if (!IsIdentStart(s[i]) || (i > 0 && IsIdentChar(s[i - 1]))) {
      *out += s[i++];
      continue;
    }
    size_t e = i;
    while (e < s.size() && IsIdentChar(s[e])) ++e;
    const std::string name(s.substr(i, e - i));
    auto it = textMacros_.find(name);
    if (it == textMacros_.end() || std::find(hiding.begin(), hiding.end(), name) != hiding.end()) {
      out->append(name);
      i = e;
      continue;
    }
    const TextMacro& m = it->second;
    if (depth >= kMaxDepth) {
      *problemAt = i;
      *problem =
          "#define '" + name + "' expands more than " + std::to_string(kMaxDepth) + " levels deep";
      return false;
    }
    std::string text = m.body;
    size_t useEnd = e;
    if (m.function) {
      size_t q = e;
      while (q < s.size() && IsSpace(s[q])) ++q;
      if (q >= s.size() || s[q] != '(') {  // the name alone is not a use (as in C)
        out->append(name);
        i = e;
        continue;
      }
      // The arguments: split at commas outside parentheses and brackets.
      std::vector<std::string> args;
      int nest = 0;
      size_t a = q + 1;
      size_t c = q + 1;
      for (; c < s.size(); ++c) {
        const char ch = s[c];
        if (ch == '"') {
          c = SkipString(s, c) - 1;
        } else if (ch == '(' || ch == '[' || ch == '{') {
          ++nest;
        } else if ((ch == ')' || ch == ']' || ch == '}') && nest > 0) {
          --nest;
        } else if (ch == ')' || (ch == ',' && nest == 0)) {
          std::string arg;
          if (!ExpandText(s.substr(a, c - a), hiding, depth + 1, &arg, nullptr, problemAt,
                          problem)) {
            *problemAt = i;
            return false;
          }
          const size_t b = arg.find_first_not_of(" \t");
          arg = b == std::string::npos ? std::string() : arg.substr(b);
          while (!arg.empty() && IsSpace(arg.back())) arg.pop_back();
          args.push_back(std::move(arg));
          a = c + 1;
          if (ch == ')') break;
        }
      }
      if (c >= s.size()) {
        *problemAt = i;
        *problem = "unclosed '(' in the use of '#define " + name + "'";
        return false;
      }
      if (args.size() == 1 && args[0].empty() && m.params.empty()) args.clear();
      if (args.size() != m.params.size()) {
        *problemAt = i;
        *problem = "'#define " + name + "' takes " + std::to_string(m.params.size()) +
                   " arguments, given " + std::to_string(args.size());
        return false;
      }
      text = SubstituteParams(m.body, m.params, args);
      useEnd = c + 1;
    }
    usedConstants_.insert(name);
    hiding.push_back(name);
    const size_t at = out->size();
    bool ok = ExpandText(text, hiding, depth + 1, out, nullptr, problemAt, problem);
    hiding.pop_back();
    if (ok && out->size() > kMaxExpandedLine) {
      ok = false;
      *problem = "the #defines on this line expand to more than " + SizeText(kMaxExpandedLine);
    }
    if (!ok) {
      *problemAt = i;
      return false;
    }
    if (uses)
      uses->push_back(
          Line::Expansion{int(at), int(out->size() - at), int(i), int(useEnd - i), name, m.line});
    i = useEnd;
  }
  return true;
}

void GrammarParser::ExpandTextMacros(Line& l) {
  if (textMacros_.empty()) return;
  std::string out;
  std::vector<Line::Expansion> uses;
  std::vector<std::string> hiding;
  size_t at = 0;
  std::string problem;
  if (!ExpandText(l.text, hiding, 0, &out, &uses, &at, &problem)) {
    Error(l, int(at) + 1, problem);
    return;
  }
  if (uses.empty()) return;
  l.text = std::move(out);
  l.expansions = std::move(uses);
}

// Header statements: "keyword:" at the start of a line, case-insensitive.
void GrammarParser::ParseAxiom(const Line& l, int col, size_t after, size_t end) {
  if (haveAxiom_) {
    Error(l, col, "second axiom (the first is at line " + std::to_string(axiomLoc_.line) + ")", 5);
    return;
  }
  ExprScope scope{&g_.constants, &usedConstants_, nullptr, &macros_};
  scope.functions = &g_.functions;
  scope.curves = &g_.curves;
  scope.globals = &g_.globals;
  UseArrays(l, scope);
  Successor s;
  if (!ParseActualWord(l, after, end, scope, &s)) return;
  if (s.symbols.empty()) {
    Error(l, col, "empty axiom", 5);
    return;
  }
  haveAxiom_ = true;
  axiomLoc_ = Loc(l, int(after) + 1);
  axiom_ = std::move(s);
  return;
}

void GrammarParser::ParseContextNames(const Line& l, size_t after, size_t end, bool ignore) {
  const std::string& t = l.text;
  (ignore ? haveIgnore_ : haveConsider_) = true;
  size_t p = after;
  while (p < end) {
    if (IsSpace(t[p])) {
      ++p;
      continue;
    }
    std::string name;
    if (!LexName(l, p, end, &name)) return;
    // Brackets too: as in cpfg, an ignored `[` or `]` (or one that
    // `consider:` does not name) is passed over by right contexts, which
    // then read into and out of branches; left contexts always follow the
    // branching (matcher.h).
    (ignore ? ignoreNames_ : considerNames_).insert(name);
  }
  return;
}

void GrammarParser::ParsePalette(const Line& l, int col, size_t after, size_t end) {
  const std::string& t = l.text;
  size_t q = after;
  g_.palette.clear();
  while (q < end) {
    while (q < end && (IsSpace(t[q]) || t[q] == ',')) ++q;
    if (q >= end) break;
    size_t s0 = q;
    while (q < end && !IsSpace(t[q]) && t[q] != ',') ++q;
    std::string tok = t.substr(s0, q - s0);
    bool ok = tok.size() == 7 && tok[0] == '#';
    for (size_t i = 1; ok && i < 7; ++i) ok = std::isxdigit(static_cast<unsigned char>(tok[i]));
    if (!ok) {
      Error(l, int(s0) + 1, "expected a colour as #rrggbb in 'palette:'", int(tok.size()));
      return;
    }
    std::array<float, 3> c;
    for (int i = 0; i < 3; ++i)
      c[size_t(i)] = float(std::stoi(tok.substr(1 + 2 * size_t(i), 2), nullptr, 16)) / 255.0f;
    g_.palette.push_back(c);
  }
  if (g_.palette.empty()) Error(l, col, "'palette:' needs at least one colour", 8);
  return;
}

void GrammarParser::ParseTropism(const Line& l, size_t after, size_t end) {
  const std::string& t = l.text;
  // Four numbers separated by commas or spaces.
  std::vector<std::pair<size_t, size_t>> parts;
  bool commas = t.find(',', after) < end;
  size_t p = after;
  while (p < end) {
    while (p < end && (IsSpace(t[p]) || (commas && t[p] == ','))) ++p;
    if (p >= end) break;
    size_t s = p;
    if (commas) {
      while (p < end && t[p] != ',') ++p;
    } else {
      while (p < end && !IsSpace(t[p])) ++p;
    }
    parts.emplace_back(s, p);
  }
  if (parts.size() != 4) {
    Error(l, int(after) + 1, "tropism needs four numbers: X Y Z susceptibility");
    return;
  }
  double v[4];
  for (int i = 0; i < 4; ++i) {
    if (!ParseConstExpr(l, parts[i].first, parts[i].second, &v[i])) return;
  }
  if (v[0] == 0 && v[1] == 0 && v[2] == 0) {
    Error(l, int(after) + 1, "tropism vector is zero");
    return;
  }
  g_.tropism = Tropism{v[0], v[1], v[2], v[3]};
  return;
}

// `environment: KIND ITEM ...`, each item `key=EXPR`, `name(EXPR, ...)` or
// a bare word; the meaning is the plant library's (plant/environment.h).
void GrammarParser::ParseEnvironment(const Line& l, int col, size_t after, size_t end) {
  const std::string& t = l.text;
  if (g_.environment) {
    Error(l, col,
          "a second 'environment:' (the first is at line " +
              std::to_string(g_.environment->loc.line) + "); a grammar has one environment",
          11);
    return;
  }
  EnvironmentStatement env;
  auto word = [&](size_t& p) {
    const size_t s = p;
    while (p < end && IsIdentChar(t[p])) ++p;
    return t.substr(s, p - s);
  };
  size_t p = after;
  if (p >= end || !IsIdentStart(t[p])) {
    Error(l, int(p) + 1, "expected the kind of environment (shape, light) after 'environment:'");
    return;
  }
  env.loc = Loc(l, int(p) + 1);
  env.kind = word(p);
  ExprScope scope{&g_.constants, &usedConstants_, nullptr, &macros_};
  const std::string_view view(t.data(), end);
  auto constant = [&](size_t& q, double* out) {
    Expr e;
    ExprParseError err;
    if (!ParseExpr(view, &q, scope, &e, &err)) {
      Error(l, err.column, err.message, err.length);
      return false;
    }
    if (!e.IsConstant()) {
      Error(l, int(q) + 1, "expected a constant expression here (no random functions)");
      return false;
    }
    *out = e.constant();
    return true;
  };
  while (true) {
    while (p < end && (IsSpace(t[p]) || t[p] == ',')) ++p;
    if (p >= end) break;
    if (!IsIdentStart(t[p])) {
      Error(l, int(p) + 1,
            "unexpected character '" + Printable(t[p]) +
                "' in 'environment:'; expected key=value, name(values) or a word");
      return;
    }
    EnvironmentStatement::Item item;
    item.loc = Loc(l, int(p) + 1);
    item.name = word(p);
    if (p < end && t[p] == '=') {
      ++p;
      item.keyValue = true;
      item.values.emplace_back();
      if (!constant(p, &item.values.back())) return;
    } else if (p < end && t[p] == '(') {
      item.call = true;
      ++p;
      while (true) {
        item.values.emplace_back();
        if (!constant(p, &item.values.back())) return;
        while (p < end && IsSpace(t[p])) ++p;
        if (p < end && t[p] == ',') {
          ++p;
          continue;
        }
        if (p < end && t[p] == ')') {
          ++p;
          break;
        }
        Error(l, int(p) + 1, "expected ',' or ')' in '" + item.name + "(...)'");
        return;
      }
    }
    env.items.push_back(std::move(item));
  }
  g_.environment = std::move(env);
}

void GrammarParser::ParseNumberStatement(const Line& l, const std::string& k, size_t after,
                                         size_t end) {
  double v;
  if (!ParseConstExpr(l, after, end, &v)) return;
  int vcol = int(after) + 1;
  if (k == "derivation length") {
    if (v != std::floor(v) || v < 0 || v > kMaxDerivationLength) {
      Error(l, vcol,
            "derivation length must be a whole number from 0 to " +
                std::to_string(kMaxDerivationLength));
      return;
    }
    g_.derivationLength = int(v);
  } else if (k == "angle") {
    g_.angle = v;
  } else if (k == "step") {
    g_.step = v;
  } else if (k == "width") {
    g_.width = v;
  } else if (k == "width factor") {
    g_.widthFactor = v;
  } else if (k == "width increment") {
    if (!(v > 0)) {
      Error(l, vcol, "width increment must be positive");
      return;
    }
    g_.widthIncrement = v;
  } else if (k == "width scale") {
    if (!(v > 0)) {
      Error(l, vcol, "width scale must be positive");
      return;
    }
    g_.widthScale = v;
  } else if (k == "seed") {
    if (v != std::floor(v) || v < 0 || v > 18446744073709549568.0) {
      Error(l, vcol, "seed must be a whole number >= 0");
      return;
    }
    g_.seed = uint64_t(v);
  }
}

// The preprocessor's conditionals, in file order: `#if EXPR` (constants
// and `defined(NAME)`), `#ifdef NAME`, `#ifndef NAME`, `#elif EXPR`,
// `#else`, `#endif`. Lines of a branch not taken are dropped; #define lines
// of the branches taken are read here, in order, so a condition sees the
// #defines above it. (#include is spliced before: a file included in a
// branch not taken is still read, and must exist.)
void GrammarParser::Conditionals() {
  struct Open {
    bool active;  // this branch is taken (and every enclosing one)
    bool taken;   // some branch of this #if was taken
    bool sawElse;
    bool parentActive;
    Line line;  // of the #if, for the error when it is not closed
    int column;
  };
  std::vector<Open> stack;
  std::vector<Line> kept;
  kept.reserve(lines_.size());
  FindCppNames();
  // `lsystem:` lines still ahead: after `endlsystem`, #defines count only
  // when another block follows (they are that block's, as vlab's Sedge
  // #includes each sub-L-system's file, its #defines first); after the last
  // block nothing is read (it is warned about).
  int blocksAhead = 0;
  for (const Line& l : lines_) {
    size_t p = 0, kwAfter = 0;
    while (p < l.text.size() && IsSpace(l.text[p])) ++p;
    const char* kw = MatchKeyword(l.text, p, &kwAfter);
    if (kw && std::string_view(kw) == "lsystem") ++blocksAhead;
  }
  bool ended = false;
  auto active = [&]() { return stack.empty() || stack.back().active; };
  // The directive word at the start of a line ("if", "ifdef", ...), or "".
  auto directive = [](const std::string& t, size_t* pos, size_t* after) {
    size_t p = 0;
    while (p < t.size() && IsSpace(t[p])) ++p;
    *pos = p;
    if (!StartsDirective(t, p)) return std::string();
    size_t q = p + 1;
    while (q < t.size() && IsSpace(t[q])) ++q;
    size_t e = q;
    while (e < t.size() && IsIdentChar(t[e])) ++e;
    *after = e;
    return t.substr(q, e - q);
  };
  // The value of `#if`/`#elif` text from `after` on.
  auto condition = [&](Line& l, size_t after) -> bool {
    // defined(NAME) and defined NAME become 1 or 0, padded to keep columns.
    std::string& t = l.text;
    for (size_t i = after; (i = t.find("defined", i)) != std::string::npos;) {
      if ((i > 0 && IsIdentChar(t[i - 1])) || (i + 7 < t.size() && IsIdentChar(t[i + 7]))) {
        i += 7;
        continue;
      }
      size_t q = i + 7;
      while (q < t.size() && IsSpace(t[q])) ++q;
      const bool paren = q < t.size() && t[q] == '(';
      if (paren) ++q;
      while (q < t.size() && IsSpace(t[q])) ++q;
      size_t e = q;
      while (e < t.size() && IsIdentChar(t[e])) ++e;
      std::string name = t.substr(q, e - q);
      if (name.empty()) {
        Error(l, int(q) + 1, "expected a name after 'defined'");
        return false;
      }
      if (paren) {
        while (e < t.size() && IsSpace(t[e])) ++e;
        if (e >= t.size() || t[e] != ')') {
          Error(l, int(e) + 1, "expected ')' after 'defined(" + name + "'");
          return false;
        }
        ++e;
      }
      usedConstants_.insert(name);
      const bool is = defines_.count(name) > 0;
      t.replace(i, e - i, std::string(1, is ? '1' : '0') + std::string(e - i - 1, ' '));
      i = e;
    }
    ExpandTextMacros(l);  // as C's #if: text #defines are substituted
    double v = 0;
    if (!ParseConstExpr(l, after, t.size(), &v)) return false;
    return v != 0;
  };
  for (Line& l : lines_) {
    size_t pos = 0, after = 0;
    const std::string d = directive(l.text, &pos, &after);
    const int col = int(pos) + 1;
    if (d == "if" || d == "ifdef" || d == "ifndef") {
      Open o{false, false, false, active(), l, col};
      if (o.parentActive) {
        bool v = false;
        if (d == "if") {
          v = condition(l, after);
        } else {
          size_t q = after;
          while (q < l.text.size() && IsSpace(l.text[q])) ++q;
          size_t e = q;
          while (e < l.text.size() && IsIdentChar(l.text[e])) ++e;
          if (e == q) {
            Error(l, int(q) + 1, "expected a name after #" + d);
          } else {
            const std::string name = l.text.substr(q, e - q);
            usedConstants_.insert(name);
            v = (defines_.count(name) > 0) == (d == "ifdef");
          }
        }
        o.active = o.taken = v;
      }
      o.line.text.clear();
      stack.push_back(std::move(o));
      continue;
    }
    if (d == "elif" || d == "else" || d == "endif") {
      if (stack.empty()) {
        Error(l, col, "#" + d + " without #if", int(after - pos));
        continue;
      }
      Open& o = stack.back();
      if (d == "endif") {
        stack.pop_back();
        continue;
      }
      if (o.sawElse) {
        Error(l, col, "#" + d + " after #else", int(after - pos));
        continue;
      }
      if (d == "else") {
        o.sawElse = true;
        o.active = o.parentActive && !o.taken;
        o.taken = true;
        continue;
      }
      o.active = false;
      if (o.parentActive && !o.taken) o.active = o.taken = condition(l, after);
      continue;
    }
    if (!active()) continue;
    if (d == "define" && (!ended || blocksAhead > 0)) {
      ParseDefine(l, pos);
      continue;
    }
    if (d == "undef" && (!ended || blocksAhead > 0)) {
      ParseUndef(l, after);
      continue;
    }
    if (d.empty()) ExpandTextMacros(l);
    if (d.empty()) {
      size_t p = 0, kwAfter = 0;
      while (p < l.text.size() && IsSpace(l.text[p])) ++p;
      const char* kw = MatchKeyword(l.text, p, &kwAfter);
      if (kw && std::string_view(kw) == "endlsystem") ended = true;
      if (kw && std::string_view(kw) == "lsystem") ended = false, --blocksAhead;
    }
    kept.push_back(std::move(l));
  }
  for (const Open& o : stack) Error(o.line, o.column, "#if without #endif", 3);
  lines_ = std::move(kept);
}

// ParseOptions::functionFiles (a view file's `function:` lines), unless
// the grammar says `functions:` itself. Errors point at the naming line.
void GrammarParser::LoadOptionFunctions() {
  if (opt_.functionFiles.empty()) return;
  for (const Line& l : lines_) {
    size_t p = 0, after = 0;
    while (p < l.text.size() && IsSpace(l.text[p])) ++p;
    const char* kw = MatchKeyword(l.text, p, &after);
    if (kw && std::string_view(kw) == "functions") return;
  }
  for (const ParseOptions::FunctionFile& ff : opt_.functionFiles) {
    std::string why;
    auto text = Read(ff.file, &why);
    std::string problem;
    const char* kind = ff.set ? "function set" : "function file";
    if (!text) {
      problem = std::string("cannot read ") + kind + " '" + ff.file + "': " + why;
    } else if (ff.set) {
      auto set = CpfgFunction::ParseSet(*text, ff.file);
      if (!set) {
        problem = "in function set " + ff.file + ":" + std::to_string(set.error().loc.line) + ": " +
                  set.error().message;
      } else {
        for (CpfgFunction& f : *set) {
          // cpfg's -DNAME=i for each function of the set (a name that is
          // not an identifier cannot be written in a grammar: not defined).
          const std::string name = f.name();
          g_.functions.push_back(std::make_shared<const CpfgFunction>(std::move(f)));
          if (name.empty() || !IsIdentStart(name[0]) ||
              !std::all_of(name.begin(), name.end(), IsIdentChar))
            continue;
          g_.constants[name] = double(g_.functions.size());
          functionSetNames_.insert(name);
        }
        continue;
      }
    } else if (auto f = CpfgFunction::Parse(*text, ff.file); !f) {
      problem = "in function file " + ff.file + ":" + std::to_string(f.error().loc.line) + ": " +
                f.error().message;
    } else {
      g_.functions.push_back(std::make_shared<const CpfgFunction>(std::move(f).value()));
      continue;
    }
    // Every file that fails is reported; func() ids are then not checked
    // (their numbers would be off), see Error().
    diags_.Add(MakeError(SourceLoc{ff.from, ff.line, ff.column}, problem));
    functionFilesFailed_ = true;
  }
}

// ParseOptions::curveFiles (a view file's `curve:` lines). Errors point at
// the naming line.
void GrammarParser::LoadOptionCurves() {
  for (const ParseOptions::CurveFile& cf : opt_.curveFiles) {
    std::string why;
    auto text = Read(cf.file, &why);
    std::string problem;
    if (!text) {
      problem = "cannot read curve file '" + cf.file + "': " + why;
    } else if (auto c = CpfgCurve::Parse(*text, cf.file, cf.samples); !c) {
      problem = "in curve file " + cf.file + ":" + std::to_string(c.error().loc.line) + ": " +
                c.error().message;
    } else {
      g_.curves.push_back(std::make_shared<const CpfgCurve>(std::move(c).value()));
      continue;
    }
    diags_.Add(MakeError(SourceLoc{cf.from, cf.line, cf.column}, problem));
    curveFilesFailed_ = true;
  }
}

// `functions: a.func b.func`: cpfg function files, func(1, x) is the first.
// Names are relative to the grammar file. They replace those a view file
// names (ParseOptions::functionFiles).
void GrammarParser::ParseFunctions(const Line& l, size_t after, size_t end) {
  const std::string& t = l.text;
  size_t p = after;
  while (p < end) {
    while (p < end && IsSpace(t[p])) ++p;
    if (p >= end) break;
    const bool quoted = t[p] == '"';
    size_t s = quoted ? p + 1 : p;
    size_t e = s;
    while (e < end && (quoted ? t[e] != '"' : !IsSpace(t[e]))) ++e;
    const std::string name = t.substr(s, e - s);
    const int col = int(p) + 1, len = int(e - p) + (quoted ? 1 : 0);
    p = quoted ? e + 1 : e;
    if (name.empty()) {
      Error(l, col, "empty function file name");
      return;
    }
    std::filesystem::path target(name);
    if (target.is_relative())
      target = std::filesystem::path(files_[size_t(l.file)]).parent_path() / target;
    const std::string resolved = target.lexically_normal().string();
    std::string why;
    auto text = Read(resolved, &why);
    if (!text) {
      Error(l, col, "cannot read function file '" + resolved + "': " + why, len);
      return;
    }
    auto f = CpfgFunction::Parse(*text, resolved);
    if (!f) {
      Error(l, col,
            "in function file " + resolved + ":" + std::to_string(f.error().loc.line) + ": " +
                f.error().message,
            len);
      return;
    }
    g_.functions.push_back(std::make_shared<const CpfgFunction>(std::move(f).value()));
  }
}

// `Start: { ... }` and the like: statements over the global variables.
void GrammarParser::ParseGlobalBlock(const Line& l, const std::string& k, size_t after,
                                     size_t end) {
  const std::string& t = l.text;
  std::optional<Expr>* slot = k == "start"       ? &g_.startBlock
                              : k == "end"       ? &g_.endBlock
                              : k == "starteach" ? &g_.startEachBlock
                                                 : &g_.endEachBlock;
  const char* shown = k == "start"       ? "Start"
                      : k == "end"       ? "End"
                      : k == "starteach" ? "StartEach"
                                         : "EndEach";
  if (*slot) {
    Error(l, int(after), std::string("a second '") + shown + ":' block");
    return;
  }
  if (after >= end || t[after] != '{') {
    Error(l, int(after) + 1, std::string("expected '{' after '") + shown + ":'");
    return;
  }
  ExprScope scope{&g_.constants, &usedConstants_, nullptr, &macros_};
  scope.functions = &g_.functions;
  scope.curves = &g_.curves;
  scope.globals = &g_.globals;
  UseArrays(l, scope);
  HiddenGlobalSlots(t, after, k == "start", &scope);
  std::string_view view(t.data(), end);
  size_t pos = after;
  Expr block;
  if (!ParseBlockAt(l, view, &pos, scope, &block)) return;
  while (pos < end && (IsSpace(t[pos]) || t[pos] == ';')) ++pos;
  if (pos < end) {
    Error(l, int(pos) + 1, std::string("unexpected text after the '") + shown + ":' block");
    return;
  }
  *slot = std::move(block);
}

// cpfg's srand(seed) and stop(v) in a block of line text t (from `from`
// on): each stores its value in a hidden global, made at its first use, NaN
// until called. srand in Start: sets the derivation's seed; anywhere else
// it reseeds the derivation from there on (Grammar::reseeds).
void GrammarParser::HiddenGlobalSlots(const std::string& t, size_t from, bool start,
                                      ExprScope* scope) {
  auto slot = [&](const char* name, int* index) {
    if (*index < 0) {
      *index = int(g_.globals.size());
      g_.globals.push_back(name);
      g_.globalInitial.resize(g_.globals.size(), 0.0);
      g_.globalInitial.back() = std::numeric_limits<double>::quiet_NaN();  // not called
    }
    return *index;
  };
  // `name (` as a word of its own.
  auto calls = [&](std::string_view name) {
    for (size_t i = t.find(name, from); i != std::string::npos; i = t.find(name, i + 1)) {
      if (i > 0 && IsIdentChar(t[i - 1])) continue;
      size_t q = i + name.size();
      while (q < t.size() && IsSpace(t[q])) ++q;
      if (q < t.size() && t[q] == '(') return true;
    }
    return false;
  };
  if (calls("srand")) {
    scope->srandSlot = slot("srand()", &g_.srandGlobal);
    if (!start) g_.reseeds = true;
  }
  if (calls("stop")) scope->stopSlot = slot("stop()", &g_.stopGlobal);
}

// cpfg's `define: { array a[3], b[2][2] = {1, 2, 3, 4}; array c[4]; }`:
// arrays of global variables, 0 unless initialised (in row-major order; a
// shorter list leaves the rest 0). Sizes and values are constant
// expressions.
void GrammarParser::ParseArrays(const Line& l, size_t after, size_t end) {
  const std::string& t = l.text;
  size_t p = after;
  auto space = [&] {
    while (p < end && IsSpace(t[p])) ++p;
  };
  // The extent of one constant expression from p: up to a top-level `stop`
  // character.
  auto exprEnd = [&](std::string_view stops) {
    size_t q = p;
    int depth = 0;
    for (; q < end; ++q) {
      if (t[q] == '(') ++depth;
      if (t[q] == ')') --depth;
      if (depth == 0 && stops.find(t[q]) != std::string_view::npos) break;
    }
    return q;
  };
  space();
  if (p >= end || t[p] != '{') {
    Error(l, int(p) + 1, "expected '{' after 'define:' (cpfg: define: { array a[3]; })");
    return;
  }
  ++p;
  constexpr size_t kMaxArrayElements = size_t(1) << 20;
  for (;;) {
    space();
    if (p < end && t[p] == '}') {
      ++p;
      space();
      if (p < end && t[p] == ';') ++p;
      space();
      if (p < end) Error(l, int(p) + 1, "unexpected text after the 'define:' block");
      return;
    }
    if (p >= end) {
      Error(l, int(after) + 1, "unclosed '{' of 'define:': no '}'");
      return;
    }
    const size_t w = p;
    while (p < end && IsIdentChar(t[p])) ++p;
    const std::string word = t.substr(w, p - w);
    if (word != "array") {
      Error(l, int(w) + 1,
            word == "external"
                ? "'external' definitions (cpfg, for environment programs) are not supported"
                : "expected 'array' in 'define:' (cpfg: define: { array a[3]; })",
            std::max(1, int(word.size())));
      return;
    }
    for (;;) {  // NAME [n]... [= {v, ...}] , ...
      space();
      const size_t ns = p;
      while (p < end && IsIdentChar(t[p])) ++p;
      if (p == ns || !IsIdentStart(t[ns])) {
        Error(l, int(ns) + 1, "expected an array name after 'array'");
        return;
      }
      const std::string name = t.substr(ns, p - ns);
      const int nameCol = int(ns) + 1;
      bool taken = defines_.count(name) || macros_.count(name) ||
                   std::find(g_.globals.begin(), g_.globals.end(), name) != g_.globals.end();
      for (const ArrayShape& a : g_.arrays) taken |= a.name == name;
      if (taken) {
        Error(l, nameCol, "'" + name + "' is already a constant, variable or array",
              int(name.size()));
        return;
      }
      ArrayShape a;
      a.name = name;
      size_t total = 1;
      for (;;) {
        space();
        if (p >= end || t[p] != '[') break;
        ++p;
        const size_t e = exprEnd("]");
        if (e >= end) {
          Error(l, int(p) + 1, "expected ']' after the size of '" + name + "'");
          return;
        }
        double v = 0;
        if (!ParseConstExpr(l, p, e, &v)) return;
        if (!(v >= 1 && v == std::floor(v) && v <= double(kMaxArrayElements))) {
          Error(l, int(p) + 1, "an array size must be a whole number from 1 to 1048576");
          return;
        }
        total *= size_t(v);
        if (total > kMaxArrayElements) {
          Error(l, nameCol, "array '" + name + "' has more than 1048576 elements",
                int(name.size()));
          return;
        }
        a.dims.push_back(uint32_t(v));
        p = e + 1;
      }
      if (a.dims.empty()) {
        Error(l, nameCol, "array '" + name + "' needs a size: " + name + "[n]", int(name.size()));
        return;
      }
      if (g_.globals.size() + total > kMaxArrayElements * 4) {
        Error(l, nameCol, "too many array elements in one grammar", int(name.size()));
        return;
      }
      a.base = uint32_t(g_.globals.size());
      for (size_t k = 0; k < total; ++k) g_.globals.push_back(name + "[" + std::to_string(k) + "]");
      g_.globalInitial.resize(g_.globals.size(), 0.0);
      space();
      if (p < end && t[p] == '=') {  // = { v, v, ... }
        ++p;
        space();
        if (p >= end || t[p] != '{') {
          Error(l, int(p) + 1, "expected '{' with the values of '" + name + "'");
          return;
        }
        ++p;
        size_t k = 0;
        for (;;) {
          space();
          if (p < end && t[p] == '}') {
            ++p;
            break;
          }
          const size_t e = exprEnd(",}");
          if (e >= end) {
            Error(l, int(p) + 1, "expected '}' after the values of '" + name + "'");
            return;
          }
          if (k == total) {
            Error(l, int(p) + 1,
                  "more values than the " + std::to_string(total) + " elements of '" + name + "'");
            return;
          }
          double v = 0;
          if (!ParseConstExpr(l, p, e, &v)) return;
          g_.globalInitial[a.base + k++] = v;
          p = t[e] == ',' ? e + 1 : e;
        }
        space();
      }
      g_.arrays.push_back(std::move(a));
      if (p < end && t[p] == ',') {
        ++p;
        continue;
      }
      if (p < end && t[p] == ';') {
        ++p;
        break;
      }
      Error(l, int(p) + 1, "expected ',' or ';' after array '" + name + "'");
      return;
    }
  }
}

// The global variables: every name assigned in a Start:, StartEach:,
// EndEach: or End: block (found in the text before any line is parsed, so
// a production anywhere in the file sees them).
void GrammarParser::CollectGlobals() {
  for (const Line& l : lines_) {
    const std::string& t = l.text;
    size_t p = 0;
    while (p < t.size() && IsSpace(t[p])) ++p;
    size_t after = 0;
    const char* kw = MatchKeyword(t, p, &after);
    if (!kw || !IsGlobalBlockKeyword(kw)) continue;
    for (size_t i = after; i < t.size(); ++i) {
      if (t[i] == '"') {  // a string (printf's, fscanf's format): skipped
        for (++i; i < t.size() && t[i] != '"'; ++i)
          if (t[i] == '\\') ++i;
        continue;
      }
      // fscanf's `&name` assigns name (not `&&`, not an array's `&a[i]`).
      if (t[i] == '&' && (i + 1 >= t.size() || t[i + 1] != '&') && (i == 0 || t[i - 1] != '&')) {
        size_t b = i + 1;
        while (b < t.size() && IsSpace(t[b])) ++b;
        size_t e = b;
        while (e < t.size() && IsIdentChar(t[e])) ++e;
        size_t n = e;
        while (n < t.size() && IsSpace(t[n])) ++n;
        if (e > b && IsIdentStart(t[b]) && (n >= t.size() || t[n] != '[')) {
          std::string name = t.substr(b, e - b);
          if (std::find(g_.globals.begin(), g_.globals.end(), name) == g_.globals.end())
            g_.globals.push_back(std::move(name));
        }
        continue;
      }
      if (t[i] != '=') continue;
      if (i + 1 < t.size() && t[i + 1] == '=') {
        ++i;
        continue;
      }
      size_t e = i;
      if (e > after && std::strchr("<>!=", t[e - 1])) continue;
      if (e > after && std::strchr("+-*/", t[e - 1])) --e;
      while (e > after && IsSpace(t[e - 1])) --e;
      size_t b = e;
      while (b > after && IsIdentChar(t[b - 1])) --b;
      if (b == e || !IsIdentStart(t[b])) continue;
      std::string name = t.substr(b, e - b);
      if (std::find(g_.globals.begin(), g_.globals.end(), name) == g_.globals.end())
        g_.globals.push_back(std::move(name));
    }
  }
}

bool GrammarParser::ParseHeader(const Line& l, size_t pos) {
  const std::string& t = l.text;
  size_t after = 0;
  const char* kw = MatchKeyword(t, pos, &after);
  if (!kw) return false;
  std::string k = kw;
  size_t end = t.size();
  while (after < end && IsSpace(t[after])) ++after;
  while (end > after && IsSpace(t[end - 1])) --end;
  int col = int(pos) + 1;
  auto needValue = [&]() {
    if (after < end) return true;
    Error(l, col, "'" + k + ":' needs a value", int(k.size()));
    return false;
  };
  bool inMain = section_ == &g_.main;
  auto mainOnly = [&]() {
    if (inMain) return true;
    Error(l, col,
          "'" + k + ":' belongs before the productions, not in a " +
              (section_ == &g_.decomposition ? "decomposition" : "interpretation") + " section",
          int(k.size()));
    return false;
  };
  if (k == "endlsystem") {
    ended_ = true;
    return true;
  }
  if (k == "decomposition") {
    section_ = &g_.decomposition;
    return true;
  }
  if (k == "interpretation" || k == "homomorphism") {
    section_ = &g_.interpretation;
    return true;
  }
  if (k == "lsystem") {
    BeginLsystem(l, col, after, end);
    return true;
  }
  if (k == "module") return true;  // collected before parsing
  if (!needValue()) return true;
  if (k == "maximum depth") {
    if (inMain) {
      Error(l, col, "'maximum depth:' belongs in a decomposition or interpretation section", 13);
      return true;
    }
    double v;
    if (!ParseConstExpr(l, after, end, &v)) return true;
    // cpfg's decompositions run thousands deep (self-thinning: 15000, a
    // module that makes one plant a pass); passes stop when nothing changes.
    if (v != std::floor(v) || v < 1 || v > kMaxSectionDepth) {
      Error(l, int(after) + 1,
            "maximum depth must be a whole number from 1 to " + std::to_string(kMaxSectionDepth));
      return true;
    }
    section_->maxDepth = int(v);
    return true;
  }
  if (!mainOnly()) return true;
  if (lsystem_ > 0) {
    // A sub-L-system block: cpfg reads its axiom and derivation length but
    // uses only the main L-system's; its ignore:/consider: are its own.
    if (k == "axiom") {
      ExprScope scope{&g_.constants, &usedConstants_, nullptr, &macros_};
      scope.functions = &g_.functions;
      scope.curves = &g_.curves;
      scope.globals = &g_.globals;
      UseArrays(l, scope);
      Successor unused;
      ParseActualWord(l, after, end, scope, &unused);
      return true;
    }
    if (k == "derivation length") {
      double unused;
      ParseConstExpr(l, after, end, &unused);
      return true;
    }
    if (k == "seed") {
      Warn(Loc(l, col), OriginalAt(l, col),
           "'seed:' of a sub-L-system is not used: Sylva draws every random number from the "
           "main L-system's seed",
           4);
      return true;
    }
    if (k != "ignore" && k != "consider") {
      Error(l, col,
            "'" + k +
                ":' belongs to the main L-system (the first 'lsystem:' block), not to a "
                "sub-L-system",
            int(k.size()));
      return true;
    }
  }
  if (IsGlobalBlockKeyword(k)) {
    ParseGlobalBlock(l, k, after, end);
    return true;
  }
  if (k == "define") {
    ParseArrays(l, after, end);
    return true;
  }
  if (k == "axiom") {
    ParseAxiom(l, col, after, end);
    return true;
  }
  if (k == "ignore" || k == "consider") {
    ParseContextNames(l, after, end, k == "ignore");
    return true;
  }
  if (k == "palette") {
    ParsePalette(l, col, after, end);
    return true;
  }
  if (k == "functions") {
    ParseFunctions(l, after, end);
    return true;
  }
  if (k == "tropism") {
    ParseTropism(l, after, end);
    return true;
  }
  if (k == "environment") {
    ParseEnvironment(l, col, after, end);
    return true;
  }
  ParseNumberStatement(l, k, after, end);
  return true;
}

static size_t FindTopLevel(const std::string& t, size_t from, size_t to, std::string_view what) {
  int depth = 0;
  for (size_t i = from; i < to; ++i) {
    char c = t[i];
    if (c == '(')
      ++depth;
    else if (c == ')')
      --depth;
    else if (depth == 0 && c == what[0] && i + what.size() <= to &&
             t.compare(i, what.size(), what) == 0)
      return i;
  }
  return std::string::npos;
}

// The ':' before a probability weight in a successor: the first outside
// parentheses and outside cpfg statement blocks (which may hold `?:`).
static size_t FindWeightColon(const std::string& t, size_t from, size_t to) {
  int depth = 0;
  std::string_view view(t.data(), to);
  for (size_t i = from; i < to; ++i) {
    char c = t[i];
    if (c == '(') {
      ++depth;
    } else if (c == ')') {
      --depth;
    } else if (c == '{' && IsStatementBlock(view, i)) {
      int braces = 0;
      for (; i < to; ++i) {
        if (t[i] == '{') ++braces;
        if (t[i] == '}' && --braces == 0) break;
      }
    } else if (depth == 0 && c == ':') {
      return i;
    }
  }
  return std::string::npos;
}

// `array NAME` from p on, blanks first: cpfg's `define: { array a[3],`
// whose block goes on over the next lines.
static bool StartsArrayDefinition(const std::string& t, size_t p) {
  while (p < t.size() && IsSpace(t[p])) ++p;
  if (t.compare(p, 5, "array") != 0) return false;
  p += 5;
  if (p >= t.size() || !IsSpace(t[p])) return false;
  while (p < t.size() && IsSpace(t[p])) ++p;
  return p < t.size() && IsIdentStart(t[p]);
}

// The depth of statement-block braces at the end of `t`, from `depth` at
// its start: a `{` opens a block when it follows a ':' and ends its line
// (a pre-condition, `Start: {`) or starts a statement (IsStatementBlock; `next` is the text
// of the following line, for a `{` that ends its line); inside a block
// every brace counts.
static int BlockDepth(const std::string& t, int depth, std::string_view next) {
  char prev = 0;
  for (size_t i = 0; i < t.size(); ++i) {
    const char c = t[i];
    if (depth > 0) {
      depth += c == '{' ? 1 : (c == '}' ? -1 : 0);
    } else if (c == '{' &&
               ((prev == ':' && t.find_first_not_of(" \t\r", i + 1) == std::string::npos) ||
                (prev == ':' && StartsArrayDefinition(t, i + 1)) || IsStatementBlock(t, i, next))) {
      depth = 1;
    }
    if (!IsSpace(c)) prev = c;
  }
  return depth;
}

// A line continued on the next: by a `\` at its end (the `\` reads as a
// space), or, for a production, by indented lines that are neither
// statements nor productions themselves (cpfg's way of writing a long
// successor, or the `-->` of a production on the line after its
// predecessor and condition), and for `axiom:` by indented lines without an
// arrow (a long axiom). Lines of different files are never joined.
// Joined lines keep where each piece came from (Line::more), so errors
// point into the right line and column.
void GrammarParser::JoinContinuations() {
  auto firstText = [](const std::string& t) {
    size_t p = 0;
    while (p < t.size() && IsSpace(t[p])) ++p;
    return p;
  };
  auto hasArrow = [](const std::string& t) {
    return FindTopLevel(t, 0, t.size(), "->") != std::string::npos;
  };
  auto startsWithArrow = [&](const std::string& t) {
    const size_t p = firstText(t);
    return t.compare(p, 2, "->") == 0 || t.compare(p, 3, "-->") == 0;
  };
  // Not blank, not a statement, not a directive.
  auto isProduction = [&](const Line& l) {
    const size_t p = firstText(l.text);
    size_t after = 0;
    return p < l.text.size() && !StartsDirective(l.text, p) && !MatchKeyword(l.text, p, &after);
  };
  auto isAxiom = [&](const Line& l) {
    size_t after = 0;
    const char* kw = MatchKeyword(l.text, firstText(l.text), &after);
    return kw && std::string_view(kw) == "axiom";
  };
  // `l` ends with `\` and `next` goes on with it (text that is not a
  // statement, directive or production of its own; otherwise the `\` is
  // the roll module that ends a word): blanks the `\` and says so.
  auto takeBackslash = [&](Line& l, const Line* next) {
    if (!next || next->file != l.file || !isProduction(*next) ||
        (hasArrow(next->text) && !startsWithArrow(next->text)))
      return false;
    size_t e = l.text.size();
    while (e > 0 && IsSpace(l.text[e - 1])) --e;
    if (e == 0 || l.text[e - 1] != '\\') return false;
    l.text[e - 1] = ' ';
    // cpfg's files end some #define lines with `\\` (two backslashes):
    // both continue the line there.
    const size_t d = firstText(l.text);
    if (e >= 2 && l.text[e - 2] == '\\' && l.text.compare(d, 7, "#define") == 0)
      l.text[e - 2] = ' ';
    return true;
  };
  std::vector<Line> out;
  out.reserve(lines_.size());
  bool continued = false;  // out.back() ended with a backslash
  bool curArrow = false;   // out.back() has a `->` (kept, not rescanned: linear time)
  int blocks = 0;          // statement blocks open at the end of out.back()
  // The next line with text of the same file, for each line: a `{` at the
  // end of a line opens a statement block when a statement follows, even
  // after blank and comment-only lines (Ridley: `A(s,a) : s<L {` / `// ...`
  // / `rho = ...;`).
  std::vector<size_t> nextWithText(lines_.size() + 1, lines_.size());
  for (size_t k = lines_.size(); k-- > 0;) {
    const bool hasText = firstText(lines_[k].text) < lines_[k].text.size();
    nextWithText[k] = hasText ? k : nextWithText[k + 1];
  }
  for (size_t i = 0; i < lines_.size(); ++i) {
    Line& l = lines_[i];
    const Line* next = i + 1 < lines_.size() ? &lines_[i + 1] : nullptr;
    const size_t nt = nextWithText[i + 1];
    const std::string_view nextText = nt < lines_.size() && lines_[nt].file == l.file
                                          ? std::string_view(lines_[nt].text)
                                          : std::string_view();
    const size_t p = firstText(l.text);
    const bool blank = p >= l.text.size();
    if (blocks > 0 && out.back().file == l.file) {
      // Inside a statement block: joined with a space between the lines.
      Line& cur = out.back();
      cur.more.push_back(Line::Piece{int(cur.text.size()) + 1, l.number, 1, l.original});
      cur.text += ' ';
      cur.text += l.text;
      blocks = BlockDepth(l.text, blocks, nextText);
      curArrow = curArrow || hasArrow(l.text);
      continued = blocks == 0 && takeBackslash(cur, next);
      continue;
    }
    bool join = continued;
    if (!join && !out.empty() && out.back().file == l.file && !blank && p > 0 && isProduction(l) &&
        !hasArrow(l.text) && isAxiom(out.back())) {
      // cpfg's axiom over several lines: the indented lines after
      // `axiom:` that are not statements or productions go on with it.
      join = true;
    }
    if (!join && !out.empty() && out.back().file == l.file && !blank && p > 0 && isProduction(l) &&
        isProduction(out.back())) {
      // Without its arrow yet, the production goes on with a line that
      // starts with the arrow or with a statement block (cpfg's
      // `A(t) : t < 5` / `  {nt = t + 1;}` / `  --> ...`), or, after the
      // ':' of a condition, with any indented line (`A(x) : {...}` /
      // `  x < 5 -->`): without its arrow it is no production on its own.
      // So does a line that starts with the ':' of the condition (vlab's
      // soil3d: `?E(...)A(tl,l,o) > @v?P(x,y,z)` / `  : (nut>0) ...`), and
      // any indented line without an arrow: a context continued on the next
      // line (ShootRoot's `N > [I(...)]` / `  [I(...)] : ...`).
      join = curArrow ? !hasArrow(l.text)
                      : (startsWithArrow(l.text) || l.text[p] == '{' || l.text[p] == ':' ||
                         !hasArrow(l.text) ||
                         FindTopLevel(out.back().text, 0, out.back().text.size(), ":") !=
                             std::string::npos);
    }
    if (!join) {
      out.push_back(std::move(l));
      curArrow = hasArrow(out.back().text);
      blocks = BlockDepth(out.back().text, 0, nextText);
      continued = blocks == 0 && takeBackslash(out.back(), next);
      continue;
    }
    curArrow = curArrow || hasArrow(l.text);
    Line& cur = out.back();
    cur.more.push_back(Line::Piece{int(cur.text.size()), l.number, 1, l.original});
    cur.text += l.text;
    blocks = BlockDepth(l.text, 0, nextText);
    continued = blocks == 0 && takeBackslash(cur, next);
  }
  lines_ = std::move(out);
}

void GrammarParser::ParseProduction(const Line& l, size_t pos, size_t arrow, size_t arrowLen) {
  const std::string& t = l.text;
  Production p;
  // LHS: [LEFT <] PRED [> RIGHT] [: CONDITION]
  size_t lhsEnd = arrow;
  size_t condAt = FindTopLevel(t, pos, lhsEnd, ":");
  size_t ctxEnd = condAt == std::string::npos ? lhsEnd : condAt;

  std::vector<Formal> w1, w2, w3;
  size_t q = pos;
  if (!ParseFormalWord(l, q, ctxEnd, &w1)) return;
  std::vector<Formal>*left = nullptr, *pred = &w1, *right = nullptr;
  if (q < ctxEnd && t[q] == '<') {
    ++q;
    left = &w1;
    if (!ParseFormalWord(l, q, ctxEnd, &w2)) return;
    pred = &w2;
  }
  if (q < ctxEnd && t[q] == '>') {
    ++q;
    if (!ParseFormalWord(l, q, ctxEnd, &w3)) return;
    right = &w3;
  }
  if (q < ctxEnd) {
    Error(l, int(q) + 1, std::string("unexpected '") + t[q] + "' in the predecessor");
    return;
  }
  if (pred->empty()) {
    Error(l, int(pos) + 1, "production has no predecessor");
    return;
  }
  for (const Formal& f : *pred) {
    if (f.wildcard) {
      Error(l, f.column, "'*' cannot be (part of) a predecessor: it stands alone as a context");
      return;
    }
  }
  auto isWildcard = [](const std::vector<Formal>* w) {
    return w && w->size() == 1 && (*w)[0].wildcard;
  };
  if (left && left->empty()) {
    Error(l, int(pos) + 1, "empty left context before '<'");
    return;
  }
  if (right && right->empty()) {
    Error(l, int(ctxEnd), "empty right context after '>'");
    return;
  }
  std::vector<std::string> formals;
  auto bind = [&](const Formal& f, FormalModule* fm) -> bool {
    if (f.wildcard) {
      Error(l, f.column, "'*' stands alone as a context meaning 'any'");
      return false;
    }
    auto id = Intern(l, f.column, f.name, int(f.params.size()));
    if (!id) return false;
    fm->symbol = *id;
    fm->firstFormal = uint16_t(formals.size());
    for (const auto& name : f.params) {
      if (std::find(formals.begin(), formals.end(), name) != formals.end()) {
        Error(l, f.column, "formal parameter '" + name + "' appears twice in this production",
              int(f.name.size()));
        return false;
      }
      formals.push_back(name);
    }
    return true;
  };
  if (left && !isWildcard(left)) {
    for (const auto& f : *left) {
      if (f.name == "[" || f.name == "]") {
        Error(l, f.column, "brackets are not allowed in a left context");
        return;
      }
      FormalModule fm;
      if (!bind(f, &fm)) return;
      p.left.push_back(fm);
    }
  }
  const Formal& pf = (*pred)[0];
  // cpfg's strict predecessor may be several modules (`A B --> C`), matched
  // on consecutive modules of the word.
  // Brackets may be part of it in balanced pairs (cpfg's
  // `[f(y)-f(z)P(r,s)?E(x)] --> ...` rewrites a whole branch), matched
  // module for module like the rest; the successor is balanced too, so
  // the word stays balanced.
  std::vector<int> openAt;
  for (const Formal& f : *pred) {
    if (f.name == "%") {
      Error(l, f.column, "'%' cannot be rewritten");
      return;
    }
    if (f.name == "[") openAt.push_back(f.column);
    if (f.name == "]") {
      if (openAt.empty()) {
        Error(l, f.column,
              "']' cannot be rewritten without its '[': a predecessor holds brackets only in "
              "balanced pairs");
        return;
      }
      openAt.pop_back();
    }
  }
  if (!openAt.empty()) {
    Error(l, openAt.back(),
          "'[' cannot be rewritten without its ']': a predecessor holds brackets only in "
          "balanced pairs");
    return;
  }
  if (!bind(pf, &p.pred)) return;
  for (size_t k = 1; k < pred->size(); ++k) {
    FormalModule fm;
    if (!bind((*pred)[k], &fm)) return;
    p.predTail.push_back(fm);
  }
  if (right && !isWildcard(right)) {
    std::vector<int> cols;
    for (const auto& f : *right) {
      FormalModule fm;
      if (f.name == "=" && !f.wildcard) {
        // cpfg's `=`: the rest of the current branch (`A > [B=]C`).
        if (!f.params.empty()) {
          Error(l, f.column, "'=' in a right context (the rest of the branch) takes no parameters");
          return;
        }
        fm.symbol = kRestOfBranch;
      } else if (!bind(f, &fm)) {
        return;
      }
      p.right.push_back(fm);
      cols.push_back(f.column);
    }
    // As in cpfg, a right context need not be balanced: a `]` without its
    // `[` leaves the branch of the predecessor (`A > B]C`), a `[` without
    // its `]` ends the context inside that branch.
    std::vector<SymbolId> syms;
    for (auto& fm : p.right) syms.push_back(fm.symbol);
    int depth = 0;
    for (size_t k = 0; k < syms.size(); ++k) {
      depth += syms[k] == kOpenBracket ? 1 : (syms[k] == kCloseBracket ? -1 : 0);
      if (depth > kMaxRightContextNesting) {
        Error(l, cols[k],
              "right context nested deeper than " + std::to_string(kMaxRightContextNesting) +
                  " brackets");
        return;
      }
    }
  }
  p.formalCount = uint16_t(formals.size());
  ExprScope scope{&g_.constants, &usedConstants_, &formals, &macros_};
  scope.functions = &g_.functions;
  scope.curves = &g_.curves;
  UseArrays(l, scope);

  // Condition, with cpfg's statement blocks around it.
  std::vector<std::string> locals;
  bool writesGlobal = false;
  scope.locals = &locals;
  scope.globals = &g_.globals;
  scope.writesGlobal = &writesGlobal;
  HiddenGlobalSlots(t, pos, false, &scope);
  if (condAt != std::string::npos && !ParseCondition(l, p, scope, condAt, lhsEnd)) return;

  // RHS: SUCCESSOR [: WEIGHT]
  size_t rs = arrow + arrowLen;
  size_t rend = t.size();
  size_t weightAt = FindWeightColon(t, rs, rend);
  size_t succEnd = weightAt == std::string::npos ? rend : weightAt;
  size_t s0 = rs;
  while (s0 < succEnd && IsSpace(t[s0])) ++s0;
  size_t s1 = succEnd;
  while (s1 > s0 && IsSpace(t[s1 - 1])) --s1;
  if (s0 >= s1) {
    Error(l, int(arrow) + 1, "empty successor (write '*' for the empty word)", int(arrowLen));
    return;
  }
  if (!(s1 == s0 + 1 && t[s0] == '*')) {
    if (!ParseActualWord(l, s0, s1, scope, &p.successor)) return;
  }
  if (weightAt != std::string::npos) {
    size_t w = weightAt + 1;
    while (w < rend && IsSpace(t[w])) ++w;
    if (w >= rend) {
      Error(l, int(weightAt) + 1, "expected a probability weight after ':'");
      return;
    }
    std::string_view view(t.data(), rend);
    Expr weight;
    ExprParseError err;
    size_t wp = w;
    if (!ParseExpr(view, &wp, Lenient(scope), &weight, &err)) {
      Error(l, err.column, err.message, err.length);
      return;
    }
    WarnUndefined(l);
    while (wp < rend && IsSpace(t[wp])) ++wp;
    if (wp < rend) {
      Error(l, int(wp) + 1, "unexpected text after the weight");
      return;
    }
    if (weight.IsConstant() && weight.constant() < 0) {
      Error(l, int(w) + 1, "negative probability weight");
      return;
    }
    p.weightColumn = int(w) + 1;
    p.weight = std::move(weight);
  }
  if (locals.size() + formals.size() > 60000) {
    Error(l, pf.column, "too many local variables in one production");
    return;
  }
  p.localCount = uint16_t(locals.size());
  p.lsystem = lsystem_;
  if (writesGlobal) g_.productionsWriteGlobals = true;
  p.loc = Loc(l, pf.column);
  if (!l.expansions.empty()) {
    // Columns of the text with #defines substituted, mapped one by one:
    // a new piece wherever the file position does not follow on.
    SourceLoc prev;
    for (int c = 1; c <= int(l.text.size()); ++c) {
      const SourceLoc at = Loc(l, c);
      if (c == 1 || at.line != prev.line || at.column != prev.column + 1)
        p.pieces.push_back(Production::LinePiece{c - 1, at.line, at.column});
      prev = at;
    }
  } else if (!l.more.empty()) {
    p.pieces.push_back(Production::LinePiece{0, l.number, 1});
    for (const Line::Piece& q : l.more)
      p.pieces.push_back(Production::LinePiece{q.at, q.number, q.column});
  }
  if (section_->productions.size() >= kMaxProductionsPerSection) {
    Error(l, pf.column,
          "more than " + std::to_string(kMaxProductionsPerSection) + " productions in one section");
    return;
  }
  section_->productions.push_back(std::move(p));
}

// `: [{pre}] [COND] [{post}]` between condAt (the ':') and lhsEnd (the
// arrow). A condition left out, or `*`, is always true.
bool GrammarParser::ParseCondition(const Line& l, Production& p, const ExprScope& scope,
                                   size_t condAt, size_t lhsEnd) {
  const std::string& t = l.text;
  std::string_view view(t.data(), lhsEnd);
  size_t c = condAt + 1;
  auto skip = [&]() {
    while (c < lhsEnd && IsSpace(t[c])) ++c;
  };
  auto block = [&](std::optional<Expr>* out) {
    Expr b;
    if (!ParseBlockAt(l, view, &c, scope, &b)) return false;
    *out = std::move(b);
    skip();
    return true;
  };
  skip();
  if (c < lhsEnd && t[c] == '{' && !block(&p.preBlock)) return false;
  if (c >= lhsEnd) {
    if (p.preBlock) return true;
    Error(l, int(condAt) + 1, "empty condition after ':' (write '*' for always)");
    return false;
  }
  if (t[c] == '*') {
    ++c;
    skip();
  } else if (t[c] != '{') {
    const size_t c0 = c;
    Expr cond;
    ExprParseError err;
    if (!ParseExpr(view, &c, Lenient(scope), &cond, &err)) {
      Error(l, err.column, err.message, err.length);
      return false;
    }
    WarnUndefined(l);
    size_t e = c;
    while (e > c0 && IsSpace(t[e - 1])) --e;
    p.conditionColumn = int(c0) + 1;
    if (cond.IsConstant() && cond.constant() == 0) {
      Warn(Loc(l, int(c0) + 1), OriginalAt(l, int(c0) + 1),
           "condition is always false: production never applies", int(e - c0));
    }
    if (!(cond.IsConstant() && cond.constant() != 0)) p.condition = std::move(cond);
    skip();
  }
  if (c < lhsEnd && t[c] == '{' && !block(&p.postBlock)) return false;
  if (c < lhsEnd) {
    Error(l, int(c) + 1, "unexpected text after the condition");
    return false;
  }
  return true;
}

void GrammarParser::ParseLine(const Line& l) {
  const std::string& t = l.text;
  size_t pos = 0;
  while (pos < t.size() && IsSpace(t[pos])) ++pos;
  if (pos >= t.size()) return;
  if (t.compare(pos, 7, "#define") == 0 && (pos + 7 >= t.size() || IsSpace(t[pos + 7]))) {
    return;  // read by Conditionals()
  }
  if (StartsDirective(t, pos)) {
    size_t e = pos + 1;
    while (e < t.size() && IsIdentChar(t[e])) ++e;
    Error(l, int(pos) + 1, "unknown directive '" + t.substr(pos, e - pos) + "'", int(e - pos));
    return;
  }
  if (ParseHeader(l, pos)) return;
  size_t arrow = FindTopLevel(t, pos, t.size(), "-->");
  size_t arrowLen = 3;
  if (arrow == std::string::npos) {
    arrow = FindTopLevel(t, pos, t.size(), "->");
    arrowLen = 2;
  }
  if (arrow != std::string::npos) {
    ParseProduction(l, pos, arrow, arrowLen);
    return;
  }
  // Name the problem as precisely as we can.
  if (BlockDepth(t, 0, {}) > 0) {
    // A statement block that runs to the end of the file (or of its
    // #include): point at its '{'.
    size_t open = t.size();
    int depth = 0;
    for (size_t i = t.size(); i-- > 0;) {
      if (t[i] == '}') ++depth;
      if (t[i] == '{' && depth-- == 0) open = i;
      if (open != t.size()) break;
    }
    Error(l, int(open) + 1, "unclosed '{': the statement block has no '}'");
    return;
  }
  {
    // cpfg's `ring lsystem` statement (Ring/ring.l): the word is a ring.
    std::string words;
    for (size_t i = pos; i < t.size(); ++i)
      if (!IsSpace(t[i])) words += char(std::tolower(static_cast<unsigned char>(t[i])));
    if (words == "ringlsystem") {
      if (lsystem_ > 0) {
        Error(l, int(pos) + 1,
              "'ring lsystem' in a sub-L-system is not supported by Sylva (the main "
              "L-system's word is a ring when its header says so)",
              int(t.size() - pos));
        return;
      }
      if (ringLine_) {
        Warn(Loc(l, int(pos) + 1), OriginalAt(l, int(pos) + 1),
             "second 'ring lsystem' (the first is at line " + std::to_string(ringLine_) +
                 "): it changes nothing",
             int(t.size() - pos));
        return;
      }
      ringLine_ = Loc(l, int(pos) + 1).line;
      g_.ring = true;
      return;
    }
  }
  size_t e = pos;
  while (e < t.size() && (IsIdentChar(t[e]) || t[e] == ' ')) ++e;
  if (e < t.size() && t[e] == ':' && e > pos) {
    std::string word = t.substr(pos, e - pos);
    while (!word.empty() && word.back() == ' ') word.pop_back();
    Error(l, int(pos) + 1, "unknown statement '" + word + ":'", int(word.size()));
    return;
  }
  Error(l, int(pos) + 1,
        "expected a production 'PRED --> SUCCESSOR' or a statement such as 'axiom:'");
}

// ---------------------------------------------------------------------------
// Sub-L-systems (cpfg): several `lsystem:` blocks in one file

bool GrammarParser::StartsLsystem(const Line& l) const {
  size_t pos = 0, after = 0;
  while (pos < l.text.size() && IsSpace(l.text[pos])) ++pos;
  const char* kw = MatchKeyword(l.text, pos, &after);
  return kw && std::string_view(kw) == "lsystem";
}

// `lsystem: LABEL`. The first names the grammar; each later one (after an
// `endlsystem`) starts a sub-L-system whose number is the label read as a
// number, as cpfg reads it (atof: "2" is 2, a label that is not a number is 0).
void GrammarParser::BeginLsystem(const Line& l, int col, size_t after, size_t end) {
  const std::string label = l.text.substr(after, end - after);
  LsystemBlock b;
  b.name = label;
  const double number = std::strtod(label.c_str(), nullptr);
  b.loc = Loc(l, col);
  if (!(std::fabs(number) <= double(std::numeric_limits<int>::max()))) {
    Error(l, col, "L-system label '" + label + "' is a number out of range", 7);
    return;
  }
  b.id = int(number);
  if (g_.lsystems.empty()) {
    g_.name = label;
    g_.lsystems.push_back(std::move(b));
    return;
  }
  if (!blockMayStart_) {
    Error(l, col,
          "a second 'lsystem:' inside an L-system: end the first with 'endlsystem' before a "
          "sub-L-system starts",
          7);
    return;
  }
  for (const LsystemBlock& o : g_.lsystems) {
    if (o.id != b.id) continue;
    Error(l, col,
          "two L-systems numbered " + std::to_string(b.id) + " (the other at line " +
              std::to_string(o.loc.line) + "): ?(id, scale) could not tell them apart",
          7);
    return;
  }
  if (g_.lsystems.size() >= 65535) {
    Error(l, col, "too many L-system blocks in one file", 7);
    return;
  }
  blockContext_.push_back(
      ContextNames{std::move(ignoreNames_), std::move(considerNames_), haveIgnore_, haveConsider_});
  ignoreNames_.clear();
  considerNames_.clear();
  haveIgnore_ = haveConsider_ = false;
  section_ = &g_.main;
  lsystem_ = uint16_t(g_.lsystems.size());
  g_.lsystems.push_back(std::move(b));
}

// Per symbol id: 1 when context matching skips it under these names.
std::vector<uint8_t> GrammarParser::SkipTable(const ContextNames& c) const {
  const size_t nsym = g_.symbols.size();
  std::vector<uint8_t> skip(nsym, 0);
  for (size_t s = 0; s < nsym; ++s) {
    const std::string& name = g_.symbols.name(SymbolId(s));
    if (c.haveConsider) skip[s] = !c.consider.count(name);
    if (c.haveIgnore && c.ignore.count(name)) skip[s] = 1;
  }
  return skip;
}

// ---------------------------------------------------------------------------
// After all lines

// The first line with text after `endlsystem`: Sylva reads one L-system a
// file, so what follows is said to be ignored, where it starts.
void GrammarParser::WarnAfterEnd(const Line& l) {
  const std::string& t = l.text;
  size_t pos = 0;
  while (pos < t.size() && IsSpace(t[pos])) ++pos;
  if (pos >= t.size()) return;
  warnedAfterEnd_ = true;
  Warn(Loc(l, int(pos) + 1), l.original,
       "text after 'endlsystem' is ignored (it is not an 'lsystem:' block)", 1);
}

void GrammarParser::WarnUnmatchable() {
  // Symbols that can occur in a derived word: the axiom and every successor
  // of the main and decomposition sections; interpretation successors only
  // feed interpretation.
  std::vector<uint8_t> occurs(g_.symbols.size(), 0);
  for (SymbolId s : axiom_.symbols) occurs[s] = 1;
  for (auto* sec : {&g_.main, &g_.decomposition}) {
    for (const auto& p : sec->productions) {
      for (SymbolId s : p.successor.symbols) occurs[s] = 1;
    }
  }
  std::vector<uint8_t> occursInterp = occurs;
  for (const auto& p : g_.interpretation.productions) {
    for (SymbolId s : p.successor.symbols) occursInterp[s] = 1;
  }
  for (auto* sec : {&g_.main, &g_.decomposition, &g_.interpretation}) {
    const auto& occ = sec == &g_.interpretation ? occursInterp : occurs;
    // Per symbol: the first production that always applies (no context,
    // condition or weight), which shadows every later one.
    // (Per L-system block: a sub-L-system's productions shadow only its own.)
    const size_t blocks = std::max<size_t>(1, g_.lsystems.size());
    std::vector<int64_t> firstAlways(g_.symbols.size() * blocks, -1);
    for (size_t i = 0; i < sec->productions.size(); ++i) {
      const Production& p = sec->productions[i];
      SymbolId s = p.pred.symbol;
      const std::string& name = g_.symbols.name(s);
      int64_t& always = firstAlways[size_t(p.lsystem) * g_.symbols.size() + s];
      const int64_t shadow = always;
      if (shadow < 0 && !p.HasContext() && !p.condition && !p.weight && p.predTail.empty())
        always = int64_t(i);
      if (!occ[s]) {
        int a = g_.symbols.arity(s);
        Warn(p.loc, g_.SourceLine(p.loc),
             "production can never match: no module '" + name + "' with " + std::to_string(a) +
                 " parameter" + (a == 1 ? "" : "s") + " occurs in the axiom or any successor",
             int(name.size()));
        continue;
      }
      // Shadowed by an earlier production that always applies.
      if (shadow >= 0) {
        const Production& q = sec->productions[size_t(shadow)];
        Warn(p.loc, g_.SourceLine(p.loc),
             "production never applies: the production at line " + std::to_string(q.loc.line) +
                 " always matches '" + name + "' first",
             int(name.size()));
      }
    }
  }
}

void GrammarParser::Finish() {
  // Overrides must name a #define.
  for (const auto& [name, value] : opt_.overrides) {
    if (!usedOverrides_.count(name)) {
      Diagnostic d;
      d.loc.file = files_.empty() ? "" : files_[0];
      d.message = "-D " + name + ": the grammar has no '#define " + name + "'";
      diags_.Add(std::move(d));
    }
  }
  if (!haveAxiom_ && !diags_.HasErrors()) {
    Diagnostic d;
    d.loc = SourceLoc{files_[0], lines_.empty() ? 1 : lines_.back().number, 0};
    d.message = "the grammar has no 'axiom:'";
    diags_.Add(std::move(d));
  }
  for (const auto& [name, def] : defines_) {
    if (!usedConstants_.count(name)) {
      Warn(def.loc, g_.SourceLine(def.loc),
           (textMacros_.count(name) ? "#define '" : "constant '") + name + "' is never used",
           def.length);
    }
  }
  if (diags_.HasErrors()) return;
  WarnUnmatchable();
  WarnMixedArity();
  // ?E is answered by the environment that `environment:` names; without
  // one its parameters keep the values written in the grammar.
  if (!g_.environment && !opt_.environmentGiven) {
    for (size_t s = 0; s < g_.symbols.size(); ++s) {
      if (g_.symbols.name(SymbolId(s)) != "?E") continue;
      auto it = g_.symbolLoc.find("?E");
      const SourceLoc loc = it != g_.symbolLoc.end() ? it->second.loc : SourceLoc{files_[0], 0, 0};
      Warn(loc, g_.SourceLine(loc),
           "query module '?E' is not answered: the grammar has no 'environment:' statement, so "
           "its parameters keep the values written in the grammar",
           2);
      break;
    }
  }
  // cpfg (interpret.c, 's'): when a grammar has a `?` module (it then runs
  // its environment pass), s(x, y) and s(x, y, z) get the turtle's position,
  // an older form of ?P. Sylva reads `s` as a plain module: said once.
  {
    bool queries = false, positionS = false;
    for (size_t s = 0; s < g_.symbols.size(); ++s) {
      const std::string& name = g_.symbols.name(SymbolId(s));
      const int arity = g_.symbols.arity(SymbolId(s));
      queries |= !name.empty() && name[0] == '?';
      positionS |= name == "s" && (arity == 2 || arity == 3);
    }
    auto it = g_.symbolLoc.find("s");
    if (queries && positionS && it != g_.symbolLoc.end()) {
      Warn(it->second.loc, g_.SourceLine(it->second.loc),
           "module 's' with 2 or 3 parameters: in a grammar with '?' modules cpfg fills them "
           "with the turtle's position (an older form of ?P); Sylva reads 's' as a plain module "
           "and leaves them as written (use ?P)",
           1);
    }
  }

  const size_t nsym = g_.symbols.size();
  for (auto* sec : {&g_.main, &g_.decomposition, &g_.interpretation}) {
    sec->bySymbol.assign(nsym, {});
    for (size_t i = 0; i < sec->productions.size(); ++i) {
      const Production& p = sec->productions[i];
      sec->bySymbol[p.pred.symbol].push_back(uint32_t(i));
      if (p.HasContext()) g_.usesContext = true;
      if (p.weight) g_.usesRandom = true;
      if (p.condition && p.condition->UsesRandom()) g_.usesRandom = true;
      for (const auto& e : p.successor.params) g_.usesRandom |= e.UsesRandom();
      for (const auto& b : p.successor.blocks) g_.usesRandom |= b.code.UsesRandom();
      if (p.preBlock) g_.usesRandom |= p.preBlock->UsesRandom();
      if (p.postBlock) g_.usesRandom |= p.postBlock->UsesRandom();
    }
  }
  for (const auto* b : {&g_.startBlock, &g_.startEachBlock, &g_.endEachBlock, &g_.endBlock})
    if (*b) g_.usesRandom |= (*b)->UsesRandom();
  // The context tables: the main L-system's, then each sub-L-system's.
  blockContext_.push_back(
      ContextNames{std::move(ignoreNames_), std::move(considerNames_), haveIgnore_, haveConsider_});
  g_.contextSkip = SkipTable(blockContext_[0]);
  for (size_t b = 1; b < blockContext_.size() && b < g_.lsystems.size(); ++b)
    g_.lsystems[b].contextSkip = SkipTable(blockContext_[b]);
  for (const auto* sec : {&g_.main, &g_.decomposition, &g_.interpretation})
    for (const Production& p : sec->productions)
      if (!p.predTail.empty()) g_.multiModulePredecessors = true;
  if (g_.lsystems.empty()) g_.lsystems.push_back(LsystemBlock{0, g_.name, SourceLoc{}, {}});
  g_.subLsystems = g_.lsystems.size() > 1;
  for (int a = 1; a <= kMaxArity && !g_.subLsystems; ++a)
    g_.subLsystems = g_.symbols.Find("?", a).has_value();
  CheckSubLsystemIds();
  g_.cutSymbol = g_.symbols.Find("%", 0);
  if (g_.dataFiles && g_.dataFiles->empty()) g_.dataFiles.reset();
  g_.axiom = std::move(axiom_);
  g_.axiomLoc = axiomLoc_;
}

// `?(id, ...)` with a constant id that no `lsystem:` block has, in the
// axiom or a successor: cpfg stops when the derivation gets there ("L-system
// N not in .l file"); Sylva says so where it is written, before deriving.
void GrammarParser::CheckSubLsystemIds() {
  if (!g_.subLsystems) return;
  std::string ids;
  for (const LsystemBlock& b : g_.lsystems) ids += (ids.empty() ? "" : ", ") + std::to_string(b.id);
  auto check = [&](const Successor& w, const SourceLoc& loc, const char* where) {
    size_t param = 0;
    for (SymbolId sym : w.symbols) {
      const int arity = g_.symbols.arity(sym);
      if (arity >= 1 && g_.symbols.name(sym) == "?" && param < w.params.size() &&
          w.params[param].IsConstant()) {
        const double id = std::trunc(w.params[param].constant());
        bool known = false;
        for (const LsystemBlock& b : g_.lsystems) known |= double(b.id) == id;
        if (!known) {
          char shown[32];
          std::snprintf(shown, sizeof shown, "%.6g", id);
          diags_.Add(MakeError(loc,
                               std::string("'?(") + shown + ", ...)' in " + where +
                                   " starts sub-L-system " + shown +
                                   ", but the file's 'lsystem:' blocks are numbered " + ids,
                               1, g_.SourceLine(loc)));
          return;
        }
      }
      param += size_t(arity);
    }
  };
  check(axiom_, axiomLoc_, "the axiom");
  for (const auto* sec : {&g_.main, &g_.decomposition, &g_.interpretation})
    for (const Production& p : sec->productions)
      check(p.successor, p.loc, "the successor of this production");
}

ParseResult GrammarParser::Run(const std::string& text, const std::string& path) {
  if (text.size() > opt_.maxFileBytes) {
    ParseResult r;
    Diagnostic d;
    d.loc.file = path;
    d.message = "file is larger than the limit of " + SizeText(opt_.maxFileBytes);
    r.diagnostics.Add(std::move(d));
    return r;
  }
  g_.cpfgFile = std::filesystem::path(path).extension() == ".l";
  std::vector<std::string> stack{std::filesystem::path(path).lexically_normal().string()};
  Preprocess(std::make_shared<const std::string>(text), path, 0, stack);
  JoinContinuations();
  // Before the #defines are read: a function set defines names.
  LoadOptionFunctions();
  LoadOptionCurves();
  Conditionals();
  CollectGlobals();
  g_.path = path;
  g_.name = std::filesystem::path(path).stem().string();
  // module: declarations apply to the whole file, wherever they stand.
  for (const Line& l : lines_) {
    size_t p = 0;
    while (p < l.text.size() && IsSpace(l.text[p])) ++p;
    if (Lower(l.text.substr(p, 6)) != "module") continue;
    size_t q = p + 6;
    while (q < l.text.size() && IsSpace(l.text[q])) ++q;
    if (q >= l.text.size() || l.text[q] != ':') continue;
    ++q;
    while (q < l.text.size()) {
      while (q < l.text.size() && IsSpace(l.text[q])) ++q;
      size_t s = q;
      while (q < l.text.size() && !IsSpace(l.text[q]) && l.text[q] != '(' && l.text[q] != ')' &&
             l.text[q] != ',')
        ++q;
      if (q > s) declared_.push_back(l.text.substr(s, q - s));
      if (q < l.text.size() && !IsSpace(l.text[q])) {
        Error(l, int(q) + 1, "module names cannot contain '" + Printable(l.text[q]) + "'");
        break;
      }
    }
  }
  for (const std::string& d : declared_) {
    declaredSet_.insert(d);
    declaredLengths_.push_back(d.size());
  }
  std::sort(declaredLengths_.begin(), declaredLengths_.end(), std::greater<>());
  declaredLengths_.erase(std::unique(declaredLengths_.begin(), declaredLengths_.end()),
                         declaredLengths_.end());
  for (const Line& l : lines_) {
    if (ended_ && StartsLsystem(l)) {  // the next block of a file with sub-L-systems
      ended_ = false;
      blockMayStart_ = true;
      ParseLine(l);
      blockMayStart_ = false;
      continue;
    }
    if (ended_) {
      WarnAfterEnd(l);
      if (warnedAfterEnd_) break;
      continue;
    }
    ParseLine(l);
  }
  Finish();
  ParseResult r;
  r.diagnostics = std::move(diags_);
  for (auto& w : warnings_) r.diagnostics.Add(std::move(w));
  if (!r.diagnostics.HasErrors()) r.grammar = std::move(g_);
  return r;
}

}  // namespace

SourceLoc Production::LocOf(int column) const {
  const LinePiece* piece = nullptr;
  for (const LinePiece& q : pieces) {
    if (column > q.at) piece = &q;
  }
  if (!piece) return SourceLoc{loc.file, loc.line, column};
  return SourceLoc{loc.file, piece->line, piece->column + (column - 1 - piece->at)};
}

std::string_view Grammar::SourceLine(const SourceLoc& loc) const {
  for (const SourceFile& f : sources) {
    if (f.path != loc.file) continue;
    if (loc.line < 1 || size_t(loc.line) > f.lineStarts.size()) return {};
    const std::string_view text = *f.text;
    const size_t begin = f.lineStarts[size_t(loc.line) - 1];
    size_t end = text.find('\n', begin);
    if (end == std::string_view::npos) end = text.size();
    if (end > begin && text[end - 1] == '\r') --end;
    return text.substr(begin, end - begin);
  }
  return {};
}

ParseResult ParseGrammarText(const std::string& text, const std::string& path,
                             const ParseOptions& options) {
  GrammarParser p(options);
  return p.Run(text, path);
}

ParseResult ParseGrammarFile(const std::string& path, const ParseOptions& options) {
  std::optional<std::string> text;
  if (options.readFile) {
    text = options.readFile(path);
  } else {
    auto r = ReadFile(path, options.maxFileBytes);
    if (!r) {
      ParseResult res;
      res.diagnostics.Add(r.error());
      return res;
    }
    text = std::move(r).value();
  }
  if (!text) {
    ParseResult res;
    Diagnostic d;
    d.loc.file = path;
    d.message = "cannot read file";
    res.diagnostics.Add(std::move(d));
    return res;
  }
  return ParseGrammarText(*text, path, options);
}

}  // namespace sylva::lsys
