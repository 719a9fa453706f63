// cpfg's data files: `fp = fopen(NAME, "r");` and `fscanf(fp, FORMAT,
// &x, &a[i]);` in statement blocks (vlab's soil3d reads its root
// parameters this way, lilac-congo its internode lengths).
//
// What cpfg does (generate.c, Eval: tFOPEN, tFSCANF, tFCLOSE): fopen opens
// the file relative to the folder cpfg runs in (the object's folder, where
// the .l file is) and returns an index; fscanf is C's fscanf on it, with
// the addresses of up to 10 variables (all doubles), and returns what C's
// returns (the number of values assigned, or EOF); fclose closes it.
//
// Sylva reads each file NAME (relative to the grammar file's folder) once,
// when the grammar is parsed: a file that cannot be read (missing, a
// directory, a device or FIFO, larger than kMaxDataFileBytes) is an error
// at the fopen. At run time fopen gives a new read position at the start
// of that text (the handle, a number from 1), fscanf scans from it with C's
// rules for the directives below, and a new derivation starts with no file
// open (the Start: block opens them again). The format is read when the
// grammar is parsed:
//   blanks (space, \t, \n...)  skip any blanks in the input, none included
//   %lf %f %le %e %lg %g %E %G %a   a number, blanks before it skipped: the
//                                   characters glibc's scanf takes for one
//                                   (`1e` of `1e,`), converted by strtod
//   %d %i %u %ld %x %o ...          a whole number, stored as a double
//   %*... (any of those, or %*s %*c) read and not assigned
//   %%                              a '%' after blanks
//   any other character             that character exactly
// With a width (`%5lf`) at most that many characters are read. A format
// whose conversions do not match its addresses, or that has `%s`, `%c`,
// `%[`, `%n` or `%p` (cpfg has no strings), is an error. A value that is not
// finite (`nan`, `inf`, 1e999) is a run-time error; so is fscanf on a
// number that is not an open file of this grammar. When fscanf stops early
// (the end of the file, or text that does not match the format), the
// variables it did not reach keep their values, as in C; such short reads
// are counted and reported as one warning per file after the derivation
// (ShortReads), so a model that reads less than it expects says so.
#pragma once

#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "core/diagnostic.h"
#include "core/status.h"

namespace sylva::lsys {

inline constexpr size_t kMaxDataFileBytes = size_t(16) << 20;
// Files opened (fopen calls) in one derivation; more is a run-time error.
inline constexpr uint32_t kMaxOpenDataFiles = 4096;
// Values one fscanf may assign (cpfg passes 10 addresses).
inline constexpr int kMaxScanValues = 10;

// One fscanf format, read once.
struct ScanFormat {
  enum class Kind : uint8_t { kBlanks, kLiteral, kReal, kInteger, kWord, kChars };
  struct Directive {
    Kind kind = Kind::kBlanks;
    char literal = 0;    // kLiteral
    int base = 10;       // kInteger: 10, 16, 8, or 0 (%i: as C's strtol)
    int width = 0;       // 0: no limit (kChars: 1)
    bool assign = true;  // false for %*...
  };
  std::vector<Directive> directives;
  int assignments = 0;
};

// Reads `format` (its C escapes already turned into characters); false and
// *why on what Sylva does not read.
bool ParseScanFormat(std::string_view format, ScanFormat* out, std::string* why);

// Turns a C string literal's body (between the quotes) into its
// characters: \n \t \r \\ \" \' \0 and \a..\v; other escapes keep the
// character after the backslash.
std::string UnescapeC(std::string_view body);

// The data files of one grammar and, while it derives, the files it has
// open. Parse time: Add, AddCall. Run time (one derivation at a time; the
// calls lock, so two threads never corrupt it): Reset, Open, Close, Scan.
class CpfgDataFiles {
 public:
  using Reader = std::function<Expected<std::string>(const std::string& path)>;

  // `folder`: where relative names are found (the grammar file's).
  // `reader`: reads a whole file (the parser's: the file system with the
  // checks of core's ReadFile, or a test's).
  CpfgDataFiles(std::string folder, Reader reader);

  // Reads the file `name` names (once per path); its index, or false and
  // *why.
  bool Add(const std::string& name, uint32_t* file, std::string* why);
  // An fscanf call: its format and, per address, whether it is an array
  // element (its offset is on the stack below its value). Its index.
  struct Call {
    ScanFormat format;
    std::vector<uint8_t> element;
  };
  uint32_t AddCall(Call call);
  const Call& call(uint32_t i) const { return calls_[i]; }
  bool empty() const { return files_.empty(); }
  size_t fileCount() const { return files_.size(); }
  const std::string& path(uint32_t file) const { return files_[file].path; }

  // Closes every file (a derivation starts) and forgets the short reads.
  void Reset();
  // A new handle reading file `file` from its start; 0 when too many are open.
  double Open(uint32_t file);
  // Closes the handle if it is one; anything else is left alone (cpfg's
  // fclose of a file it could not open only prints a message).
  void Close(double handle);
  // fscanf: values[k] holds the k-th address's value and receives what is
  // read; *count is C's result (the values assigned, or -1 when the input
  // ends before any is: glibc's rule). False
  // and *why when the handle is no open file or a value is not finite.
  bool Scan(double handle, uint32_t call, double* values, int* count, std::string* why);

  // Per file with short reads since Reset: a warning naming the file, how
  // often fscanf stopped early, and the first place.
  std::vector<Diagnostic> ShortReads() const;

 private:
  struct File {
    std::string path;
    std::string text;
    // Short reads since Reset: how many, and the first one's description.
    int shortReads = 0;
    std::string firstShort;
  };
  struct Handle {
    uint32_t file = 0;
    size_t pos = 0;
    bool open = false;
  };
  std::string folder_;
  Reader reader_;
  std::vector<File> files_;
  std::vector<Call> calls_;
  std::vector<Handle> handles_;  // handle h is handles_[h - 1]
  mutable std::mutex mutex_;
};

}  // namespace sylva::lsys
