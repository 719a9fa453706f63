// Word: a derived string of modules, stored compactly.
//
//   symbols     one SymbolId (2 bytes) per module
//   params      every parameter of every module, in order (8-byte doubles)
//   paramStart  size()+1 offsets into params, or empty when params is empty
//
// A word without parameters (Koch curves, bracketed plants) costs 2 bytes a
// module; a parametric one 6 bytes a module plus 8 per parameter. Parameters
// are 64-bit doubles: exact integers up to 2^53 and the same rounding as the
// expressions that computed them.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "core/pod_buffer.h"
#include "lsys/symbols.h"

namespace sylva::lsys {

struct Word {
  PodBuffer<SymbolId> symbols;
  PodBuffer<uint32_t> paramStart;
  PodBuffer<double> params;

  size_t size() const { return symbols.size(); }
  bool empty() const { return symbols.empty(); }
  bool HasParams() const { return !params.empty(); }
  std::span<const double> ParamsOf(size_t i) const {
    if (paramStart.empty()) return {};
    return {params.data() + paramStart[i], params.data() + paramStart[i + 1]};
  }
  size_t MemoryBytes() const {
    return symbols.MemoryBytes() + paramStart.MemoryBytes() + params.MemoryBytes();
  }

  void Clear() {
    symbols.clear();
    paramStart.clear();
    params.clear();
  }
  // Appends one module (slow path: building axioms and tests).
  void Append(SymbolId s, std::span<const double> p);
};

// 64-bit hash of the word's content (symbols and parameter bits); equal words
// hash equal on every machine.
uint64_t HashWord(const Word& w);

// Writes the canonical text: names, parameters as %.6g in parentheses,
// comma-separated, no spaces. `sink` is called with pieces of about 1 MiB.
template <typename Sink>
void FormatWord(const Word& w, const SymbolTable& table, Sink&& sink);
std::string FormatWord(const Word& w, const SymbolTable& table);

// Appends one number as %.6g would print it.
void AppendNumber(std::string& out, double v);

}  // namespace sylva::lsys

#include "lsys/word_format.inl"
