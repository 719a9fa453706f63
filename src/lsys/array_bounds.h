// cpfg arrays read or written past their ends.
//
// cpfg does not stop a derivation on an array index out of bounds: its
// evaluator (vlab `cpfg/generate.c`, Eval, tARRAYREF) prints "Subscript out
// of range ... using N" and uses the nearest element, index 0 for a
// negative index and the last for one past the end, for reads and writes
// alike. Real files rely on it (vlab's CelticKnot reads `turn0[7]` of a
// 7-element array in its homomorphism). Sylva does the same, and says so:
// each index written in the grammar is a site, numbered when the grammar is
// parsed; the evaluator notes the indices out of bounds at each site, and
// after the derivation Warnings() gives one warning per array, at its first
// site that went out of bounds, with the range of indices seen there
// (`--strict` makes it an error). Notes come from every derivation thread.
#pragma once

#include <atomic>
#include <cmath>
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "core/diagnostic.h"

namespace sylva::lsys {

class ArrayBounds {
 public:
  // One index written in the grammar: the `dimension`-th index (1 on) of
  // array `array`, whose extent there is `size`. Returns the site's number
  // (1 on; 0 is no site). Not thread-safe: called while parsing.
  uint32_t AddSite(SourceLoc loc, std::string sourceLine, std::string array, int dimension,
                   uint32_t size);
  // At run time: site read index `index`, outside 0 .. size - 1 (finite).
  // Thread-safe, lock-free.
  void Note(uint32_t site, double index);
  // One warning per array that went out of bounds since the grammar was
  // parsed, in the order of its sites in the file.
  std::vector<Diagnostic> Warnings() const;

 private:
  struct Site {
    SourceLoc loc;
    std::string sourceLine;
    std::string array;
    int dimension = 1;
    uint32_t size = 0;
    // Of the indices out of bounds; lowest > highest: none yet.
    std::atomic<double> lowest{HUGE_VAL}, highest{-HUGE_VAL};
  };
  std::deque<Site> sites_;  // a deque: sites never move (their atomics)
  bool multiDimensional_ = false;
};

}  // namespace sylva::lsys
