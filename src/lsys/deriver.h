// Deriving words: parallel rewriting of a Grammar.
//
// Each step rewrites every module of the word of step k from that word
// (parallel rewriting), then applies decomposition (up to its maximum
// depth) and cut. The word is split into chunks that threads process in
// two passes, after Lipp, Wonka & Wimmer, "Parallel generation of
// multiple L-systems" (Computers & Graphics 34(5), 2010):
//   1. choose a production per module and count the output size per chunk;
//   2. prefix-sum the sizes, then write every chunk at its own offset.
// Random draws are keyed by (seed, section, step, module index), never by
// thread, so the word is the same for any thread count.
//
// Grammars whose choice per symbol is fixed and parameter-free (Koch curves,
// bracketed plants) take a table-driven path that copies successors.
//
// cpfg's forms that make a module's rewriting depend on the modules before
// it run on one chunk, left to right, as cpfg rewrites: a predecessor of
// several modules takes the modules it matched (they are not rewritten
// again), and in a grammar with sub-L-systems each module is rewritten by
// the productions of the `lsystem:` block it lies in, found from the
// `?(id, scale)` ... `$` nesting before it (docs/cpfg.md).
//
// Limits: a step that would make the word longer than maxModules, or hold
// more than kMaxParams parameters, stops with an error naming the step and
// the size, before any memory for it is allocated.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "core/status.h"
#include "lsys/grammar.h"
#include "lsys/parser.h"
#include "lsys/word.h"

namespace sylva {
class ThreadPool;
}

namespace sylva::lsys {

// 2^28 modules: 512 MiB of symbols for a parameter-free word.
inline constexpr uint64_t kDefaultMaxModules = uint64_t(1) << 28;
// 2^29 parameters: 4 GiB of doubles.
inline constexpr uint64_t kMaxParams = uint64_t(1) << 29;
inline constexpr uint64_t kMaxModulesCap = 0xFFFFFFF0ull;
// A derivation length may be any int (lsys::kMaxDerivationLength, as
// cpfg's): once a step changes neither the word nor the global variables,
// and the grammar draws no random numbers, every later step gives the same
// word and is skipped. At most this many steps that do change something
// are taken (a derivation of 1000-module words this long takes seconds).
inline constexpr int kMaxChangingSteps = 1000000;
// Animation frames are drawn one step at a time (plant/frames.h).
inline constexpr int kMaxAnimationSteps = 100000;

struct DeriveOptions {
  int steps = -1;                // -1: the grammar's derivation length
  std::optional<uint64_t> seed;  // overrides `seed:`
  int threads = 0;               // 0: all hardware threads
  // When set, the derivation runs on this pool (shared with the process:
  // core/parallel.h SharedPool; not owned, outliving the derivation) and
  // `threads` is not used. The word is the same either way.
  ThreadPool* pool = nullptr;
  uint64_t maxModules = kDefaultMaxModules;
  // Steps that change the word (or the global variables) taken at most.
  int maxChangingSteps = kMaxChangingSteps;
  // Called after each step (from the calling thread).
  std::function<void(int step, int steps, uint64_t modules)> progress;
};

struct StepStats {
  int step = 0;          // 1-based; 0 is the axiom
  uint64_t modules = 0;  // after the step
  double seconds = 0;
};

struct DeriveResult {
  Word word;
  std::vector<StepStats> steps;  // steps[0] is the axiom
  double seconds = 0;
};

Expected<DeriveResult> Derive(const Grammar& g, const DeriveOptions& options = {});

// A derivation driven one step at a time, so a caller can look at (or
// answer queries in) the word between steps: the plant library runs the
// turtle between steps for environmental queries. Derive() is Start() and
// Step() until the requested length. `g` must outlive the Derivation; it
// holds its own thread pool (options.threads) and scratch memory.
class Derivation {
 public:
  // Builds the axiom (step 0). options.steps and options.progress are not
  // used: the caller decides how many steps to take.
  static Expected<Derivation> Start(const Grammar& g, const DeriveOptions& options = {});

  // Rewrites the word once (main section, then decomposition and cut).
  // An error (a limit reached, an expression that fails) ends the
  // derivation: the word is then undefined and must not be stepped again.
  Status Step();

  int step() const;  // steps taken; 0 after Start
  // cpfg's `stop(v);` with v other than 1 was called (in Start: or in the
  // last step): as cpfg's animation halts there, Derive() takes no further
  // step, nor do the plant library's growers.
  bool stopped() const;
  // The last step changed neither the word nor the global variables and
  // the grammar draws no random numbers (nor did the caller edit the word
  // between steps): every later step gives this word. SkipToStep(n) then
  // takes the derivation to step n at no cost (one StepStats entry for it).
  bool settled() const;
  void SkipToStep(int step);
  const Word& word() const;
  // The word, for a caller that fills query parameters between steps.
  Word& MutableWord();
  const std::vector<StepStats>& stats() const;  // stats()[0] is the axiom
  // The current word through the interpretation section (what the turtle
  // reads); a copy of word() when the section is empty.
  Expected<Word> Interpreted() const;
  // Runs the grammar's End: block (Derive() does, after the last step).
  Status RunEnd();
  // The grammar's global variables (Grammar::globals order), as the last
  // step left them.
  const std::vector<double>& globals() const;
  // Ends the derivation, handing over the word and the statistics.
  DeriveResult Finish() &&;

  Derivation(Derivation&&) noexcept;
  Derivation& operator=(Derivation&&) noexcept;
  ~Derivation();

 private:
  struct State;
  explicit Derivation(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

// Applies the interpretation section (up to its maximum depth) to a derived
// word: the word handed to the turtle. Returns a copy when the section is
// empty.
Expected<Word> Interpret(const Grammar& g, const Word& word, const DeriveOptions& options = {});

}  // namespace sylva::lsys
