// Template part of word.h: streaming canonical text.
#pragma once

#include <string>

namespace sylva::lsys {

template <typename Sink>
void FormatWord(const Word& w, const SymbolTable& table, Sink&& sink) {
  static constexpr size_t kFlush = 1 << 20;
  std::string buf;
  buf.reserve(kFlush + 4096);
  const size_t n = w.size();
  const bool hasParams = w.HasParams();
  for (size_t i = 0; i < n; ++i) {
    SymbolId s = w.symbols[i];
    buf += table.name(s);
    if (hasParams && w.paramStart[i] != w.paramStart[i + 1]) {
      buf += '(';
      for (uint32_t k = w.paramStart[i]; k < w.paramStart[i + 1]; ++k) {
        if (k != w.paramStart[i]) buf += ',';
        AppendNumber(buf, w.params[k]);
      }
      buf += ')';
    }
    if (buf.size() >= kFlush) {
      sink(std::string_view(buf));
      buf.clear();
    }
  }
  if (!buf.empty()) sink(std::string_view(buf));
}

}  // namespace sylva::lsys
