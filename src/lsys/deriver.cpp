#include "lsys/deriver.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <type_traits>

#include "core/parallel.h"
#include "core/rng.h"
#include "lsys/matcher.h"

namespace sylva::lsys {
namespace {

using Clock = std::chrono::steady_clock;

// Purposes of random draws; combined with the pass depth into the stream key.
enum : uint64_t {
  kAxiomDraws = 0,
  kMainDraws = 1,
  kDecompositionDraws = 2,
  kInterpretDraws = 3,
  kGlobalBlockDraws = 4,  // Start:, StartEach:, EndEach:, End:
};

constexpr uint32_t kIdentity = 0xFFFFFFFFu;
constexpr uint32_t kDynamic = 0xFFFFFFFEu;
// Per-module choices are stored in 16 bits (the parser allows at most
// kMaxProductionsPerSection productions per section).
constexpr uint16_t kIdentity16 = 0xFFFF;
// A module taken by the predecessor of several modules that starts before it.
constexpr uint16_t kConsumed16 = 0xFFFE;
static_assert(kMaxProductionsPerSection < kConsumed16);
constexpr size_t kMinChunk = 16384;
// Successors of up to kOverCopy symbols are copied as one fixed-size block
// (the table is padded, and the copy stays inside the chunk's own output).
constexpr size_t kOverCopy = 16;

std::string FormatParam(double v) {
  std::string s;
  AppendNumber(s, v);
  return s;
}

Diagnostic LimitError(const std::string& what) {
  Diagnostic d;
  d.kind = ErrorKind::kRuntime;
  d.message = what;
  return d;
}

// Table for sections whose production per symbol is fixed and parameter-free.
struct StaticTable {
  bool usable = false;
  std::vector<uint32_t> offset, length;  // per symbol, into flat
  std::vector<SymbolId> flat;            // padded by 8 for over-copying
};

StaticTable BuildStaticTable(const Grammar& g, const Section& sec) {
  StaticTable t;
  const size_t nsym = g.symbols.size();
  t.offset.resize(nsym);
  t.length.resize(nsym);
  for (size_t s = 0; s < nsym; ++s) {
    const auto& list = sec.bySymbol[s];
    t.offset[s] = uint32_t(t.flat.size());
    if (list.empty()) {
      t.flat.push_back(SymbolId(s));
      t.length[s] = 1;
      continue;
    }
    const Production& p = sec.productions[list[0]];
    if (p.HasContext() || p.condition || p.weight || p.HasBlocks() || !p.successor.params.empty() ||
        g.symbols.arity(SymbolId(s)) != 0 || !p.predTail.empty() || g.subLsystems)
      return t;  // not usable
    for (SymbolId x : p.successor.symbols) t.flat.push_back(x);
    t.length[s] = uint32_t(p.successor.symbols.size());
  }
  t.flat.resize(t.flat.size() + kOverCopy, 0);
  t.usable = true;
  return t;
}

// What Choose needs of a production, packed (16 bytes) and stored per symbol
// in file order, so trying the productions of a module touches one cache line.
struct ProdInfo {
  uint32_t index;        // into Section::productions
  SymbolId left0;        // the left-context module nearest the predecessor
  SymbolId right0;       // the first right-context module
  uint8_t leftKind;      // 0 none; 1 one module, no parameters; 2 anything else
  uint8_t rightKind;     // same for the right context
  uint8_t hasCondition;  // a condition or statement blocks
  uint8_t hasWeight;
  uint8_t hasBlocks;  // statement blocks (cpfg): the slow path of Matches
  // A predecessor of several modules, or a grammar with sub-L-systems:
  // MatchSpecial decides.
  uint8_t special = 0;
  uint16_t lsystem = 0;  // Production::lsystem
};
static_assert(sizeof(ProdInfo) == 16);

// Decision table of a symbol whose productions all have at most one
// parameter-free module of context on each side and no condition or weight:
// the first-match choice is then a function of the neighbours' symbols
// alone, looked up in O(1) instead of trying productions in turn. Class 0 of
// a side is "no neighbour, or a symbol no production names".
struct ContextTable {
  std::vector<uint8_t> leftClass, rightClass;  // per symbol id
  int rightClasses = 1;
  bool useLeft = false, useRight = false;
  std::vector<uint32_t> choice;  // [leftClass * rightClasses + rightClass]
};

struct Chunk {
  size_t begin = 0, end = 0;
  uint64_t inParam = 0;  // parameter offset of `begin` in the input
  uint64_t outModules = 0, outParams = 0;
  uint64_t outModuleAt = 0, outParamAt = 0;
  bool changed = false;
  // Successor parameters of the productions with statement blocks, computed
  // when the production is chosen (so the blocks run once, in word order),
  // in module order; Write takes them from stashAt on.
  std::vector<double> stash;
  size_t stashAt = 0;
  std::optional<Diagnostic> error;
};

// Buffers reused from step to step, so a derivation allocates (and the
// kernel zeroes) them once, not at every step.
struct Scratch {
  PodBuffer<uint16_t> choice;  // production chosen per module of the input (kIdentity16: none)
  PodBuffer<uint32_t> match;   // bracket partners
};

// The seed that cpfg's srand(seed) last set, or `seed` while it has not
// been called (its hidden global is NaN until then).
uint64_t SrandSeed(const Grammar& g, const double* globals, uint64_t seed) {
  if (g.srandGlobal < 0 || !globals) return seed;
  const double v = globals[size_t(g.srandGlobal)];
  if (!(std::abs(v) < 9e18)) return seed;
  return uint64_t(int64_t(std::trunc(v)));
}

// One parallel rewriting pass of one section over a word.
class Pass {
 public:
  Pass(const Grammar& g, const Section& sec, const StaticTable& table, ThreadPool& pool,
       Scratch& scratch, uint64_t seed, uint64_t purpose, uint64_t step, int stepForMessages,
       uint64_t maxModules, double* globals)
      : g_(g),
        sec_(sec),
        table_(table),
        pool_(pool),
        seed_(seed),
        purpose_(purpose),
        step_(step),
        stepForMessages_(stepForMessages),
        maxModules_(maxModules),
        choice_(scratch.choice),
        match_(scratch.match),
        globals_(globals) {
    reseeds_ = g.reseeds && globals != nullptr;
    for (const auto& p : sec.productions) {
      maxFormals_ = std::max<size_t>(maxFormals_, size_t(p.formalCount) + p.localCount);
      needsMatch_ |= p.HasContext();
      succModules_.push_back(uint32_t(p.successor.symbols.size()));
      succParams_.push_back(uint32_t(p.successor.params.size()));
      predLength_.push_back(uint32_t(p.PredLength()));
      anyBlocks_ |= p.HasBlocks();
      multi_ |= !p.predTail.empty();
    }
    special_ = multi_ || g.subLsystems;
    if (g.subLsystems) {  // the modules that start and end a sub-L-system
      subKind_.assign(g.symbols.size(), 0);
      for (size_t sy = 0; sy < g.symbols.size(); ++sy) {
        const std::string& name = g.symbols.name(SymbolId(sy));
        const int a = g.symbols.arity(SymbolId(sy));
        if (name == "?" && a >= 1) subKind_[sy] = 1;
        if (name == "$") subKind_[sy] = 2;
      }
    }
    // Per symbol: no production (identity), a production that always
    // applies first (its index), or a choice to make per module.
    infoStart_.push_back(0);
    for (size_t sy = 0; sy < sec.bySymbol.size(); ++sy) {
      for (uint32_t idx : sec.bySymbol[sy]) {
        const Production& p = sec.productions[idx];
        ProdInfo pi{};
        pi.index = idx;
        auto kind = [&](const std::vector<FormalModule>& ctx) -> uint8_t {
          if (ctx.empty()) return 0;
          if (ctx.size() == 1 && ctx[0].symbol != kRestOfBranch &&
              g.symbols.arity(ctx[0].symbol) == 0 && ctx[0].symbol != kOpenBracket &&
              ctx[0].symbol != kCloseBracket)
            return 1;
          return 2;
        };
        pi.leftKind = kind(p.left);
        pi.rightKind = kind(p.right);
        pi.left0 = p.left.empty() ? 0 : p.left.back().symbol;
        pi.right0 = p.right.empty() ? 0 : p.right.front().symbol;
        pi.hasCondition = p.condition.has_value() || p.HasBlocks();
        pi.hasBlocks = p.HasBlocks();
        pi.hasWeight = p.weight.has_value();
        pi.special = !p.predTail.empty() || g.subLsystems;
        pi.lsystem = p.lsystem;
        infos_.push_back(pi);
      }
      infoStart_.push_back(uint32_t(infos_.size()));
    }
    tables_.resize(sec.bySymbol.size());
    for (size_t sy = 0; sy < sec.bySymbol.size(); ++sy) BuildTable(SymbolId(sy));
    symChoice_.resize(sec.bySymbol.size());
    for (size_t s = 0; s < sec.bySymbol.size(); ++s) {
      const auto& list = sec.bySymbol[s];
      if (list.empty()) {
        symChoice_[s] = kIdentity;
        continue;
      }
      const Production& p = sec.productions[list[0]];
      symChoice_[s] = (p.HasContext() || p.condition || p.weight || p.HasBlocks() ||
                       !p.predTail.empty() || g.subLsystems)
                          ? kDynamic
                          : list[0];
    }
  }

  Status Run(const Word& in, Word& out, bool* changed);

 private:
  void SplitChunks(const Word& in);
  void MatchBrackets(const Word& in);
  Status Allocate(Word& out, bool outHasParams);
  // General path.
  bool Choose(const WordView& w, size_t i, double* formals, uint32_t* choice, Chunk& c);
  // 1 matches, 0 does not, -1 error (recorded in c).
  int Draw(const ProdInfo* pi, const ProdInfo* last, const WordView& w, size_t i, const double* pp,
           int arity, double* formals, size_t& prev, size_t& next, RandomStream& rng, Chunk& c,
           double* weights, uint32_t* cands, size_t capacity, uint32_t* choice);
  [[gnu::noinline]] bool DrawMany(const ProdInfo* pi, const ProdInfo* last, const WordView& w,
                                  size_t i, const double* pp, int arity, double* formals,
                                  size_t& prev, size_t& next, RandomStream rng, Chunk& c,
                                  uint32_t* choice);
  int Matches(const ProdInfo& pi, const WordView& w, size_t i, const double* pp, int arity,
              double* formals, size_t& prev, size_t& next, RandomStream& rng, Chunk& c);
  // Matches for a predecessor of several modules or a sub-L-system grammar.
  [[gnu::noinline]] int MatchSpecial(const ProdInfo& pi, const WordView& w, size_t i,
                                     const double* pp, int arity, double* formals,
                                     RandomStream& rng, Chunk& c);
  // Binds every formal of production p (chosen for module i): predecessor,
  // the modules after it, and its context read with its block's table.
  void BindSpecial(const Production& p, const WordView& w, size_t i, double* formals) const;
  // The word as seen by production p: its block's ignore:/consider:.
  WordView ViewFor(const Production& p, const WordView& w) const {
    WordView v = w;
    if (p.lsystem > 0 && !g_.lsystems[p.lsystem].contextSkip.empty())
      v.skip = g_.lsystems[p.lsystem].contextSkip.data();
    return v;
  }
  // The L-system block of every module of `in` (sub-L-systems).
  Status ComputeOwners(const Word& in);
  // The blocks and condition of a production with statement blocks.
  [[gnu::noinline]] int MatchBlocks(const Production& q, size_t i, double* formals,
                                    RandomStream& rng, Chunk& c);
  template <bool kMulti>  // some production has a predecessor of several modules
  void Write(const WordView& w, const Word& in, Word& out, Chunk& c, bool outHasParams);
  // Runs the successor of a production with statement blocks (vars bound)
  // and appends its parameters to c.stash; false on an error (in c).
  bool Stash(const Production& p, size_t i, double* vars, Chunk& c);
  // Binds the formals and context of production `index` for module i and
  // runs its blocks and condition again (a weighted production drawn).
  bool Rebind(uint32_t index, const WordView& w, size_t i, double* vars, Chunk& c);
  void Fail(Chunk& c, const Production& p, const EvalError& e, int column, size_t i);

  const Grammar& g_;
  const Section& sec_;
  const StaticTable& table_;
  ThreadPool& pool_;
  uint64_t seed_, purpose_, step_;
  // srand outside Start: (Grammar::reseeds): the seed each module of the
  // input is rewritten with, as srand left it when the module came up (the
  // pass then runs in word order on one chunk).
  bool reseeds_ = false;
  std::vector<uint64_t> moduleSeed_;
  uint64_t SeedOf(size_t i) const { return reseeds_ ? moduleSeed_[i] : seed_; }
  int stepForMessages_;
  uint64_t maxModules_;
  size_t maxFormals_ = 0;
  bool needsMatch_ = false;
  bool anyBlocks_ = false;            // some production has statement blocks
  bool multi_ = false;                // some production has a predecessor of several modules
  bool special_ = false;              // multi_, or a grammar with sub-L-systems
  std::vector<uint32_t> predLength_;  // per production
  std::vector<uint8_t> subKind_;      // per symbol: 1 `?(id..)`, 2 `$` (sub-L-systems only)
  std::vector<uint16_t> owner_;       // per module of the input: its L-system block
  std::vector<uint32_t> symChoice_;   // per symbol
  std::vector<ProdInfo> infos_;       // per symbol, in file order
  std::vector<uint32_t> infoStart_;   // symbol -> first info
  std::vector<std::unique_ptr<ContextTable>> tables_;  // per symbol, or null

  void BuildTable(SymbolId sym) {
    const ProdInfo* first = infos_.data() + infoStart_[sym];
    const ProdInfo* last = infos_.data() + infoStart_[sym + 1];
    if (first == last) return;
    std::vector<SymbolId> lefts, rights;
    for (const ProdInfo* pi = first; pi != last; ++pi) {
      if (pi->leftKind > 1 || pi->rightKind > 1 || pi->hasCondition || pi->hasWeight || pi->special)
        return;
      if (pi->leftKind && std::find(lefts.begin(), lefts.end(), pi->left0) == lefts.end())
        lefts.push_back(pi->left0);
      if (pi->rightKind && std::find(rights.begin(), rights.end(), pi->right0) == rights.end())
        rights.push_back(pi->right0);
    }
    if (lefts.empty() && rights.empty()) return;  // context-free: symChoice_ handles it
    if (lefts.size() > 254 || rights.size() > 254) return;
    auto t = std::make_unique<ContextTable>();
    const size_t nsym = g_.symbols.size();
    t->leftClass.assign(nsym, 0);
    t->rightClass.assign(nsym, 0);
    for (size_t k = 0; k < lefts.size(); ++k) t->leftClass[lefts[k]] = uint8_t(k + 1);
    for (size_t k = 0; k < rights.size(); ++k) t->rightClass[rights[k]] = uint8_t(k + 1);
    t->useLeft = !lefts.empty();
    t->useRight = !rights.empty();
    const int nl = int(lefts.size()) + 1, nr = int(rights.size()) + 1;
    t->rightClasses = nr;
    t->choice.assign(size_t(nl * nr), kIdentity);
    for (int lc = 0; lc < nl; ++lc) {
      for (int rc = 0; rc < nr; ++rc) {
        for (const ProdInfo* pi = first; pi != last; ++pi) {  // first match in file order
          if (pi->leftKind && (lc == 0 || lefts[lc - 1] != pi->left0)) continue;
          if (pi->rightKind && (rc == 0 || rights[rc - 1] != pi->right0)) continue;
          t->choice[size_t(lc * nr + rc)] = pi->index;
          break;
        }
      }
    }
    tables_[sym] = std::move(t);
  }
  std::vector<uint32_t> succModules_, succParams_;  // per production
  std::vector<Chunk> chunks_;
  PodBuffer<uint16_t>& choice_;
  PodBuffer<uint32_t>& match_;
  double* globals_;  // the grammar's global variables (null: none)
};

// Bracket partners in parallel: each chunk matches its own brackets and
// keeps the ones it cannot close (']' first, then '['); a sequential merge
// pairs those across chunks. The merge touches only brackets that span a
// chunk boundary, about depth x chunks of them.
void Pass::MatchBrackets(const Word& in) {
  const SymbolId* sym = in.symbols.data();
  uint32_t* match = match_.data();
  if (chunks_.size() == 1) {
    ComputeBracketMatch(sym, in.size(), match);
    return;
  }
  struct Open {
    std::vector<uint32_t> closes, opens;  // unmatched, in word order
  };
  std::vector<Open> open(chunks_.size());
  pool_.ParallelFor(chunks_.size(), [&](size_t k) {
    Open& o = open[k];
    for (size_t i = chunks_[k].begin; i < chunks_[k].end; ++i) {
      if (sym[i] == kOpenBracket) {
        o.opens.push_back(uint32_t(i));
        match[i] = kNoMatch;
      } else if (sym[i] == kCloseBracket) {
        if (o.opens.empty()) {
          o.closes.push_back(uint32_t(i));
          match[i] = kNoMatch;
        } else {
          const uint32_t a = o.opens.back();
          o.opens.pop_back();
          match[a] = uint32_t(i);
          match[i] = a;
        }
      }
    }
  });
  std::vector<uint32_t> stack;
  for (const Open& o : open) {
    for (uint32_t c : o.closes) {
      if (stack.empty()) continue;  // unbalanced: stays kNoMatch
      const uint32_t a = stack.back();
      stack.pop_back();
      match[a] = c;
      match[c] = a;
    }
    stack.insert(stack.end(), o.opens.begin(), o.opens.end());
  }
}

void Pass::SplitChunks(const Word& in) {
  const size_t n = in.size();
  size_t count = 1;
  // Productions that assign global variables run in word order, as in cpfg.
  // So do predecessors of several modules and sub-L-systems (each module's
  // rewriting depends on the ones before it).
  if (n >= 2 * kMinChunk && pool_.threads() > 1 && !g_.productionsWriteGlobals &&
      !g_.multiModulePredecessors && !g_.subLsystems)
    count = std::min<size_t>(size_t(pool_.threads()) * 8, n / kMinChunk);
  chunks_.assign(count, Chunk{});
  for (size_t k = 0; k < count; ++k) {
    chunks_[k].begin = n * k / count;
    chunks_[k].end = n * (k + 1) / count;
    chunks_[k].inParam = in.paramStart.empty() ? 0 : in.paramStart[chunks_[k].begin];
  }
}

Status Pass::Allocate(Word& out, bool outHasParams) {
  uint64_t modules = 0, params = 0;
  for (auto& c : chunks_) {
    c.outModuleAt = modules;
    c.outParamAt = params;
    modules += c.outModules;
    params += c.outParams;
  }
  if (modules > maxModules_) {
    return LimitError("derivation step " + std::to_string(stepForMessages_) +
                      " would make the word " + std::to_string(modules) +
                      " modules long, more than the limit of " + std::to_string(maxModules_) +
                      " (--max-modules)");
  }
  if (params > kMaxParams) {
    return LimitError("derivation step " + std::to_string(stepForMessages_) + " would need " +
                      std::to_string(params) + " parameters, more than the limit of " +
                      std::to_string(kMaxParams));
  }
  out.Clear();
  out.symbols.ResizeUninitialized(size_t(modules) + 16);  // slack for over-copying
  out.symbols.ResizeUninitialized(size_t(modules));
  if (outHasParams && params > 0) {
    out.params.ResizeUninitialized(size_t(params));
    out.paramStart.ResizeUninitialized(size_t(modules) + 1);
    out.paramStart[size_t(modules)] = uint32_t(params);
  }
  return {};
}

void Pass::Fail(Chunk& c, const Production& p, const EvalError& e, int column, size_t i) {
  if (c.error) return;
  const SourceLoc loc = p.LocOf(e.column ? e.column : column);
  Diagnostic d = MakeError(loc,
                           e.message + " (module " + std::to_string(i + 1) + " of the word, step " +
                               std::to_string(stepForMessages_) + ")",
                           1, g_.SourceLine(loc));
  c.error = std::move(d);
}

// Sentinel for "neighbour not looked up yet".
constexpr size_t kNotLooked = kNoPosition - 1;

int Pass::Matches(const ProdInfo& pi, const WordView& w, size_t i, const double* pp, int arity,
                  double* formals, size_t& prev, size_t& next, RandomStream& rng, Chunk& c) {
  if (pi.special) [[unlikely]]
    return MatchSpecial(pi, w, i, pp, arity, formals, rng, c);
  if (pi.leftKind) {
    if (prev == kNotLooked) prev = PrevInContext(w, i);
    if (prev == kNoPosition || w.symbols[prev] != pi.left0) return 0;
  }
  if (pi.rightKind == 1) {
    if (next == kNotLooked) next = NextInContext(w, i + 1);
    if (next == kNoPosition || w.symbols[next] != pi.right0) return 0;
  }
  const Production& q = sec_.productions[pi.index];
  for (int k = 0; k < arity; ++k) formals[q.pred.firstFormal + k] = pp[k];
  if (pi.leftKind == 2 && !MatchLeft(q, w, prev, formals)) return 0;
  if (pi.rightKind == 2) {
    if (next == kNotLooked) next = NextInContext(w, i + 1);
    if (!MatchRight(q, w, i, next, formals)) return 0;
  }
  if (pi.hasCondition) {
    if (pi.hasBlocks) [[unlikely]]
      return MatchBlocks(q, i, formals, rng, c);
    double v;
    EvalError e;
    if (!q.condition->Eval(formals, rng, &v, &e, globals_)) {
      Fail(c, q, e, q.conditionColumn, i);
      return -1;
    }
    if (v == 0) return 0;
  }
  return 1;
}

int Pass::MatchSpecial(const ProdInfo& pi, const WordView& w, size_t i, const double* pp, int arity,
                       double* formals, RandomStream& rng, Chunk& c) {
  if (!owner_.empty() && owner_[i] != pi.lsystem) return 0;  // another L-system's module
  const Production& q = sec_.productions[pi.index];
  // The modules after the first of the predecessor: the next ones in the word.
  for (size_t k = 0; k < q.predTail.size(); ++k) {
    const size_t j = i + 1 + k;
    if (j >= w.size || w.symbols[j] != q.predTail[k].symbol) return 0;
  }
  for (int k = 0; k < arity; ++k) formals[q.pred.firstFormal + k] = pp[k];
  const WordView v = ViewFor(q, w);
  if (!q.left.empty() && !MatchLeft(q, v, PrevInContext(v, i), formals)) return 0;
  const size_t last = i + q.predTail.size();
  if (!q.right.empty() && !MatchRight(q, v, last, NextInContext(v, last + 1), formals)) return 0;
  BindSpecial(q, w, i, formals);  // the predecessor's other modules
  if (pi.hasBlocks) return MatchBlocks(q, i, formals, rng, c);
  if (q.condition) {
    double val;
    EvalError e;
    if (!q.condition->Eval(formals, rng, &val, &e, globals_)) {
      Fail(c, q, e, q.conditionColumn, i);
      return -1;
    }
    if (val == 0) return 0;
  }
  return 1;
}

void Pass::BindSpecial(const Production& p, const WordView& w, size_t i, double* formals) const {
  if (!w.paramStart) return;
  for (size_t k = 0; k < p.predTail.size(); ++k) {
    const size_t j = i + 1 + k;
    const uint32_t a = w.paramStart[j], b = w.paramStart[j + 1];
    double* dst = formals + p.predTail[k].firstFormal;
    for (uint32_t m = a; m < b; ++m) *dst++ = w.params[m];
  }
}

Status Pass::ComputeOwners(const Word& in) {
  const size_t n = in.size();
  owner_.resize(n);
  std::vector<uint16_t> stack{0};
  for (size_t i = 0; i < n; ++i) {
    const SymbolId s = in.symbols[i];
    owner_[i] = stack.back();
    const uint8_t kind = subKind_[s];
    if (kind == 0) continue;
    if (kind == 2) {  // `$` belongs to the sub-L-system it ends
      if (stack.size() > 1) stack.pop_back();
      continue;
    }
    const double id = in.params[in.paramStart[i]];
    size_t b = 0;
    while (b < g_.lsystems.size() && double(g_.lsystems[b].id) != std::trunc(id)) ++b;
    if (b == g_.lsystems.size()) {
      std::string ids;
      for (const LsystemBlock& l : g_.lsystems)
        ids += (ids.empty() ? "" : ", ") + std::to_string(l.id);
      return LimitError("step " + std::to_string(stepForMessages_) + ": module " +
                        std::to_string(i) + ", '?(" + FormatParam(id) +
                        ", ...)', starts sub-L-system " + FormatParam(id) +
                        ", but the file's 'lsystem:' blocks are numbered " + ids);
    }
    stack.push_back(uint16_t(b));
  }
  return {};
}

int Pass::MatchBlocks(const Production& q, size_t i, double* formals, RandomStream& rng, Chunk& c) {
  EvalError e;
  double* locals = formals + q.formalCount;
  for (int k = 0; k < q.localCount; ++k) locals[k] = 0;
  if (q.preBlock && !q.preBlock->Exec(formals, globals_, rng, &e)) {
    Fail(c, q, e, q.conditionColumn, i);
    return -1;
  }
  if (q.condition) {
    double v;
    if (!q.condition->Eval(formals, rng, &v, &e, globals_)) {
      Fail(c, q, e, q.conditionColumn, i);
      return -1;
    }
    if (v == 0) return 0;
  }
  if (q.postBlock && !q.postBlock->Exec(formals, globals_, rng, &e)) {
    Fail(c, q, e, q.conditionColumn, i);
    return -1;
  }
  return 1;
}

bool Pass::Stash(const Production& p, size_t i, double* vars, Chunk& c) {
  const Successor& s = p.successor;
  RandomStream rng{SeedOf(i), purpose_, step_, uint64_t(i) * 2 + 1, 0};
  const auto& arities = g_.symbols.arities();
  size_t e = 0, b = 0;
  EvalError err;
  for (size_t m = 0; m <= s.symbols.size(); ++m) {
    for (; b < s.blocks.size() && s.blocks[b].before == m; ++b) {
      if (!s.blocks[b].code.Exec(vars, globals_, rng, &err)) {
        Fail(c, p, err, 0, i);
        return false;
      }
    }
    if (m == s.symbols.size()) break;
    for (int k = 0; k < arities[s.symbols[m]]; ++k, ++e) {
      double v;
      if (!s.params[e].Eval(vars, rng, &v, &err, globals_)) {
        Fail(c, p, err, 0, i);
        return false;
      }
      c.stash.push_back(v);
    }
  }
  return true;
}

bool Pass::Rebind(uint32_t index, const WordView& w, size_t i, double* vars, Chunk& c) {
  const SymbolId sym = w.symbols[i];
  const ProdInfo* pi = infos_.data() + infoStart_[sym];
  while (pi->index != index) ++pi;
  RandomStream rng{SeedOf(i), purpose_, step_, uint64_t(i) * 2, 1};
  const double* pp = w.paramStart ? w.params + w.paramStart[i] : nullptr;
  size_t prev = kNotLooked, next = kNotLooked;
  return Matches(*pi, w, i, pp, g_.symbols.arity(sym), vars, prev, next, rng, c) >= 0;
}

// Draws one of the matching weighted productions from pi on, by weight
// (kIdentity when every weight is 0), with room for `capacity` candidates in
// weights/cands: 1 drawn, 0 more candidates than capacity, -1 an error
// (reported in c).
inline int Pass::Draw(const ProdInfo* pi, const ProdInfo* last, const WordView& w, size_t i,
                      const double* pp, int arity, double* formals, size_t& prev, size_t& next,
                      RandomStream& rng, Chunk& c, double* weights, uint32_t* cands,
                      size_t capacity, uint32_t* choice) {
  size_t nc = 0;
  double total = 0;
  for (const ProdInfo* qi = pi; qi != last; ++qi) {
    if (!qi->hasWeight) continue;
    if (qi != pi) {
      int mq = Matches(*qi, w, i, pp, arity, formals, prev, next, rng, c);
      if (mq < 0) return -1;
      if (mq == 0) continue;
    }
    if (nc == capacity) return 0;
    const Production& q = sec_.productions[qi->index];
    double wv;
    EvalError e;
    if (!q.weight->Eval(formals, rng, &wv, &e, globals_)) {
      Fail(c, q, e, q.weightColumn, i);
      return -1;
    }
    if (wv < 0) {
      e.message = "negative probability weight";
      Fail(c, q, e, q.weightColumn, i);
      return -1;
    }
    weights[nc] = wv;
    cands[nc++] = qi->index;
    total += wv;
  }
  if (total <= 0) {
    *choice = kIdentity;
    return 1;
  }
  double r = rng.Uniform() * total;
  size_t pick = nc - 1;
  for (size_t k = 0; k < nc; ++k) {
    if (r < weights[k]) {
      pick = k;
      break;
    }
    r -= weights[k];
  }
  *choice = cands[pick];
  return 1;
}

bool Pass::DrawMany(const ProdInfo* pi, const ProdInfo* last, const WordView& w, size_t i,
                    const double* pp, int arity, double* formals, size_t& prev, size_t& next,
                    RandomStream rng, Chunk& c, uint32_t* choice) {
  const size_t capacity = size_t(last - pi);
  std::vector<double> weights(capacity);
  std::vector<uint32_t> cands(capacity);
  return Draw(pi, last, w, i, pp, arity, formals, prev, next, rng, c, weights.data(), cands.data(),
              capacity, choice) > 0;
}

bool Pass::Choose(const WordView& w, size_t i, double* formals, uint32_t* choice, Chunk& c) {
  const SymbolId sym = w.symbols[i];
  const ProdInfo* first = infos_.data() + infoStart_[sym];
  const ProdInfo* last = infos_.data() + infoStart_[sym + 1];
  RandomStream rng{SeedOf(i), purpose_, step_, uint64_t(i) * 2, 0};
  const double* pp = w.paramStart ? w.params + w.paramStart[i] : nullptr;
  const int arity = g_.symbols.arity(sym);
  // Context neighbours, looked up once and shared by every production.
  size_t prev = kNotLooked, next = kNotLooked;
  for (const ProdInfo* pi = first; pi != last; ++pi) {
    int m = Matches(*pi, w, i, pp, arity, formals, prev, next, rng, c);
    if (m < 0) return false;
    if (m == 0) continue;
    if (!pi->hasWeight) {
      *choice = pi->index;
      return !pi->hasBlocks || Stash(sec_.productions[pi->index], i, formals, c);
    }
    // Stochastic: draw among every matching production that carries a
    // weight, however many: up to kInline here; past that, DrawMany draws
    // again from the same random state with room for all of them.
    constexpr size_t kInline = 64;
    double weights[kInline];
    uint32_t cands[kInline];
    const RandomStream rngAtWeights = rng;
    int got = Draw(pi, last, w, i, pp, arity, formals, prev, next, rng, c, weights, cands, kInline,
                   choice);
    if (got == 0) [[unlikely]] {
      if (!DrawMany(pi, last, w, i, pp, arity, formals, prev, next, rngAtWeights, c, choice))
        return false;
      got = 1;
    }
    if (got < 0) return false;
    if (*choice != kIdentity && sec_.productions[*choice].HasBlocks()) {
      const Production& q = sec_.productions[*choice];
      return Rebind(*choice, w, i, formals, c) && Stash(q, i, formals, c);
    }
    return true;
  }
  *choice = kIdentity;
  return true;
}

template <bool kMulti>
void Pass::Write(const WordView& w, const Word& in, Word& out, Chunk& c, bool outHasParams) {
  std::vector<double> formals(maxFormals_ + 1);
  size_t o = c.outModuleAt;
  uint64_t po = c.outParamAt;
  SymbolId* osym = out.symbols.data();
  uint32_t* ostart = out.paramStart.empty() ? nullptr : out.paramStart.data();
  double* opar = out.params.empty() ? nullptr : out.params.data();
  const auto& arities = g_.symbols.arities();
  for (size_t i = c.begin; i < c.end; ++i) {
    const SymbolId sym = w.symbols[i];
    const uint16_t ch16 = choice_[i];
    if constexpr (kMulti) {
      if (ch16 == kConsumed16) continue;  // part of the predecessor before it
    }
    if (ch16 == kIdentity16) {
      osym[o] = sym;
      if (ostart) {
        ostart[o] = uint32_t(po);
        const int a = arities[sym];
        if (a) {
          const double* src = in.params.data() + in.paramStart[i];
          for (int k = 0; k < a; ++k) opar[po + k] = src[k];
          po += a;
        }
      }
      ++o;
      continue;
    }
    const Production& p = sec_.productions[ch16];
    const Successor& s = p.successor;
    if (!ostart) {  // no parameters anywhere in the output: copy the symbols
      const size_t len = s.symbols.size();
      const SymbolId* src = s.symbols.data();
      if (len <= 4) {
        for (size_t k = 0; k < len; ++k) osym[o + k] = src[k];
      } else {
        std::memcpy(osym + o, src, len * sizeof(SymbolId));
      }
      o += len;
      continue;
    }
    if (anyBlocks_ && p.HasBlocks()) [[unlikely]] {  // parameters computed when chosen
      for (SymbolId x : s.symbols) {
        osym[o] = x;
        ostart[o] = uint32_t(po);
        for (int k = 0; k < arities[x]; ++k) opar[po++] = c.stash[c.stashAt++];
        ++o;
      }
      continue;
    }
    if (!s.allConstant) {
      // Bind formals for the chosen production.
      const int a = arities[sym];
      if (a) {
        const double* src = in.params.data() + in.paramStart[i];
        for (int k = 0; k < a; ++k) formals[p.pred.firstFormal + k] = src[k];
      }
      if (special_ && (p.lsystem > 0 || !p.predTail.empty())) [[unlikely]] {
        const WordView v = ViewFor(p, w);
        const size_t last = i + p.predTail.size();
        if (!p.left.empty()) MatchLeft(p, v, PrevInContext(v, i), formals.data());
        if (!p.right.empty()) MatchRight(p, v, last, NextInContext(v, last + 1), formals.data());
        BindSpecial(p, w, i, formals.data());
      } else {
        if (!p.left.empty()) MatchLeft(p, w, PrevInContext(w, i), formals.data());
        if (!p.right.empty()) MatchRight(p, w, i, NextInContext(w, i + 1), formals.data());
      }
    }
    RandomStream rng{SeedOf(i), purpose_, step_, uint64_t(i) * 2 + 1, 0};
    size_t e = 0;
    for (SymbolId x : s.symbols) {
      osym[o] = x;
      if (ostart) {
        ostart[o] = uint32_t(po);
        const int a = arities[x];
        for (int k = 0; k < a; ++k, ++e) {
          double v;
          EvalError err;
          if (!s.params[e].Eval(formals.data(), rng, &v, &err, globals_)) {
            Fail(c, p, err, 0, i);
            return;
          }
          opar[po++] = v;
        }
      }
      ++o;
    }
  }
}

Status Pass::Run(const Word& in, Word& out, bool* changed) {
  SplitChunks(in);
  const size_t n = in.size();
  const bool inHasParams = in.HasParams();

  // Fast path: a fixed table of parameter-free successors.
  if (table_.usable && !inHasParams) {
    const SymbolId* sym = in.symbols.data();
    const uint32_t* len = table_.length.data();
    pool_.ParallelFor(chunks_.size(), [&](size_t k) {
      Chunk& c = chunks_[k];
      uint64_t total = 0;
      for (size_t i = c.begin; i < c.end; ++i) total += len[sym[i]];
      c.outModules = total;
    });
    if (Status s = Allocate(out, false); !s.ok()) return s;
    const uint32_t* off = table_.offset.data();
    const SymbolId* flat = table_.flat.data();
    SymbolId* dst0 = out.symbols.data();
    pool_.ParallelFor(chunks_.size(), [&](size_t k) {
      Chunk& c = chunks_[k];
      SymbolId* dst = dst0 + c.outModuleAt;
      // Over-copying is safe up to kOverCopy before the chunk's own end;
      // past that it would overwrite the next chunk's output.
      SymbolId* const safeEnd = dst + (c.outModules >= kOverCopy ? c.outModules - kOverCopy : 0);
      for (size_t i = c.begin; i < c.end; ++i) {
        const SymbolId s = sym[i];
        const uint32_t l = len[s];
        const SymbolId* src = flat + off[s];
        if (l <= kOverCopy && dst <= safeEnd) {
          std::memcpy(dst, src, kOverCopy * sizeof(SymbolId));  // over-copy
        } else {
          std::memcpy(dst, src, size_t(l) * sizeof(SymbolId));
        }
        dst += l;
      }
    });
    // Changed unless every symbol maps to itself.
    bool any = false;
    for (size_t s = 0; s < table_.length.size() && !any; ++s) any = !sec_.bySymbol[s].empty();
    *changed = any && n > 0;
    return {};
  }

  // General path.
  WordView w;
  w.symbols = in.symbols.data();
  w.size = n;
  w.paramStart = inHasParams ? in.paramStart.data() : nullptr;
  w.params = inHasParams ? in.params.data() : nullptr;
  w.skip = g_.contextSkip.data();
  w.ring = g_.ring;
  if (needsMatch_) {
    match_.ResizeUninitialized(n);
    MatchBrackets(in);
    w.bracketMatch = match_.data();
  }
  if (!subKind_.empty()) {
    if (Status st = ComputeOwners(in); !st.ok()) return st;
  }
  choice_.ResizeUninitialized(n);
  if (reseeds_) moduleSeed_.resize(n);
  const auto& arities = g_.symbols.arities();
  // Compiled twice: only grammars with predecessors of several modules pay
  // for the check of modules a match took.
  auto count = [&](size_t k, auto multiTag) {
    constexpr bool kMulti = decltype(multiTag)::value;
    Chunk& c = chunks_[k];
    std::vector<double> formals(maxFormals_ + 1);
    uint64_t modules = 0, params = 0;
    const uint32_t* symChoice = symChoice_.data();
    const uint32_t* succModules = succModules_.data();
    const uint32_t* succParams = succParams_.data();
    const uint8_t* arity = arities.data();
    bool rewrote = false;
    [[maybe_unused]] size_t consumedUntil =
        0;  // modules before this belong to a chosen predecessor
    for (size_t i = c.begin; i < c.end; ++i) {
      if constexpr (kMulti) {
        if (i < consumedUntil) {
          choice_[i] = kConsumed16;
          continue;
        }
      }
      const SymbolId sym = w.symbols[i];
      if (reseeds_) moduleSeed_[i] = SrandSeed(g_, globals_, seed_);
      uint32_t ch = symChoice[sym];
      if (ch == kDynamic) {
        if (const ContextTable* t = tables_[sym].get()) {
          int lc = 0, rc = 0;
          if (t->useLeft) {
            size_t j = PrevInContext(w, i);
            if (j != kNoPosition) lc = t->leftClass[w.symbols[j]];
          }
          if (t->useRight) {
            size_t j = NextInContext(w, i + 1);
            if (j != kNoPosition) rc = t->rightClass[w.symbols[j]];
          }
          ch = t->choice[size_t(lc * t->rightClasses + rc)];
        } else if (!Choose(w, i, formals.data(), &ch, c)) {
          return;
        }
      }
      choice_[i] = ch == kIdentity ? kIdentity16 : uint16_t(ch);
      if (ch == kIdentity) {
        modules += 1;
        params += arity[sym];
      } else {
        modules += succModules[ch];
        params += succParams[ch];
        rewrote = true;
        if constexpr (kMulti) consumedUntil = i + predLength_[ch];
      }
    }
    c.changed = rewrote;
    c.outModules = modules;
    c.outParams = params;
  };
  if (multi_) {
    pool_.ParallelFor(chunks_.size(), [&](size_t k) { count(k, std::true_type{}); });
  } else {
    pool_.ParallelFor(chunks_.size(), [&](size_t k) { count(k, std::false_type{}); });
  }
  for (auto& c : chunks_) {
    if (c.error) return *c.error;
  }
  uint64_t totalParams = 0;
  for (auto& c : chunks_) totalParams += c.outParams;
  if (Status s = Allocate(out, totalParams > 0); !s.ok()) return s;
  if (multi_) {
    pool_.ParallelFor(chunks_.size(),
                      [&](size_t k) { Write<true>(w, in, out, chunks_[k], totalParams > 0); });
  } else {
    pool_.ParallelFor(chunks_.size(),
                      [&](size_t k) { Write<false>(w, in, out, chunks_[k], totalParams > 0); });
  }
  for (auto& c : chunks_) {
    if (c.error) return *c.error;
  }
  *changed = false;
  for (auto& c : chunks_) *changed |= c.changed;
  return {};
}

// Removes each cut symbol and the rest of its branch (up to, not including,
// the `]` that closes it, or to the end of the word). In place.
void ApplyCut(Word& w, SymbolId cut) {
  const size_t n = w.size();
  const bool hasParams = w.HasParams();
  size_t o = 0;
  uint32_t po = 0;
  for (size_t i = 0; i < n;) {
    if (w.symbols[i] == cut) {
      int depth = 0;
      for (; i < n; ++i) {
        SymbolId s = w.symbols[i];
        if (s == kOpenBracket)
          ++depth;
        else if (s == kCloseBracket && depth-- == 0)
          break;
      }
      continue;
    }
    if (hasParams) {
      uint32_t a = w.paramStart[i], b = w.paramStart[i + 1];
      w.paramStart[o] = po;
      for (uint32_t k = a; k < b; ++k) w.params[po++] = w.params[k];
    }
    w.symbols[o++] = w.symbols[i];
    ++i;
  }
  w.symbols.ResizeUninitialized(o);
  if (hasParams) {
    w.paramStart[o] = po;
    w.paramStart.ResizeUninitialized(o + 1);
    w.params.ResizeUninitialized(po);
    if (po == 0) {
      w.paramStart.clear();
    }
  }
}

bool ContainsSymbol(const Word& w, SymbolId s) {
  return std::find(w.symbols.begin(), w.symbols.end(), s) != w.symbols.end();
}

// Runs one of the grammar's global blocks (Start:, StartEach:, ...).
Status RunGlobalBlock(const Grammar& g, const std::optional<Expr>& block, const char* name,
                      uint64_t seed, uint64_t step, std::vector<double>& globals) {
  if (!block) return {};
  if (g.reseeds) seed = SrandSeed(g, globals.data(), seed);
  RandomStream rng{seed, kGlobalBlockDraws, step, 0, 0};
  EvalError err;
  if (block->Exec(nullptr, globals.data(), rng, &err)) return {};
  Diagnostic d;
  d.message = err.message + " in the '" + name + ":' block (step " + std::to_string(step) + ")";
  d.kind = ErrorKind::kRuntime;
  return d;
}

// srand(seed) in Start: is the grammar's seed, as `seed:` (a seed given in
// the options still wins).
uint64_t SeedAfterStart(const Grammar& g, const DeriveOptions& options,
                        const std::vector<double>& globals, uint64_t seed) {
  if (g.srandGlobal < 0 || options.seed) return seed;
  const double v = globals[size_t(g.srandGlobal)];
  if (!(std::abs(v) < 9e18)) return seed;  // NaN: srand was not called
  return uint64_t(int64_t(std::trunc(v)));
}

// cpfg's stop(v): a value other than 1 in its hidden global (NaN: not
// called; 1 is cpfg's "run on").
bool StopCalled(const Grammar& g, const std::vector<double>& globals) {
  if (g.stopGlobal < 0) return false;
  const double v = globals[size_t(g.stopGlobal)];
  return !std::isnan(v) && v != 1;
}

// The global variables as the Start: block leaves them.
Expected<std::vector<double>> StartGlobals(const Grammar& g, uint64_t seed) {
  if (g.dataFiles) g.dataFiles->Reset();  // no data file open; Start: opens them
  std::vector<double> globals(g.globals.size(), 0.0);
  for (size_t k = 0; k < g.globalInitial.size() && k < globals.size(); ++k)
    globals[k] = g.globalInitial[k];
  if (Status s = RunGlobalBlock(g, g.startBlock, "Start", seed, 0, globals); !s.ok())
    return s.error();
  return globals;
}

Expected<Word> BuildAxiom(const Grammar& g, uint64_t seed, const double* globals) {
  Word w;
  const Successor& a = g.axiom;
  RandomStream rng{seed, kAxiomDraws, 0, 0, 0};
  size_t e = 0;
  std::vector<double> values;
  for (SymbolId s : a.symbols) {
    values.clear();
    for (int k = 0; k < g.symbols.arity(s); ++k, ++e) {
      double v;
      EvalError err;
      if (!a.params[e].Eval(nullptr, rng, &v, &err, globals)) {
        return MakeError(g.axiomLoc, err.message + " in the axiom");
      }
      values.push_back(v);
    }
    w.Append(s, values);
  }
  return w;
}

// Runs passes of a decomposition or interpretation section until nothing
// changes or the maximum depth is reached.
Status RunSection(const Grammar& g, const Section& sec, ThreadPool& pool, Scratch& scratch,
                  uint64_t seed, uint64_t purpose, uint64_t step, int stepForMessages,
                  uint64_t maxModules, double* globals, Word& word) {
  if (sec.empty()) return {};
  StaticTable table = BuildStaticTable(g, sec);
  Word next;
  for (int depth = 0; depth < sec.maxDepth; ++depth) {
    Pass pass(g, sec, table, pool, scratch, seed, purpose | (uint64_t(depth) << 8), step,
              stepForMessages, maxModules, globals);
    bool changed = false;
    if (Status s = pass.Run(word, next, &changed); !s.ok()) return s;
    if (!changed) break;
    word.symbols.swap(next.symbols);
    word.params.swap(next.params);
    word.paramStart.swap(next.paramStart);
  }
  return {};
}

}  // namespace

// The state a derivation carries from one step to the next.
struct Derivation::State {
  State(const Grammar& grammar, const DeriveOptions& o)
      : g(grammar),
        seed(o.seed.value_or(grammar.seed)),
        maxModules(std::min(o.maxModules, kMaxModulesCap)),
        maxChangingSteps(o.maxChangingSteps),
        ownPool(o.pool ? 1 : o.threads),
        pool(o.pool ? *o.pool : ownPool),
        table(BuildStaticTable(grammar, grammar.main)) {}

  const Grammar& g;
  uint64_t seed;  // srand(s) in Start: may set it (Derivation::Start)
  const uint64_t maxModules;
  const int maxChangingSteps;
  ThreadPool ownPool;  // unused (one thread, no workers) with a shared pool
  ThreadPool& pool;
  const StaticTable table;
  Scratch scratch;
  Word word, next;
  std::vector<double> globals;  // the grammar's global variables
  int step = 0;
  int changingSteps = 0;  // steps taken that were not at the fixed point
  // Every later step gives this same word (and global variables): each is
  // free, and Derive() skips them (SkipToStep).
  bool fixedPoint = false;
  bool edited = false;   // the caller changed the word between steps (MutableWord)
  bool stopped = false;  // cpfg's stop(v), v not 1, was called
  std::vector<StepStats> stats;
};

namespace {

template <typename T>
bool SameBytes(const PodBuffer<T>& a, const PodBuffer<T>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

// The same modules with the same parameters, bit for bit.
bool SameWord(const Word& a, const Word& b) {
  return SameBytes(a.symbols, b.symbols) && SameBytes(a.paramStart, b.paramStart) &&
         SameBytes(a.params, b.params);
}

}  // namespace

Derivation::Derivation(std::unique_ptr<State> state) : state_(std::move(state)) {}
Derivation::Derivation(Derivation&&) noexcept = default;
Derivation& Derivation::operator=(Derivation&&) noexcept = default;
Derivation::~Derivation() = default;

Expected<Derivation> Derivation::Start(const Grammar& g, const DeriveOptions& options) {
  SYLVA_ASSERT(g.main.bySymbol.size() == g.symbols.size());  // a Grammar from the parser
  auto state = std::make_unique<State>(g, options);
  auto globals = StartGlobals(g, state->seed);
  if (!globals) return globals.error();
  state->globals = std::move(globals).value();
  state->seed = SeedAfterStart(g, options, state->globals, state->seed);
  // A --seed given wins over srand in Start:; a later srand still reseeds.
  if (options.seed && g.srandGlobal >= 0)
    state->globals[size_t(g.srandGlobal)] = std::numeric_limits<double>::quiet_NaN();
  state->stopped = StopCalled(g, state->globals);
  auto axiom = BuildAxiom(g, state->seed, state->globals.data());
  if (!axiom) return axiom.error();
  state->word = std::move(axiom).value();
  if (state->word.size() > state->maxModules) {
    return LimitError("the axiom has " + std::to_string(state->word.size()) +
                      " modules, more than the limit of " + std::to_string(state->maxModules));
  }
  state->stats.push_back(StepStats{0, state->word.size(), 0});
  return Derivation(std::move(state));
}

Status Derivation::Step() {
  State& s = *state_;
  if (s.step == std::numeric_limits<int>::max()) {
    return LimitError("derivation length " + std::to_string(s.step) + " reached: no step follows");
  }
  if (!s.fixedPoint && s.changingSteps >= s.maxChangingSteps) {
    return LimitError("step " + std::to_string(s.step + 1) + ": the word still changes after " +
                      std::to_string(s.maxChangingSteps) +
                      " steps, the most Sylva takes (steps that change nothing are free)");
  }
  const auto ts = Clock::now();
  const int step = s.step + 1;
  if (!s.fixedPoint) {
    ++s.changingSteps;
    bool changed = false;
    // A step is a function of the word and the global variables unless it
    // draws random numbers: with both unchanged after it, so is every later one.
    const bool canSettle = !s.g.usesRandom && !s.edited;
    std::vector<double> globalsBefore;
    if (canSettle) globalsBefore = s.globals;
    double* globals = s.globals.data();
    if (Status st =
            RunGlobalBlock(s.g, s.g.startEachBlock, "StartEach", s.seed, uint64_t(step), s.globals);
        !st.ok())
      return st;
    Pass pass(s.g, s.g.main, s.table, s.pool, s.scratch, s.seed, kMainDraws, uint64_t(step), step,
              s.maxModules, globals);
    if (Status st = pass.Run(s.word, s.next, &changed); !st.ok()) return st;
    std::swap(s.word, s.next);
    if (Status st =
            RunSection(s.g, s.g.decomposition, s.pool, s.scratch, s.seed, kDecompositionDraws,
                       uint64_t(step), step, s.maxModules, globals, s.word);
        !st.ok())
      return st;
    if (s.g.cutSymbol && ContainsSymbol(s.word, *s.g.cutSymbol)) {
      ApplyCut(s.word, *s.g.cutSymbol);
      changed = true;
    }
    if (Status st =
            RunGlobalBlock(s.g, s.g.endEachBlock, "EndEach", s.seed, uint64_t(step), s.globals);
        !st.ok())
      return st;
    // With no production applied, no randomness and no global variables,
    // every later step gives this same word. (A caller that edits the word
    // between steps breaks this: MutableWord() clears it.)
    if (!changed && s.g.decomposition.empty() && !s.g.usesRandom && s.g.globals.empty())
      s.fixedPoint = true;
    // s.next holds the word the step started from.
    if (canSettle && !s.fixedPoint && s.word.size() == s.next.size() &&
        (globalsBefore.empty() || std::memcmp(globalsBefore.data(), s.globals.data(),
                                              globalsBefore.size() * sizeof(double)) == 0) &&
        SameWord(s.word, s.next))
      s.fixedPoint = true;
    s.stopped = s.stopped || StopCalled(s.g, s.globals);
  }
  s.step = step;
  s.stats.push_back(
      StepStats{step, s.word.size(), std::chrono::duration<double>(Clock::now() - ts).count()});
  return {};
}

int Derivation::step() const {
  return state_->step;
}
bool Derivation::stopped() const {
  return state_->stopped;
}
const Word& Derivation::word() const {
  return state_->word;
}
Word& Derivation::MutableWord() {
  state_->fixedPoint = false;
  state_->edited = true;
  return state_->word;
}
bool Derivation::settled() const {
  return state_->fixedPoint;
}
void Derivation::SkipToStep(int step) {
  State& s = *state_;
  SYLVA_ASSERT(s.fixedPoint && !s.stopped && step >= s.step);
  if (step == s.step) return;
  s.step = step;
  s.stats.push_back(StepStats{step, s.word.size(), 0});
}
const std::vector<StepStats>& Derivation::stats() const {
  return state_->stats;
}

Expected<Word> Derivation::Interpreted() const {
  State& s = *state_;
  Word w = s.word;
  if (s.g.interpretation.empty()) return w;
  Scratch scratch;
  std::vector<double> globals = s.globals;  // interpretation may assign them: a copy
  if (Status st = RunSection(s.g, s.g.interpretation, s.pool, scratch, s.seed, kInterpretDraws, 0,
                             0, s.maxModules, globals.data(), w);
      !st.ok())
    return st.error();
  return w;
}

Status Derivation::RunEnd() {
  State& s = *state_;
  return RunGlobalBlock(s.g, s.g.endBlock, "End", s.seed, uint64_t(s.step), s.globals);
}

const std::vector<double>& Derivation::globals() const {
  return state_->globals;
}

DeriveResult Derivation::Finish() && {
  DeriveResult r;
  r.word = std::move(state_->word);
  r.steps = std::move(state_->stats);
  for (const StepStats& s : r.steps) r.seconds += s.seconds;
  return r;
}

Expected<DeriveResult> Derive(const Grammar& g, const DeriveOptions& options) {
  const auto t0 = Clock::now();
  const int steps = options.steps >= 0 ? options.steps : g.derivationLength;
  auto derivation = Derivation::Start(g, options);
  if (!derivation) return derivation.error();
  while (derivation->step() < steps && !derivation->stopped()) {
    if (derivation->settled()) {
      derivation->SkipToStep(steps);
      break;
    }
    if (Status s = derivation->Step(); !s.ok()) return s.error();
    if (options.progress) options.progress(derivation->step(), steps, derivation->word().size());
  }
  if (Status s = derivation->RunEnd(); !s.ok()) return s.error();
  DeriveResult result = std::move(*derivation).Finish();
  result.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return result;
}

Expected<Word> Interpret(const Grammar& g, const Word& word, const DeriveOptions& options) {
  Word w = word;
  if (g.interpretation.empty()) return w;
  ThreadPool ownPool(options.pool ? 1 : options.threads);
  ThreadPool& pool = options.pool ? *options.pool : ownPool;
  uint64_t seed = options.seed.value_or(g.seed);
  const uint64_t maxModules = std::min(options.maxModules, kMaxModulesCap);
  Scratch scratch;
  // The global variables as Start: leaves them (the derivation's own are
  // in Derivation::Interpreted).
  auto globals = StartGlobals(g, seed);
  if (!globals) return globals.error();
  seed = SeedAfterStart(g, options, *globals, seed);
  if (Status s = RunSection(g, g.interpretation, pool, scratch, seed, kInterpretDraws, 0, 0,
                            maxModules, globals->data(), w);
      !s.ok())
    return s.error();
  return w;
}

}  // namespace sylva::lsys
