#include "core/diagnostic.h"

#include <cstdio>
#include <cstdlib>

#include "core/assert.h"

namespace sylva {

namespace detail {
void AssertFail(const char* cond, const char* file, int line) {
  std::fprintf(stderr, "%s:%d: internal error: assertion failed: %s\n", file, line, cond);
  std::abort();
}
}  // namespace detail

static const char* SeverityName(Severity s) {
  switch (s) {
    case Severity::kNote: return "note";
    case Severity::kWarning: return "warning";
    case Severity::kError: return "error";
  }
  return "error";
}

std::string Diagnostic::Format() const {
  std::string out;
  if (loc.file.empty()) {
    out += "sylva";
  } else {
    out += loc.file;
    if (loc.line > 0) {
      out += ':' + std::to_string(loc.line);
      if (loc.column > 0) out += ':' + std::to_string(loc.column);
    }
  }
  out += ": ";
  out += SeverityName(severity);
  out += ": ";
  out += message;
  out += '\n';
  if (loc.line > 0 && !sourceLine.empty()) {
    std::string num = std::to_string(loc.line);
    // Printable excerpt: control bytes become spaces so the caret lines up.
    std::string text = sourceLine;
    for (char& c : text) {
      if (static_cast<unsigned char>(c) < 32) c = ' ';
    }
    out += ' ' + std::string(num.size() < 4 ? 4 - num.size() : 0, ' ') + num + " | " + text + '\n';
    out += ' ' + std::string(num.size() < 4 ? 4 : num.size(), ' ') + " | ";
    if (loc.column > 0) {
      out += std::string(loc.column - 1, ' ');
      out += '^';
      if (length > 1) out += std::string(length - 1, '~');
    }
    out += '\n';
  }
  return out;
}

Diagnostic MakeError(SourceLoc loc, std::string message, int length, std::string sourceLine) {
  Diagnostic d;
  d.severity = Severity::kError;
  d.loc = std::move(loc);
  d.length = length < 1 ? 1 : length;
  d.message = std::move(message);
  d.sourceLine = std::move(sourceLine);
  return d;
}

bool DiagnosticList::HasErrors() const { return ErrorCount() > 0; }

size_t DiagnosticList::ErrorCount() const {
  size_t n = 0;
  for (const auto& d : items) n += d.severity == Severity::kError;
  return n;
}

std::string DiagnosticList::FormatAll() const {
  std::string out;
  for (const auto& d : items) out += d.Format();
  return out;
}

}  // namespace sylva
