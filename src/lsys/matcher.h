// Context matching on the branching structure (ABOP section 1.8; cpfg).
//
// The left context is read backwards from the predecessor along the path to
// the root: a complete sibling branch `[...]` met on the way is skipped
// whole (jumping from its `]` to its `[` in O(1) with the bracket match
// table), and an enclosing `[` is stepped out of, to the parent. The right
// context is read forwards along the same branch: sibling branches that the
// context does not name are skipped whole; a `[` in the context descends
// into a branch; a `]` in the context skips the rest of that branch (one
// without its `[` leaves the predecessor's branch into its parent, as in
// cpfg); cpfg's `=` (kRestOfBranch) skips to the `]` that ends the current
// branch; otherwise the word's `]` ends the current branch, and the right
// context does not cross it. Symbols flagged in `skip` (ignore:/consider:)
// are passed over. The right context checks `skip` before the brackets, as
// cpfg's RconDiff: an ignored `[` or `]` is passed over like any module
// (the context then reads into and out of branches); the left context
// always follows the branching (cpfg's LconDiff). Both matchers bind the
// context modules' parameters into the formal slots.
//
// A ring word (cpfg's `ring lsystem`, WordView::ring) closes on itself: a
// left context that reaches the start of the word goes on from its end,
// and a right context that reaches the end goes on from its start, each at
// most once per module read, so a word of ignored modules does not loop.
#pragma once

#include <cstdint>

#include "lsys/grammar.h"

namespace sylva::lsys {

inline constexpr uint32_t kNoMatch = 0xFFFFFFFFu;

struct WordView {
  const SymbolId* symbols = nullptr;
  size_t size = 0;
  const uint32_t* paramStart = nullptr;  // null when the word has no parameters
  const double* params = nullptr;
  const uint32_t* bracketMatch = nullptr;  // at '[' and ']' positions; kNoMatch if unbalanced
  const uint8_t* skip = nullptr;           // per symbol id
  bool ring = false;  // cpfg's ring L-system: the last module is the first one's left neighbour
};

// Bracket partners of every '[' and ']' (other entries are left unset).
void ComputeBracketMatch(const SymbolId* symbols, size_t n, uint32_t* match);

// The nearest module before position j that the left context sees, or
// kNoPosition (start of the word).
inline constexpr size_t kNoPosition = ~size_t(0);
inline size_t PrevInContext(const WordView& w, size_t j);
// The first module at or after position j that the right context sees on the
// current branch, or kNoPosition (end of the branch or of the word).
inline size_t NextInContext(const WordView& w, size_t j);

// `prev` / `next` are PrevInContext(w, i) and NextInContext(w, i + 1), which
// callers compute once per module and share between productions.
bool MatchLeft(const Production& p, const WordView& w, size_t prev, double* formals);
bool MatchRight(const Production& p, const WordView& w, size_t i, size_t next, double* formals);

// --- inline definitions (hot: called once or twice per module) ---

inline size_t PrevInContext(const WordView& w, size_t j) {
  bool wrapped = false;
  for (;;) {
    if (j == 0) {
      if (!w.ring || wrapped || w.size == 0) return kNoPosition;
      wrapped = true;
      j = w.size;  // the ring's last module is the first one's left neighbour
    }
    --j;
    const SymbolId s = w.symbols[j];
    if (s == kCloseBracket) {
      const uint32_t m = w.bracketMatch[j];
      if (m == kNoMatch) return kNoPosition;
      j = m;  // skip the sibling branch; the loop steps before its '['
      continue;
    }
    if (s == kOpenBracket || w.skip[s]) continue;  // step out to the parent / ignored
    return j;
  }
}

inline size_t NextInContext(const WordView& w, size_t j) {
  bool wrapped = false;
  for (;;) {
    if (j >= w.size) {
      if (!w.ring || wrapped || w.size == 0) return kNoPosition;
      wrapped = true;
      j = 0;  // the ring's first module is the last one's right neighbour
    }
    const SymbolId s = w.symbols[j];
    if (w.skip[s]) {  // ignored (a bracket too, when ignore: names it)
      ++j;
      continue;
    }
    if (s == kOpenBracket) {  // a sibling branch the context does not name
      const uint32_t m = w.bracketMatch[j];
      if (m == kNoMatch) return kNoPosition;
      j = size_t(m) + 1;
      continue;
    }
    if (s == kCloseBracket) return kNoPosition;  // end of this branch
    return j;
  }
}

}  // namespace sylva::lsys
