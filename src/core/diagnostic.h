// Diagnostic: one message about user input, with its location.
//
// Printed GCC style, with the source line and a caret under the offending
// columns:
//   grammars/tree.lsys:14:23: error: unknown name 'r3' in expression
//      14 | A(l,w) --> !(w)F(l)[&(a0)B(l*r3,w*wr)]
//         |                               ^~
// Lines and columns are 1-based; column counts bytes. A diagnostic with no
// file (command-line errors) prints "sylva: error: ...".
#pragma once

#include <string>
#include <vector>

namespace sylva {

enum class Severity { kNote, kWarning, kError };

// What kind of failure an error is. Bad input (the user must change a file or
// a flag) and a run-time limit or I/O failure (the input was fine) map to the
// exit statuses 2 and 1 of the `sylva` command.
enum class ErrorKind { kInput, kRuntime };

struct SourceLoc {
  std::string file;  // as the user named it (or as resolved for #include)
  int line = 0;      // 1-based; 0 = no position
  int column = 0;    // 1-based byte column; 0 = whole line
};

struct Diagnostic {
  Severity severity = Severity::kError;
  ErrorKind kind = ErrorKind::kInput;
  SourceLoc loc;
  int length = 1;          // columns underlined by the caret
  std::string message;
  std::string sourceLine;  // the text of loc.line, for the excerpt; may be empty

  // "file:line:col: error: message" plus excerpt lines, newline-terminated.
  std::string Format() const;
};

Diagnostic MakeError(SourceLoc loc, std::string message, int length = 1,
                     std::string sourceLine = {});

// Diagnostics of one run, in the order found.
struct DiagnosticList {
  std::vector<Diagnostic> items;

  void Add(Diagnostic d) { items.push_back(std::move(d)); }
  bool HasErrors() const;
  size_t ErrorCount() const;
  std::string FormatAll() const;
};

}  // namespace sylva
