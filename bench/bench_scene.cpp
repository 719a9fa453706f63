// Scene benchmarks (issue 16's targets):
//  - BM_ReadScene10k: ReadScene on a generated 10,000-element scene
//    (elements counted with their children and the root); target < 50 ms.
//  - BM_SnowStep: one Simulation step of 100,000 snow particles (gravity,
//    drag, collide with stick against a 50-tree forest and the ground) on 2
//    threads; target 10 ms per step. items_per_second = particle steps/s
//    (per second of wall time).
// Both scenes are written to a temporary folder, so what is timed is the
// real reader and the real simulation as `sylva render` runs them.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include "scene/build.h"
#include "scene/reader.h"
#include "scene/simulation.h"

namespace {

using namespace sylva;
namespace fs = std::filesystem;

std::string TempFolder() {
  const fs::path dir = fs::temp_directory_path() / "sylva_bench_scene";
  fs::create_directories(dir);
  return dir.string();
}

std::string Grammar(const char* name) {
  return std::string(SYLVA_SOURCE_DIR) + "/grammars/abop/" + name;
}

// A scene of exactly `total` elements: the root, a simulation, and blocks
// of plants (each with two defines: 3 elements), particle systems (emitter,
// gravity, drag, collide, draw: 6 elements) and terrains (1 element), in
// turn, filled up with terrains.
std::string TenThousandElements(int total, int* written) {
  std::ostringstream s;
  s << "<?xml version=\"1.0\"?>\n<scene version=\"1\" seed=\"3\">\n";
  s << "  <simulation fps=\"24\" substeps=\"2\" duration=\"4\"/>\n";
  int n = 2, k = 0;
  const std::string g = Grammar("fig1_24a_bracketed_plant.lsys");
  while (n + 6 <= total) {
    switch (k % 3) {
      case 0:
        s << "  <plant id=\"p" << k << "\" grammar=\"" << g << "\" steps=\"3\" position=\""
          << k % 97 << " 0 " << k / 97 << "\" rotate=\"" << k % 360 << "\" scale=\"1.1\">\n"
          << "    <define name=\"a\" value=\"22.5\"/>\n    <define name=\"l\" value=\"0.5\"/>\n"
          << "  </plant>\n";
        n += 3;
        break;
      case 1:
        s << "  <particles id=\"s" << k << "\" max=\"1000\" integrator=\"symplectic\">\n"
          << "    <emitter shape=\"box\" at=\"0 10 0\" size=\"4 1 4\" rate=\"100\" "
             "direction=\"0 -1 0\" speed=\"0.5\" spread=\"15\" lifetime=\"2 3\" mass=\"0.01\" "
             "radius=\"0.02\"/>\n"
          << "    <gravity g=\"0 -9.81 0\"/>\n    <drag k=\"0.01\" quadratic=\"true\"/>\n"
          << "    <collide with=\"ground\" restitution=\"0.2\" friction=\"0.5\"/>\n"
          << "    <draw as=\"sprites\" size=\"0.05\" color=\"#ffffff\" alpha=\"0.8\"/>\n"
          << "  </particles>\n";
        n += 6;
        break;
      default:
        s << "  <terrain id=\"t" << k
          << "\" size=\"20 20\" resolution=\"33\" height=\"2\" "
             "noise=\"fbm\" octaves=\"4\" color=\"#335522\"/>\n";
        n += 1;
        break;
    }
    ++k;
  }
  for (; n < total; ++n, ++k)
    s << "  <terrain id=\"t" << k << "\" size=\"20 20\" resolution=\"33\" height=\"2\"/>\n";
  s << "</scene>\n";
  *written = n;
  return s.str();
}

void BM_ReadScene10k(benchmark::State& state) {
  int elements = 0;
  const std::string path = TempFolder() + "/ten_thousand.xml";
  std::ofstream(path) << TenThousandElements(int(state.range(0)), &elements);
  const auto bytes = fs::file_size(path);
  for (auto _ : state) {
    scene::ReadResult r = scene::ReadScene(path);
    if (!r.scene) {
      state.SkipWithError(r.diagnostics.FormatAll().c_str());
      return;
    }
    benchmark::DoNotOptimize(r.scene);
  }
  state.counters["elements"] = elements;
  state.counters["bytes"] = double(bytes);
  state.SetItemsProcessed(int64_t(elements) * state.iterations());
}
BENCHMARK(BM_ReadScene10k)->Arg(10000)->Unit(benchmark::kMillisecond)->UseRealTime();

// 50 trees of ABOP Fig. 2.6a at 11 steps (2,047 segments each, 102,350 in
// all: the "about 100k segments") 9 m tall on flat ground; snow born in a
// box above them at 100,000 a second with max 100,000, so after one second
// every particle exists. Steps of 1/24 s with one substep, as
// examples/scenes/snowy_forest.xml.
std::string SnowScene(int flakes, bool gusts) {
  std::ostringstream s;
  s << "<scene version=\"1\" seed=\"7\">\n"
    << "  <forest id=\"firs\" grammar=\"" << Grammar("fig2_06a_monopodial.lsys")
    << "\" count=\"50\" height=\"9\" area=\"-20 -20 20 20\" min-distance=\"4\" variants=\"8\" "
       "scale=\"0.9 1.3\" steps=\"11\"/>\n"
    << "  <wind velocity=\"1.2 0 0.4\" gust=\"" << (gusts ? "0.6" : "0")
    << "\" scale=\"12\" frequency=\"0.15\"/>\n"
    << "  <particles id=\"snow\" max=\"" << flakes << "\">\n"
    << "    <emitter shape=\"box\" at=\"0 14 0\" size=\"40 1 40\" rate=\"" << flakes
    << "\" direction=\"0 -1 0\" speed=\"0.4\" spread=\"20\" lifetime=\"30\" mass=\"0.0001\" "
       "radius=\"0.02\"/>\n"
    << "    <gravity g=\"0 -9.81 0\"/>\n    <drag k=\"0.0003\"/>\n"
    << "    <collide with=\"firs ground\" restitution=\"0\" friction=\"1\" stick=\"true\"/>\n"
    << "  </particles>\n"
    << "  <simulation fps=\"24\" substeps=\"1\" duration=\"30\"/>\n"
    << "</scene>\n";
  return s.str();
}

struct SnowWorld {
  scene::Scene scene;
  scene::BuiltScene built;
  std::unique_ptr<scene::Simulation> sim;
};

// Arguments: flakes, threads, tenths of a second simulated before timing,
// gusts (1: the wind of snowy_forest.xml; 0: its mean only, no noise).
void BM_SnowStep(benchmark::State& state) {
  const std::string path = TempFolder() + "/snow.xml";
  std::ofstream(path) << SnowScene(int(state.range(0)), state.range(3) != 0);
  auto w = std::make_unique<SnowWorld>();
  scene::ReadResult r = scene::ReadScene(path);
  if (!r.scene) {
    state.SkipWithError(r.diagnostics.FormatAll().c_str());
    return;
  }
  w->scene = std::move(*r.scene);
  scene::BuildResult b = scene::Build(w->scene, {});
  if (!b.scene) {
    state.SkipWithError(b.diagnostics.FormatAll().c_str());
    return;
  }
  w->built = std::move(*b.scene);
  DiagnosticList diags;
  scene::SimulationOptions options;
  options.threads = int(state.range(1));
  auto sim = scene::Simulation::Create(w->scene, w->built, options, diags);
  if (!sim) {
    state.SkipWithError(sim.error().Format().c_str());
    return;
  }
  w->sim = std::move(*sim);
  // Warm up: until every particle exists and some have landed.
  if (Status s = w->sim->AdvanceTo(double(state.range(2)) / 10); !s.ok()) {
    state.SkipWithError(s.error().Format().c_str());
    return;
  }
  const size_t live = w->sim->Count();
  for (auto _ : state) {
    if (Status s = w->sim->AdvanceTo(w->sim->time() + w->sim->stepLength()); !s.ok()) {
      state.SkipWithError(s.error().Format().c_str());
      return;
    }
  }
  state.counters["particles"] = double(live);
  size_t capsules = 0;
  for (const auto& [id, points] : w->built.points) capsules += points.capsules.size();
  state.counters["capsules"] = double(capsules);  // what the snow collides with
  state.SetItemsProcessed(int64_t(live) * state.iterations());
}
// Timed from 1.5 s (all born, all still falling: drag holds them near
// mg/k = 3.3 m/s, so the first reach the tree tops at about 1.6 s), 3.5 s
// (part resting on branches and the ground, part falling) and 6 s (all
// resting: births stop at 1 s when `max` is reached). 1.5 s once more
// without gusts: the cost of sampling the noise wind. 20,000 on 1 thread
// for profiling: valgrind --tool=callgrind bench_scene
// --benchmark_filter=BM_SnowStep/20000. CPU time is the process's (all
// threads): on a loaded machine wall time is not the step's cost, and
// CPU / threads is what an idle machine would show.
BENCHMARK(BM_SnowStep)
    ->Args({20000, 1, 15, 1})
    ->Args({100000, 2, 15, 1})
    ->Args({100000, 2, 15, 0})
    ->Args({100000, 2, 35, 1})
    ->Args({100000, 2, 60, 1})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime()
    ->Iterations(24);

}  // namespace

BENCHMARK_MAIN();
