// Reading grammar files: preprocessing (comments, #include, #define) and the
// line-oriented cpfg syntax of ../docs/grammar.md.
//
// Every problem is reported as a Diagnostic with file:line:col; parsing goes
// on after an error to report more (the first kMaxErrors are kept, the
// rest counted in DiagnosticList::droppedErrors), and a grammar is returned
// only when there is no error. Warnings: a production that can
// never match, a constant never used, a module name used with two different
// parameter counts, a condition that is always false.
#pragma once

#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/diagnostic.h"
#include "lsys/grammar.h"

namespace sylva::lsys {

inline constexpr int kMaxErrors = 50;
inline constexpr int kMaxIncludeDepth = 16;
// What one grammar may read: each file (the main one or an #include) at most
// kMaxGrammarFileBytes, all of them together kMaxGrammarBytes, and at most
// kMaxIncludedFiles #include files (a file included twice counts twice).
inline constexpr size_t kMaxGrammarFileBytes = size_t(64) << 20;
inline constexpr size_t kMaxGrammarBytes = size_t(256) << 20;
inline constexpr int kMaxIncludedFiles = 1000;
inline constexpr int kMaxDerivationLength = std::numeric_limits<int>::max();  // cpfg's int
inline constexpr size_t kMaxProductionsPerSection = 65000;

struct ParseOptions {
  // -D NAME=VALUE: replaces the value of `#define NAME`.
  std::map<std::string, double> overrides;
  // Reads a file (for the main file when parsing from disk, and #include).
  // Default: the file system.
  std::function<std::optional<std::string>(const std::string& path)> readFile;
  // Whether a predefined surface of this name (without `~`) exists. cpfg's
  // surface names are one letter, so `~lF` is `~l` then `F`; Sylva's may be
  // longer (`~leaf`). With this set, `~` and the identifier after it is
  // read whole when that name is a surface, else as its first letter when
  // that one is (`~lF` with l.obj and no lF.obj), else whole (and later
  // reported as an unknown surface). Empty: always whole.
  std::function<bool(const std::string& name)> isSurface;
  // cpfg function files from outside the grammar (a view file's
  // `function: FILE [samples]` lines), func(1, x) the first; used when the
  // grammar has no `functions:` statement of its own (which wins). `file`
  // is resolved; `from` and `line` locate the naming line for diagnostics.
  // A function set (`function set: FILE.fset`, `set` true) gives all its
  // functions, in order, and defines each one's name as its number, as
  // cpfg's `-DNAME=i` does (a #define or #undef of the name in the grammar
  // replaces it).
  struct FunctionFile {
    std::string file;
    std::string from;
    int line = 0;
    int column = 0;
    bool set = false;
  };
  std::vector<FunctionFile> functionFiles;
  // cpfg curve files (a view file's `curve: FILE [samples]` lines), for
  // curveX/Y/Z(id, t) and curveGAL(id): id 1 is the first. `samples` is
  // the size of cpfg's arc-length table (100 when the line gives none).
  struct CurveFile {
    std::string file;
    std::string from;
    int line = 0;
    int column = 0;
    int samples = 100;
  };
  std::vector<CurveFile> curveFiles;
  // The cpfg view file read for this grammar (empty: none was found); the
  // error of a func() without function files says where Sylva looked.
  std::string viewFile;
  // The caller answers ?E itself (plant::PlantSpec::environment): no
  // warning that a grammar without `environment:` leaves ?E unanswered.
  bool environmentGiven = false;
  // What may be read: per file, and all files of the grammar together.
  size_t maxFileBytes = kMaxGrammarFileBytes;
  size_t maxTotalBytes = kMaxGrammarBytes;
};

struct ParseResult {
  std::optional<Grammar> grammar;  // set when there are no errors
  DiagnosticList diagnostics;      // errors and warnings, in file order
};

ParseResult ParseGrammarFile(const std::string& path, const ParseOptions& options = {});
ParseResult ParseGrammarText(const std::string& text, const std::string& path,
                             const ParseOptions& options = {});

}  // namespace sylva::lsys
