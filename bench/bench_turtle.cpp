// Turtle interpretation throughput: modules read per second (target of
// issue 3: at least 50 million modules per second on one core).
// Argument 0: drawing into fresh memory (a one-off `sylva mesh`);
// argument 1: redrawing into a reused PlantGeometry (the viewer).
#include <benchmark/benchmark.h>

#include <string>

#include "plant/plant.h"
#include "turtle/interpreter.h"

namespace {

using namespace sylva;

void BM_Turtle(benchmark::State& state, const char* file, int steps) {
  plant::PlantSpec spec;
  spec.path = std::string(SYLVA_SOURCE_DIR) + "/grammars/abop/" + file + ".lsys";
  spec.steps = steps;
  spec.until = plant::Stage::kInterpreted;
  plant::PlantResult r = plant::BuildPlant(spec);
  const lsys::Word* word = &r.plant->DrawnWord();
  const lsys::Grammar* grammar = &r.plant->grammar;
  const turtle::TurtleDef def = turtle::TurtleDefFrom(*grammar);
  size_t segments = 0;
  const bool reuse = state.range(0) == 1;
  turtle::PlantGeometry kept;
  for (auto _ : state) {
    if (reuse) {
      (void)turtle::InterpretInto(*word, grammar->symbols, def, {}, kept);
      segments = kept.segments.size();
    } else {
      auto g = turtle::Interpret(*word, grammar->symbols, def);
      segments = g->segments.size();
      benchmark::DoNotOptimize(g->segments.data());
    }
  }
  state.SetItemsProcessed(int64_t(word->size()) * state.iterations());
  state.counters["modules"] = double(word->size());
  state.counters["segments"] = double(segments);
}

BENCHMARK_CAPTURE(BM_Turtle, koch_1_6_n6, "fig1_06_koch_island", 6)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Turtle, bracketed_1_24d_n10, "fig1_24d_bracketed_plant", 10)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Turtle, monopodial_2_6a_n18, "fig2_06a_monopodial", 18)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Turtle, ternary_tropism_2_8a_n11, "fig2_08a_ternary", 11)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
