// Derivation throughput on the ABOP catalogue, grown large.
//
// Reported per case: modules/s = modules produced over all steps (the sum of
// the word sizes after each step) / wall time, for 1 and 2 threads. Targets
// (issue 2, one core of the 2-core CI machine):
//   context-free, parameter-free (Koch n=8, 1.24d n=14)   >= 600 M modules/s
//   parametric with conditions (2.6, 2.8, >= 10 M modules) >= 50 M modules/s
//   context-sensitive (1.31, grown large)                   >= 100 M modules/s
//   2 threads >= 1.7x one thread on the large cases
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/atomic_file.h"
#include "lsys/deriver.h"
#include "lsys/parser.h"

namespace {

using namespace sylva::lsys;

Grammar Load(const std::string& name) {
  ParseResult r =
      ParseGrammarFile(std::string(SYLVA_SOURCE_DIR) + "/grammars/abop/" + name + ".lsys");
  if (!r.grammar) {
    std::fprintf(stderr, "%s", r.diagnostics.FormatAll().c_str());
    std::abort();
  }
  return std::move(*r.grammar);
}

void BM_Derive(benchmark::State& state, const char* file, int steps) {
  Grammar g = Load(file);
  DeriveOptions opt;
  opt.steps = steps;
  opt.threads = int(state.range(0));
  opt.maxModules = kMaxModulesCap;
  uint64_t produced = 0, final = 0;
  for (auto _ : state) {
    auto r = Derive(g, opt);
    if (!r) {
      state.SkipWithError(r.error().message.c_str());
      return;
    }
    produced = 0;
    for (size_t k = 1; k < r->steps.size(); ++k) produced += r->steps[k].modules;
    final = r->word.size();
    benchmark::DoNotOptimize(r->word.symbols.data());
  }
  state.SetItemsProcessed(int64_t(produced) * state.iterations());
  state.counters["modules"] = double(final);
  state.counters["Mmodules/s"] =
      benchmark::Counter(double(produced) / 1e6, benchmark::Counter::kIsIterationInvariantRate);
}

#define SYLVA_DERIVE_BENCH(label, file, steps)     \
  BENCHMARK_CAPTURE(BM_Derive, label, file, steps) \
      ->Arg(1)                                     \
      ->Arg(2)                                     \
      ->UseRealTime()                              \
      ->Unit(benchmark::kMillisecond)              \
      ->MinTime(1.0)

SYLVA_DERIVE_BENCH(koch_1_6_n8, "fig1_06_koch_island", 8);
SYLVA_DERIVE_BENCH(bracketed_1_24d_n14, "fig1_24d_bracketed_plant", 14);
SYLVA_DERIVE_BENCH(monopodial_2_6a_n21, "fig2_06a_monopodial", 21);
SYLVA_DERIVE_BENCH(ternary_2_8a_n13, "fig2_08a_ternary", 13);
SYLVA_DERIVE_BENCH(hogeweg_1_31a_n62, "fig1_31a_hogeweg_hesper", 62);
SYLVA_DERIVE_BENCH(hogeweg_1_31e_n58, "fig1_31e_hogeweg_hesper", 58);
SYLVA_DERIVE_BENCH(stochastic_1_27_n10, "fig1_27_stochastic_plant", 10);

// cpfg statement blocks: a doubling grammar whose every production runs a
// block, with local variables only (parallel) or assigning a global
// variable (one thread, word order, as cpfg). 2^18 A's, ~1.3 M modules.
void BM_DeriveBlocks(benchmark::State& state, const char* text) {
  ParseResult r = ParseGrammarText(text, "blocks.l");
  if (!r.grammar) {
    std::fprintf(stderr, "%s", r.diagnostics.FormatAll().c_str());
    std::abort();
  }
  DeriveOptions opt;
  opt.threads = int(state.range(0));
  uint64_t produced = 0;
  for (auto _ : state) {
    auto w = Derive(*r.grammar, opt);
    if (!w) {
      state.SkipWithError(w.error().message.c_str());
      return;
    }
    produced = 0;
    for (size_t k = 1; k < w->steps.size(); ++k) produced += w->steps[k].modules;
    benchmark::DoNotOptimize(w->word.symbols.data());
  }
  state.counters["Mmodules/s"] =
      benchmark::Counter(double(produced) / 1e6, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK_CAPTURE(BM_DeriveBlocks, locals,
                  "derivation length: 18\naxiom: A(1)\n"
                  "A(x) : {y = x + 1; z = y * 0.5;} y > 0 --> A(y) [B(z)] A(y)\n"
                  "B(x) : {w = x * 2; if (w > 1e6) w = 0;} * --> B(w * 0.5)\n")
    ->Arg(1)
    ->Arg(2)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_DeriveBlocks, globals,
                  "Start: {k = 0;}\nderivation length: 18\naxiom: A(1)\n"
                  "A(x) : {k = k + 1;} * --> A(k) [B(k)] A(x)\n"
                  "B(x) : {w = x * 2; if (w > 1e6) w = 0;} * --> B(w * 0.5)\n")
    ->Arg(1)
    ->Arg(2)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

// cpfg's forms that derive left to right on one thread: sub-L-systems
// (each module rewritten by its block's productions), a predecessor of two
// modules, and reads of an array. Each grows to about 0.8-1.3 M modules.
BENCHMARK_CAPTURE(BM_DeriveBlocks, sub_lsystems,
                  "lsystem: 1\nderivation length: 17\naxiom: A\n"
                  "A --> A[?(2,0.5)B$]A\nB --> X\nendlsystem\n"
                  "lsystem: 2\naxiom: B\nB --> FB\nendlsystem\n")
    ->Arg(1)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_DeriveBlocks, two_module_predecessor,
                  "derivation length: 18\naxiom: A B\nA B --> A B C A B\nC --> F\n")
    ->Arg(1)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_DeriveBlocks, arrays,
                  "define: { array a[4] = {1, 2, 3, 0}; }\nderivation length: 18\naxiom: A(0)\n"
                  "A(x) --> A(a[x]) [B(a[3 - x])] A(a[x])\nB(x) --> B(a[x])\n")
    ->Arg(1)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

// Parsing and checking one grammar file (the monopodial tree).
void BM_Parse(benchmark::State& state) {
  std::string path = std::string(SYLVA_SOURCE_DIR) + "/grammars/abop/fig2_06a_monopodial.lsys";
  std::string text = *sylva::ReadFile(path);
  for (auto _ : state) {
    ParseResult r = ParseGrammarText(text, path);
    benchmark::DoNotOptimize(r.grammar);
  }
  state.SetBytesProcessed(int64_t(text.size()) * state.iterations());
}
BENCHMARK(BM_Parse);

// Printing the canonical word (what `sylva derive` writes to stdout).
void BM_FormatWord(benchmark::State& state, const char* file, int steps) {
  Grammar g = Load(file);
  DeriveOptions opt;
  opt.steps = steps;
  auto r = Derive(g, opt);
  size_t bytes = 0;
  for (auto _ : state) {
    bytes = 0;
    FormatWord(r->word, g.symbols, [&](std::string_view s) { bytes += s.size(); });
  }
  state.SetBytesProcessed(int64_t(bytes) * state.iterations());
  state.SetItemsProcessed(int64_t(r->word.size()) * state.iterations());
}
BENCHMARK_CAPTURE(BM_FormatWord, koch_1_6_n7, "fig1_06_koch_island", 7)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FormatWord, monopodial_2_6a_n16, "fig2_06a_monopodial", 16)
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
