// Diagnostic: one message about user input, with its location.
//
// Printed GCC style, with the source line and a caret under the offending
// columns:
//   grammars/tree.lsys:14:23: error: unknown name 'r3' in expression
//      14 | A(l,w) --> !(w)F(l)[&(a0)B(l*r3,w*wr)]
//         |                               ^~
// Lines and columns are 1-based; column counts bytes. A diagnostic with no
// file (command-line errors) prints "sylva: error: ...".
//
// The excerpt is a window of at most about 100 columns around the caret,
// with "..." where the line goes on; bytes that are not valid UTF-8 print as
// \xNN and control bytes as spaces, and the caret stays under its column.
#pragma once

#include <string>
#include <string_view>
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
  int length = 1;  // columns underlined by the caret
  std::string message;
  // The text of loc.line (or the part of it around loc.column that
  // SetExcerpt keeps), for the excerpt; may be empty.
  std::string sourceLine;
  int sourceLineOffset = 0;    // bytes of the line cut before sourceLine
  bool sourceLineCut = false;  // the line goes on after sourceLine

  // "file:line:col: error: message" plus excerpt lines, newline-terminated.
  std::string Format() const;
};

// Sets d.sourceLine to the part of `line` around d.loc.column that an
// excerpt can show (a few hundred bytes at most, whatever the line's length).
void SetExcerpt(Diagnostic& d, std::string_view line);

Diagnostic MakeError(SourceLoc loc, std::string message, int length = 1,
                     std::string_view sourceLine = {});

// Diagnostics of one run, in the order found.
struct DiagnosticList {
  std::vector<Diagnostic> items;
  size_t droppedErrors = 0;  // errors found but not kept (a reader's own limit)

  void Add(Diagnostic d) { items.push_back(std::move(d)); }
  bool HasErrors() const;
  size_t ErrorCount() const;
  // Every diagnostic, or at most maxErrors errors and maxErrors warnings
  // followed by "sylva: note: N more errors not shown" (0 = no limit).
  std::string FormatAll(size_t maxErrors = 0) const;
};

}  // namespace sylva
