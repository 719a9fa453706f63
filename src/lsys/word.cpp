#include "lsys/word.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "core/rng.h"

namespace sylva::lsys {

void Word::Append(SymbolId s, std::span<const double> p) {
  if (!p.empty() && paramStart.empty()) {
    // First parameter: materialise offsets for the modules so far.
    paramStart.ResizeUninitialized(symbols.size() + 1);
    for (size_t i = 0; i <= symbols.size(); ++i) paramStart[i] = 0;
  }
  symbols.push_back(s);
  if (!paramStart.empty()) {
    params.append(p.data(), p.size());
    paramStart.push_back(uint32_t(params.size()));
  }
}

uint64_t HashWord(const Word& w) {
  uint64_t h = 0x243f6a8885a308d3ULL;
  const size_t n = w.size();
  // Fold symbols four at a time, then parameters as raw bits.
  size_t i = 0;
  for (; i + 4 <= n; i += 4) {
    uint64_t v;
    std::memcpy(&v, w.symbols.data() + i, 8);
    h = Mix64(h ^ v) + i;
  }
  for (; i < n; ++i) h = Mix64(h ^ w.symbols[i]) + i;
  for (size_t k = 0; k < w.params.size(); ++k) {
    uint64_t bits;
    double p = w.params[k];
    if (p == 0) p = 0;  // -0 and +0 print the same; hash the same
    std::memcpy(&bits, &p, 8);
    h = Mix64(h ^ bits) + k;
  }
  if (!w.paramStart.empty()) {
    for (size_t k = 0; k <= n; ++k) h = Mix64(h ^ w.paramStart[k]);
  }
  return Mix64(h ^ n);
}

void AppendNumber(std::string& out, double v) {
  if (v == 0) v = 0;  // print -0 as 0
  // std::to_chars with a precision is specified to print as printf's %.6g
  // does, in the C locale; it is several times faster.
  char tmp[32];
  auto r = std::to_chars(tmp, tmp + sizeof tmp, v, std::chars_format::general, 6);
  out.append(tmp, size_t(r.ptr - tmp));
}

std::string FormatWord(const Word& w, const SymbolTable& table) {
  std::string out;
  FormatWord(w, table, [&](std::string_view piece) { out += piece; });
  return out;
}

}  // namespace sylva::lsys
