// cpfg's data files: fopen, fscanf, fclose (see cpfg_data_files.h).
#include "lsys/cpfg_data_files.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>

namespace sylva::lsys {
namespace {

bool IsBlank(char c) {
  return std::isspace(static_cast<unsigned char>(c)) != 0;
}

std::string Shown(char c) {
  if (c == '\n') return "a line break";
  if (c == '\t') return "a tab";
  if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) >= 127) {
    char b[16];
    std::snprintf(b, sizeof b, "byte 0x%02x", static_cast<unsigned char>(c));
    return b;
  }
  return std::string("'") + c + "'";
}

// How many characters of t[p, p + room) scanf takes for a number: the
// longest run that can begin one (sign, digits, '.', exponent with its
// sign, 0x, inf, nan), as glibc's scanf reads it before converting (it
// takes `1e` of `1e,` and converts it to 1: it cannot push back more than
// one character).
size_t NumberPrefix(const std::string& t, size_t p, size_t room, bool real, int base) {
  const size_t end = p + room;
  size_t q = p;
  auto at = [&](size_t i) { return i < end ? t[i] : '\0'; };
  auto lower = [](char c) { return char(std::tolower(static_cast<unsigned char>(c))); };
  if (at(q) == '+' || at(q) == '-') ++q;
  if (real) {
    for (const char* word : {"infinity", "inf", "nan"}) {
      size_t k = 0;
      while (word[k] && lower(at(q + k)) == word[k]) ++k;
      if (!word[k]) return q + k - p;
    }
  }
  bool hex = base == 16;
  if ((base == 16 || base == 0 || real) && at(q) == '0' && lower(at(q + 1)) == 'x' &&
      std::isxdigit(static_cast<unsigned char>(at(q + 2)))) {  // 0x, with a digit in the width
    q += 2;
    hex = true;
  } else if (base == 0 && at(q) == '0') {
    base = 8;
  }
  auto digit = [&](char c) {
    if (hex) return std::isxdigit(static_cast<unsigned char>(c)) != 0;
    if (base == 8) return c >= '0' && c <= '7';
    return std::isdigit(static_cast<unsigned char>(c)) != 0;
  };
  while (digit(at(q))) ++q;
  if (!real) return q - p;
  if (at(q) == '.') {
    ++q;
    while (digit(at(q))) ++q;
  }
  const char e = lower(at(q));
  if ((!hex && e == 'e') || (hex && e == 'p')) {
    ++q;
    if (at(q) == '+' || at(q) == '-') ++q;
    while (std::isdigit(static_cast<unsigned char>(at(q)))) ++q;
  }
  return q - p;
}

}  // namespace

std::string UnescapeC(std::string_view body) {
  std::string s;
  s.reserve(body.size());
  for (size_t i = 0; i < body.size(); ++i) {
    if (body[i] != '\\' || i + 1 >= body.size()) {
      s += body[i];
      continue;
    }
    const char e = body[++i];
    switch (e) {
      case 'n':
        s += '\n';
        break;
      case 't':
        s += '\t';
        break;
      case 'r':
        s += '\r';
        break;
      case 'a':
        s += '\a';
        break;
      case 'b':
        s += '\b';
        break;
      case 'f':
        s += '\f';
        break;
      case 'v':
        s += '\v';
        break;
      case '0':
        s += '\0';
        break;
      default:
        s += e;  // \\ \" \' and the rest: the character itself
    }
  }
  return s;
}

bool ParseScanFormat(std::string_view f, ScanFormat* out, std::string* why) {
  using Kind = ScanFormat::Kind;
  ScanFormat fmt;
  auto blanks = [&] {
    if (fmt.directives.empty() || fmt.directives.back().kind != Kind::kBlanks)
      fmt.directives.push_back({Kind::kBlanks});
  };
  for (size_t i = 0; i < f.size(); ++i) {
    const char c = f[i];
    if (IsBlank(c)) {
      blanks();
      continue;
    }
    if (c != '%') {
      ScanFormat::Directive d;
      d.kind = Kind::kLiteral;
      d.literal = c;
      fmt.directives.push_back(d);
      continue;
    }
    if (i + 1 < f.size() && f[i + 1] == '%') {  // %%: blanks, then '%'
      ++i;
      blanks();
      ScanFormat::Directive d;
      d.kind = Kind::kLiteral;
      d.literal = '%';
      fmt.directives.push_back(d);
      continue;
    }
    const size_t start = i;
    ScanFormat::Directive d;
    ++i;
    if (i < f.size() && f[i] == '*') {
      d.assign = false;
      ++i;
    }
    while (i < f.size() && std::isdigit(static_cast<unsigned char>(f[i]))) {
      if (d.width > 100000000) {
        *why = "the width of a conversion is too large";
        return false;
      }
      d.width = d.width * 10 + (f[i] - '0');
      ++i;
    }
    while (i < f.size() && std::strchr("hlLjztq", f[i])) ++i;  // length: all read as double
    if (i >= f.size()) {
      *why = "the format ends inside a conversion ('" + std::string(f.substr(start)) + "')";
      return false;
    }
    const char conv = f[i];
    const std::string spec(f.substr(start, i - start + 1));
    if (std::strchr("feEgGaAF", conv)) {
      d.kind = Kind::kReal;
    } else if (std::strchr("duixXo", conv)) {
      d.kind = Kind::kInteger;
      d.base = conv == 'i' ? 0 : (conv == 'x' || conv == 'X') ? 16 : conv == 'o' ? 8 : 10;
    } else if ((conv == 's' || conv == 'c') && !d.assign) {
      d.kind = conv == 's' ? Kind::kWord : Kind::kChars;
      if (conv == 'c' && d.width == 0) d.width = 1;
    } else if (conv == 's' || conv == 'c') {
      *why = "'" + spec + "' reads text, and cpfg's variables are numbers (write '%*" +
             std::string(1, conv) + "' to skip it)";
      return false;
    } else {
      *why = "'" + spec + "' is not a conversion Sylva reads (numbers: %lf %f %g %e %d %i; " +
             "skipped: %*s %*c)";
      return false;
    }
    if (d.assign) ++fmt.assignments;
    fmt.directives.push_back(d);
  }
  *out = std::move(fmt);
  return true;
}

CpfgDataFiles::CpfgDataFiles(std::string folder, Reader reader)
    : folder_(std::move(folder)), reader_(std::move(reader)) {}

bool CpfgDataFiles::Add(const std::string& name, uint32_t* file, std::string* why) {
  if (name.empty()) {
    *why = "empty file name";
    return false;
  }
  std::filesystem::path p(name);
  if (p.is_relative() && !folder_.empty()) p = std::filesystem::path(folder_) / p;
  const std::string path = p.lexically_normal().string();
  std::lock_guard<std::mutex> lock(mutex_);
  for (size_t i = 0; i < files_.size(); ++i) {
    if (files_[i].path == path) {
      *file = uint32_t(i);
      return true;
    }
  }
  auto text = reader_(path);
  if (!text) {
    *why = "cannot read data file '" + path + "': " + text.error().message;
    return false;
  }
  File f;
  f.path = path;
  f.text = std::move(*text);
  files_.push_back(std::move(f));
  *file = uint32_t(files_.size() - 1);
  return true;
}

uint32_t CpfgDataFiles::AddCall(Call call) {
  std::lock_guard<std::mutex> lock(mutex_);
  calls_.push_back(std::move(call));
  return uint32_t(calls_.size() - 1);
}

void CpfgDataFiles::Reset() {
  std::lock_guard<std::mutex> lock(mutex_);
  handles_.clear();
  for (File& f : files_) {
    f.shortReads = 0;
    f.firstShort.clear();
  }
}

double CpfgDataFiles::Open(uint32_t file) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (handles_.size() >= kMaxOpenDataFiles) return 0;
  handles_.push_back(Handle{file, 0, true});
  return double(handles_.size());
}

void CpfgDataFiles::Close(double handle) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (handle >= 1 && handle <= double(handles_.size()) && handle == std::floor(handle))
    handles_[size_t(handle) - 1].open = false;
}

bool CpfgDataFiles::Scan(double handle, uint32_t callIndex, double* values, int* count,
                         std::string* why) {
  using Kind = ScanFormat::Kind;
  std::lock_guard<std::mutex> lock(mutex_);
  if (!(handle >= 1 && handle <= double(handles_.size()) && handle == std::floor(handle)) ||
      !handles_[size_t(handle) - 1].open) {
    char b[200];
    std::snprintf(b, sizeof b,
                  "fscanf: the file pointer %.6g is not a file open for reading (fopen(NAME, "
                  "\"r\") gives one; fclose closes it)",
                  handle);
    *why = b;
    return false;
  }
  Handle& h = handles_[size_t(handle) - 1];
  File& file = files_[h.file];
  const std::string& t = file.text;
  const ScanFormat& fmt = calls_[callIndex].format;
  size_t p = h.pos;
  int assigned = 0;
  bool inputFailure = false;
  std::string stopped;  // empty: the whole format was read
  auto skipBlanks = [&] {
    while (p < t.size() && IsBlank(t[p])) ++p;
  };
  auto lineAt = [&](size_t at) {
    size_t line = 1;
    for (size_t i = 0; i < at && i < t.size(); ++i) line += t[i] == '\n';
    return std::to_string(line);
  };
  for (const ScanFormat::Directive& d : fmt.directives) {
    if (d.kind == Kind::kBlanks) {
      skipBlanks();
      continue;
    }
    if (d.kind != Kind::kLiteral && d.kind != Kind::kChars) skipBlanks();
    if (p >= t.size()) {
      inputFailure = true;
      stopped = "at the end of the file";
      break;
    }
    if (d.kind == Kind::kLiteral) {
      if (t[p] != d.literal) {
        stopped = "at line " + lineAt(p) + ": the format expects " + Shown(d.literal) +
                  ", the file has " + Shown(t[p]);
        break;
      }
      ++p;
      continue;
    }
    const size_t room = d.width > 0 ? std::min(size_t(d.width), t.size() - p) : t.size() - p;
    if (d.kind == Kind::kWord || d.kind == Kind::kChars) {
      size_t n = 0;
      while (n < room && (d.kind == Kind::kChars || !IsBlank(t[p + n]))) ++n;
      p += n;
      continue;
    }
    // A number: the characters scanf takes for one, converted by
    // strtod/strtoll (which must use at least one of them).
    const size_t taken = NumberPrefix(t, p, room, d.kind == Kind::kReal, d.base);
    const std::string text = t.substr(p, taken);
    char* end = nullptr;
    double v = 0;
    if (d.kind == Kind::kReal) {
      v = std::strtod(text.c_str(), &end);
    } else {
      v = double(std::strtoll(text.c_str(), &end, d.base));
    }
    if (taken == 0 || end == text.c_str()) {
      p += taken;
      stopped = "at line " + lineAt(p) + ": the format expects a number, the file has " +
                (p < t.size() ? Shown(t[p]) : std::string("its end"));
      break;
    }
    if (!std::isfinite(v)) {
      *why = "fscanf read a number that is not finite ('" + text.substr(0, 40) + "') at line " +
             lineAt(p) + " of " + file.path;
      return false;
    }
    p += taken;
    if (d.assign) values[assigned++] = v;
  }
  h.pos = p;
  // glibc's rule (cpfg's C library): EOF when the input ends before any
  // value was assigned.
  *count = inputFailure && assigned == 0 ? -1 : assigned;
  if (!stopped.empty()) {
    if (file.shortReads++ == 0) file.firstShort = stopped;
  }
  return true;
}

std::vector<Diagnostic> CpfgDataFiles::ShortReads() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<Diagnostic> out;
  for (const File& f : files_) {
    if (f.shortReads == 0) continue;
    Diagnostic d;
    d.severity = Severity::kWarning;
    d.loc.file = f.path;
    d.message = "fscanf stopped before the end of its format " + std::to_string(f.shortReads) +
                (f.shortReads == 1 ? " time" : " times") + " reading this file (first " +
                f.firstShort + "): the variables it did not read kept their values";
    out.push_back(std::move(d));
  }
  return out;
}

}  // namespace sylva::lsys
