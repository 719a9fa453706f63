#include "core/diagnostic.h"

#include <algorithm>
#include <cstdint>
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

namespace {

// Length of the valid UTF-8 sequence at s[i], or 0 when the byte there does
// not start one (stray continuation, overlong form, surrogate, > U+10FFFF).
size_t Utf8Length(std::string_view s, size_t i) {
  const auto c = static_cast<unsigned char>(s[i]);
  if (c < 0x80) return 1;
  size_t n;
  uint32_t cp;
  if (c >= 0xC2 && c <= 0xDF) {
    n = 2, cp = c & 0x1Fu;
  } else if (c >= 0xE0 && c <= 0xEF) {
    n = 3, cp = c & 0x0Fu;
  } else if (c >= 0xF0 && c <= 0xF4) {
    n = 4, cp = c & 0x07u;
  } else {
    return 0;
  }
  if (i + n > s.size()) return 0;
  for (size_t k = 1; k < n; ++k) {
    const auto b = static_cast<unsigned char>(s[i + k]);
    if ((b & 0xC0) != 0x80) return 0;
    cp = (cp << 6) | (b & 0x3Fu);
  }
  if ((n == 3 && cp < 0x800) || (n == 4 && (cp < 0x10000 || cp > 0x10FFFF)) ||
      (cp >= 0xD800 && cp <= 0xDFFF))
    return 0;
  return n;
}

// The printable form of the character at s[i]: itself when valid UTF-8, a
// space for a control byte in an excerpt (\xNN elsewhere), \xNN for a byte
// that is not UTF-8. Returns the bytes consumed; *width is the columns shown.
size_t AppendPrintable(std::string_view s, size_t i, bool controlAsSpace, std::string* out,
                       int* width) {
  const auto c = static_cast<unsigned char>(s[i]);
  size_t n = (c < 32 || c == 127) ? 0 : Utf8Length(s, i);
  if (n == 0 && (c < 32 || c == 127) && controlAsSpace) {
    *out += ' ';
    *width = 1;
    return 1;
  }
  if (n == 0) {
    static const char kHex[] = "0123456789abcdef";
    *out += "\\x";
    *out += kHex[c >> 4];
    *out += kHex[c & 15];
    *width = 4;
    return 1;
  }
  out->append(s.substr(i, n));
  *width = 1;
  return n;
}

std::string Printable(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  int w;
  for (size_t i = 0; i < s.size();) i += AppendPrintable(s, i, false, &out, &w);
  return out;
}

// Bytes of a line kept around the caret: enough for the shown window even
// when every byte prints as \xNN, bounded whatever the line's length.
constexpr size_t kKeepBefore = 256, kKeepAfter = 512;
// Columns of the shown window: before the caret, and in all.
constexpr int kShowBefore = 40, kShowWidth = 100;

struct Window {
  size_t begin, end;
};

// [begin, end) of `line` around byte `caret`, cut at character boundaries.
Window KeepAround(std::string_view line, size_t caret) {
  size_t begin = caret > kKeepBefore ? caret - kKeepBefore : 0;
  while (begin < caret && begin < line.size() && (line[begin] & 0xC0) == 0x80) ++begin;
  size_t end = std::min(line.size(), caret + kKeepAfter);
  if (end < line.size()) {
    while (end > caret && (line[end] & 0xC0) == 0x80) --end;
  }
  return {begin, end};
}

// Messages quote user text (a name, a number); a quote of a megabyte-long
// token keeps its two ends.
constexpr size_t kMaxMessageBytes = 480;

std::string_view ShortMessage(std::string_view m, std::string* buffer) {
  if (m.size() <= kMaxMessageBytes) return m;
  const size_t half = kMaxMessageBytes / 2;
  size_t a = half, b = m.size() - half;
  while (a > 0 && (m[a] & 0xC0) == 0x80) --a;
  while (b < m.size() && (m[b] & 0xC0) == 0x80) ++b;
  *buffer = std::string(m.substr(0, a)) + "..." + std::string(m.substr(b));
  return *buffer;
}

const char* SeverityName(Severity s) {
  switch (s) {
    case Severity::kNote:
      return "note";
    case Severity::kWarning:
      return "warning";
    case Severity::kError:
      return "error";
  }
  return "error";
}

}  // namespace

void SetExcerpt(Diagnostic& d, std::string_view line) {
  const size_t caret = d.loc.column > 0 ? std::min(line.size(), size_t(d.loc.column - 1)) : 0;
  const Window w = KeepAround(line, caret);
  d.sourceLine.assign(line.substr(w.begin, w.end - w.begin));
  d.sourceLineOffset = int(w.begin);
  d.sourceLineCut = w.end < line.size();
}

std::string Diagnostic::Format() const {
  std::string out;
  if (loc.file.empty()) {
    out += "sylva";
  } else {
    out += Printable(loc.file);
    if (loc.line > 0) {
      out += ':' + std::to_string(loc.line);
      if (loc.column > 0) out += ':' + std::to_string(loc.column);
    }
  }
  out += ": ";
  out += SeverityName(severity);
  out += ": ";
  std::string shortened;
  out += Printable(ShortMessage(message, &shortened));
  out += '\n';
  if (loc.line <= 0 || sourceLine.empty()) return out;

  // The characters of the kept part of the line, with their widths.
  std::string_view full = sourceLine;
  long caretInFull = loc.column > 0 ? long(loc.column) - 1 - sourceLineOffset : 0;
  const size_t caret = size_t(std::clamp(caretInFull, 0L, long(full.size())));
  const Window kept = KeepAround(full, caret);
  std::string_view line = full.substr(kept.begin, kept.end - kept.begin);
  const size_t caretAt = caret - kept.begin;
  struct Char {
    size_t begin;
    int width;
    std::string text;
  };
  std::vector<Char> chars;
  size_t caretChar = SIZE_MAX;
  for (size_t i = 0; i < line.size();) {
    Char c{i, 0, {}};
    i += AppendPrintable(line, i, true, &c.text, &c.width);
    if (caretChar == SIZE_MAX && i > caretAt) caretChar = chars.size();
    chars.push_back(std::move(c));
  }
  if (caretChar == SIZE_MAX) caretChar = chars.size();

  // The window: up to kShowBefore columns before the caret, kShowWidth in all.
  size_t first = caretChar, last = caretChar;  // [first, last)
  int before = 0;
  while (first > 0 && before + chars[first - 1].width <= kShowBefore)
    before += chars[--first].width;
  int width = before;
  while (last < chars.size() && (last == caretChar || width + chars[last].width <= kShowWidth))
    width += chars[last++].width;
  const bool cutLeft = first > 0 || kept.begin > 0 || sourceLineOffset > 0;
  const bool cutRight = last < chars.size() || kept.end < full.size() || sourceLineCut;

  std::string num = std::to_string(loc.line);
  out += ' ' + std::string(num.size() < 4 ? 4 - num.size() : 0, ' ') + num + " | ";
  if (cutLeft) out += "...";
  for (size_t k = first; k < last; ++k) out += chars[k].text;
  if (cutRight) out += "...";
  out += '\n';
  out += ' ' + std::string(num.size() < 4 ? 4 : num.size(), ' ') + " |";
  if (loc.column > 0) {
    out += ' ';
    out += std::string(size_t((cutLeft ? 3 : 0) + before), ' ');
    // Underline the characters of [caret, caret + length) that are shown.
    int under = 0;
    const size_t endByte = caretAt + size_t(length > 1 ? length : 1);
    for (size_t k = caretChar; k < last && chars[k].begin < endByte; ++k) under += chars[k].width;
    out += '^';
    if (under > 1) out += std::string(size_t(under - 1), '~');
  }
  out += '\n';
  return out;
}

Diagnostic MakeError(SourceLoc loc, std::string message, int length, std::string_view sourceLine) {
  Diagnostic d;
  d.severity = Severity::kError;
  d.loc = std::move(loc);
  d.length = length < 1 ? 1 : length;
  std::string shortened;
  if (ShortMessage(message, &shortened).size() < message.size()) message = std::move(shortened);
  d.message = std::move(message);
  SetExcerpt(d, sourceLine);
  return d;
}

bool DiagnosticList::HasErrors() const {
  return ErrorCount() > 0;
}

size_t DiagnosticList::ErrorCount() const {
  size_t n = droppedErrors;
  for (const auto& d : items) n += d.severity == Severity::kError;
  return n;
}

std::string DiagnosticList::FormatAll(size_t maxErrors) const {
  std::string out;
  size_t errors = 0, warnings = 0, hiddenErrors = droppedErrors, hiddenWarnings = 0;
  for (const auto& d : items) {
    const bool error = d.severity == Severity::kError;
    size_t& shown = error ? errors : warnings;
    if (maxErrors > 0 && shown >= maxErrors) {
      ++(error ? hiddenErrors : hiddenWarnings);
      continue;
    }
    ++shown;
    out += d.Format();
  }
  if (hiddenErrors > 0) {
    out += "sylva: note: " + std::to_string(hiddenErrors) + " more error" +
           (hiddenErrors == 1 ? "" : "s") + " not shown\n";
  }
  if (hiddenWarnings > 0) {
    out += "sylva: note: " + std::to_string(hiddenWarnings) + " more warning" +
           (hiddenWarnings == 1 ? "" : "s") + " not shown\n";
  }
  return out;
}

}  // namespace sylva
