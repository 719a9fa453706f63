// Context matching on the branching structure (ABOP section 1.8; cpfg).
//
// The left context is read backwards from the predecessor along the path to
// the root: a complete sibling branch `[...]` met on the way is skipped
// whole (jumping from its `]` to its `[` in O(1) with the bracket match
// table), and an enclosing `[` is stepped out of, to the parent. The right
// context is read forwards along the same branch: sibling branches that the
// context does not name are skipped whole; a `[` in the context descends
// into a branch; a `]` in the context skips the rest of that branch; the
// word's `]` ends the current branch, and the right context never crosses
// it. Symbols flagged in `skip` (ignore:/consider:) are passed over. Both
// matchers bind the context modules' parameters into the formal slots.
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
};

// Bracket partners of every '[' and ']' (other entries are left unset).
void ComputeBracketMatch(const SymbolId* symbols, size_t n, uint32_t* match);

bool MatchLeft(const Production& p, const WordView& w, size_t i, double* formals);
bool MatchRight(const Production& p, const WordView& w, size_t i, double* formals);

}  // namespace sylva::lsys
