// Template part of word.h: streaming canonical text.
//
// Names come from a flat table built once per call; when every name in the
// table is one character and the word has no parameters (Koch curves,
// bracketed plants) each module is one table lookup and one byte store.
#pragma once

#include <string>
#include <vector>

namespace sylva::lsys {

template <typename Sink>
void FormatWord(const Word& w, const SymbolTable& table, Sink&& sink) {
  static constexpr size_t kBlock = 1 << 20;
  const size_t n = w.size();
  const size_t nsym = table.size();
  std::vector<char> single(nsym);
  bool allSingle = true;
  for (size_t s = 0; s < nsym; ++s) {
    const std::string& name = table.name(SymbolId(s));
    allSingle &= name.size() == 1;
    single[s] = name.empty() ? '?' : name[0];
  }
  std::string buf;
  if (allSingle && !w.HasParams()) {
    buf.resize(std::min(kBlock, n));  // a short word clears no megabyte
    const SymbolId* sym = w.symbols.data();
    const char* lut = single.data();
    for (size_t i = 0; i < n; i += kBlock) {
      const size_t m = std::min(kBlock, n - i);
      char* out = buf.data();
      for (size_t k = 0; k < m; ++k) out[k] = lut[sym[i + k]];
      sink(std::string_view(buf.data(), m));
    }
    return;
  }
  buf.reserve(std::min(kBlock, 16 * n) + 4096);
  const bool hasParams = w.HasParams();
  for (size_t i = 0; i < n; ++i) {
    const SymbolId s = w.symbols[i];
    if (allSingle) {
      buf += single[s];
    } else {
      buf += table.name(s);
    }
    if (hasParams && w.paramStart[i] != w.paramStart[i + 1]) {
      buf += '(';
      for (uint32_t k = w.paramStart[i]; k < w.paramStart[i + 1]; ++k) {
        if (k != w.paramStart[i]) buf += ',';
        AppendNumber(buf, w.params[k]);
      }
      buf += ')';
    }
    if (buf.size() >= kBlock) {
      sink(std::string_view(buf));
      buf.clear();
    }
  }
  if (!buf.empty()) sink(std::string_view(buf));
}

}  // namespace sylva::lsys
