#include "scene/values.h"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "mesh/color.h"

namespace sylva::scene {
namespace {

bool IsSpace(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r';
}

template <typename T>
Parsed<T> Fail(std::string message, size_t at, int length = 1) {
  Parsed<T> p;
  p.error = ValueError{std::move(message), at, std::max(1, length)};
  return p;
}

// Splits on white space, remembering where each word starts.
struct Word {
  std::string_view text;
  size_t at;
};
std::vector<Word> Words(std::string_view s) {
  std::vector<Word> out;
  size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && IsSpace(s[i])) ++i;
    const size_t start = i;
    while (i < s.size() && !IsSpace(s[i])) ++i;
    if (i > start) out.push_back(Word{s.substr(start, i - start), start});
  }
  return out;
}

// Decimal syntax only: [+-] digits [. digits] [e [+-] digits].
bool IsDecimal(std::string_view s) {
  size_t i = 0, digits = 0;
  if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
  while (i < s.size() && s[i] >= '0' && s[i] <= '9') ++i, ++digits;
  if (i < s.size() && s[i] == '.') {
    ++i;
    while (i < s.size() && s[i] >= '0' && s[i] <= '9') ++i, ++digits;
  }
  if (digits == 0) return false;
  if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
    ++i;
    if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
    size_t expDigits = 0;
    while (i < s.size() && s[i] >= '0' && s[i] <= '9') ++i, ++expDigits;
    if (expDigits == 0) return false;
  }
  return i == s.size();
}

std::string Quote(std::string_view s) {
  if (s.size() > 40) return "'" + std::string(s.substr(0, 37)) + "...'";
  return "'" + std::string(s) + "'";
}

}  // namespace

Parsed<double> ParseNumber(std::string_view text) {
  const std::vector<Word> w = Words(text);
  if (w.empty()) return Fail<double>("expected a number, found an empty value", 0);
  if (w.size() > 1)
    return Fail<double>("expected one number, found " + std::to_string(w.size()) + " values",
                        w[1].at, int(w[1].text.size()));
  if (!IsDecimal(w[0].text))
    return Fail<double>("expected a decimal number, found " + Quote(w[0].text), w[0].at,
                        int(w[0].text.size()));
  const std::string s(w[0].text);
  errno = 0;
  const double v = std::strtod(s.c_str(), nullptr);
  if (!std::isfinite(v) || errno == ERANGE) {
    if (std::isfinite(v) && std::fabs(v) < 1) {
      Parsed<double> p;  // underflow to a subnormal or zero is fine
      p.value = v;
      return p;
    }
    return Fail<double>("number " + Quote(w[0].text) + " is out of range", w[0].at,
                        int(w[0].text.size()));
  }
  Parsed<double> p;
  p.value = v;
  return p;
}

Parsed<std::vector<double>> ParseNumbers(std::string_view text, size_t n) {
  const std::vector<Word> w = Words(text);
  if (w.size() != n) {
    const size_t at = w.size() > n ? w[n].at : (w.empty() ? 0 : w.back().at);
    return Fail<std::vector<double>>("expected " + std::to_string(n) +
                                         " numbers separated by "
                                         "spaces, found " +
                                         std::to_string(w.size()),
                                     at);
  }
  std::vector<double> out;
  for (const Word& word : w) {
    Parsed<double> p = ParseNumber(word.text);
    if (!p.ok()) {
      p.error.at += word.at;
      return Fail<std::vector<double>>(p.error.message, p.error.at, p.error.length);
    }
    out.push_back(*p.value);
  }
  Parsed<std::vector<double>> p;
  p.value = std::move(out);
  return p;
}

Parsed<uint64_t> ParseCount(std::string_view text, uint64_t max) {
  Parsed<double> n = ParseNumber(text);
  if (!n.ok()) return Fail<uint64_t>(n.error.message, n.error.at, n.error.length);
  const double v = *n.value;
  if (v < 0 || v != std::floor(v))
    return Fail<uint64_t>("expected a whole number of 0 or more, found " + Quote(text), 0,
                          int(text.size()));
  if (v > double(max))
    return Fail<uint64_t>("count " + Quote(text) + " is above the limit of " + std::to_string(max),
                          0, int(text.size()));
  Parsed<uint64_t> p;
  p.value = uint64_t(v);
  return p;
}

Parsed<Vec3> ParseVec3(std::string_view text) {
  Parsed<std::vector<double>> n = ParseNumbers(text, 3);
  if (!n.ok()) return Fail<Vec3>(n.error.message, n.error.at, n.error.length);
  Parsed<Vec3> p;
  p.value = Vec3((*n.value)[0], (*n.value)[1], (*n.value)[2]);
  return p;
}

Parsed<Vec3> ParseColor(std::string_view text) {
  const std::vector<Word> w = Words(text);
  if (w.size() == 1 && !w[0].text.empty() && w[0].text[0] == '#') {
    const std::string_view hex = w[0].text.substr(1);
    bool ok = hex.size() == 6;
    for (char c : hex) ok = ok && std::isxdigit(static_cast<unsigned char>(c));
    if (!ok)
      return Fail<Vec3>(
          "expected a colour '#rrggbb' (six hexadecimal digits), found " + Quote(w[0].text),
          w[0].at, int(w[0].text.size()));
    const unsigned long rgb = std::strtoul(std::string(hex).c_str(), nullptr, 16);
    const Vec3f lin = mesh::Srgb(float((rgb >> 16) & 255) / 255.f, float((rgb >> 8) & 255) / 255.f,
                                 float(rgb & 255) / 255.f);
    Parsed<Vec3> p;
    p.value = lin.cast<double>();
    return p;
  }
  if (w.size() != 3)
    return Fail<Vec3>("expected a colour: '#rrggbb' (sRGB) or 'r g b' (linear, 0 to 1)", 0,
                      int(text.size()));
  Parsed<Vec3> v = ParseVec3(text);
  if (!v.ok()) return v;
  for (int i = 0; i < 3; ++i) {
    if ((*v.value)[i] < 0 || (*v.value)[i] > 1)
      return Fail<Vec3>("colour component " + Quote(w[size_t(i)].text) +
                            " is outside 0..1 (linear 'r g b'; use '#rrggbb' for sRGB)",
                        w[size_t(i)].at, int(w[size_t(i)].text.size()));
  }
  return v;
}

Parsed<bool> ParseBool(std::string_view text) {
  Parsed<bool> p;
  if (text == "true") p.value = true;
  if (text == "false") p.value = false;
  if (!p.ok())
    return Fail<bool>("expected 'true' or 'false', found " + Quote(text), 0, int(text.size()));
  return p;
}

Parsed<std::vector<std::string>> ParseNames(std::string_view text) {
  const std::vector<Word> w = Words(text);
  if (w.empty()) return Fail<std::vector<std::string>>("expected one or more ids", 0);
  Parsed<std::vector<std::string>> p;
  p.value.emplace();
  for (const Word& word : w) p.value->emplace_back(word.text);
  return p;
}

}  // namespace sylva::scene
