#include "lsys/matcher.h"

#include <vector>

namespace sylva::lsys {

void ComputeBracketMatch(const SymbolId* symbols, size_t n, uint32_t* match) {
  std::vector<uint32_t> stack;
  stack.reserve(256);
  for (size_t i = 0; i < n; ++i) {
    SymbolId s = symbols[i];
    if (s == kOpenBracket) {
      stack.push_back(uint32_t(i));
      match[i] = kNoMatch;
    } else if (s == kCloseBracket) {
      if (stack.empty()) {
        match[i] = kNoMatch;
      } else {
        uint32_t o = stack.back();
        stack.pop_back();
        match[i] = o;
        match[o] = uint32_t(i);
      }
    }
  }
}

static inline void Bind(const FormalModule& fm, const WordView& w, size_t j, double* formals) {
  if (!w.paramStart) return;
  uint32_t a = w.paramStart[j], b = w.paramStart[j + 1];
  double* dst = formals + fm.firstFormal;
  for (uint32_t k = a; k < b; ++k) *dst++ = w.params[k];
}

bool MatchLeft(const Production& p, const WordView& w, size_t prev, double* formals) {
  size_t j = prev;
  for (size_t c = p.left.size(); c-- > 0;) {
    if (j == kNoPosition || w.symbols[j] != p.left[c].symbol) return false;
    Bind(p.left[c], w, j, formals);
    if (c) j = PrevInContext(w, j);
  }
  return true;
}

// The position of the `]` that closes the branch holding position j (j
// itself when it is that `]`), or w.size: cpfg's skipright.
static size_t EndOfBranch(const WordView& w, size_t j) {
  while (j < w.size) {
    const SymbolId s = w.symbols[j];
    if (s == kCloseBracket) return j;
    if (s == kOpenBracket) {
      const uint32_t m = w.bracketMatch[j];
      if (m == kNoMatch) return w.size;
      j = size_t(m) + 1;
      continue;
    }
    ++j;
  }
  return w.size;
}

bool MatchRight(const Production& p, const WordView& w, size_t i, size_t next, double* formals) {
  // The parser rejects right contexts nested deeper than this.
  static constexpr int kMaxNesting = kMaxRightContextNesting;
  uint32_t opened[kMaxNesting];  // word positions of '[' the context descended into
  int depth = 0;
  size_t j = i + 1;
  bool first = true;
  const size_t n = w.size;
  for (const FormalModule& fm : p.right) {
    if (fm.symbol == kRestOfBranch) {  // cpfg's `=`: up to the `]` of this branch
      if (depth > 0) {
        const uint32_t m = w.bracketMatch[opened[depth - 1]];
        if (m == kNoMatch) return false;
        j = size_t(m);
      } else {
        j = EndOfBranch(w, j);
      }
      first = false;
      continue;
    }
    if (fm.symbol == kOpenBracket) {
      // Ignored modules first (an ignored `[` too: it then never matches,
      // as in cpfg).
      while (j < n && w.skip[w.symbols[j]]) ++j;
      if (j >= n && w.ring && depth == 0 && n > 0) {  // on around the ring
        j = 0;
        while (j < n && w.skip[w.symbols[j]]) ++j;
      }
      if (j >= n || w.symbols[j] != kOpenBracket || depth == kMaxNesting) return false;
      opened[depth++] = uint32_t(j);
      ++j;
      first = false;
      continue;
    }
    if (fm.symbol == kCloseBracket) {
      if (depth == 0) {  // out of the predecessor's branch, into its parent
        const size_t e = EndOfBranch(w, j);
        if (e >= n) return false;
        j = e + 1;
      } else {
        const uint32_t m = w.bracketMatch[opened[--depth]];
        if (m == kNoMatch) return false;
        j = size_t(m) + 1;
      }
      first = false;
      continue;
    }
    const size_t k = first ? next : NextInContext(w, j);
    first = false;
    if (k == kNoPosition || w.symbols[k] != fm.symbol) return false;
    Bind(fm, w, k, formals);
    j = k + 1;
  }
  return true;
}

}  // namespace sylva::lsys
