// Scene files on the command line (SCENE.md, docs/scene.md): `sylva check
// scene.xml` reads the scene strictly and parses every grammar it names.
#include <unistd.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <ostream>
#include <sstream>

#include "core/atomic_file.h"
#include "scene/build.h"
#include "scene/simulation.h"

#include "app/cli.h"
#include "app/commands.h"
#include "core/parallel.h"
#include "scene/plants.h"
#include "scene/reader.h"

namespace sylva::app {

bool IsSceneFile(const std::string& path) {
  return path.size() > 4 && path.compare(path.size() - 4, 4, ".xml") == 0;
}

std::optional<scene::Scene> LoadScene(const std::string& path,
                                      const std::vector<std::string>& defines, int maxErrors,
                                      std::ostream& err, int* exit, bool strict) {
  scene::ReadOptions options;
  options.defines = defines;
  scene::ReadResult r = scene::ReadScene(path, options);
  if (!r.scene) {
    *exit = Report(r.diagnostics, err, maxErrors, strict);
    if (*exit == kExitOk) *exit = kExitBadInput;
    return std::nullopt;
  }
  DiagnosticList all = std::move(r.diagnostics);
  for (Diagnostic& d : scene::CheckGrammars(*r.scene).items) all.Add(std::move(d));
  *exit = Report(all, err, maxErrors, strict);
  if (*exit != kExitOk) return std::nullopt;
  return std::move(r.scene);
}

std::string FramePath(const std::string& pattern, int index) {
  // Exactly one %[0][width]d; %% stands for '%'.
  std::string out;
  int conversions = 0;
  for (size_t i = 0; i < pattern.size(); ++i) {
    if (pattern[i] != '%') {
      out += pattern[i];
      continue;
    }
    if (i + 1 < pattern.size() && pattern[i + 1] == '%') {
      out += '%';
      ++i;
      continue;
    }
    size_t j = i + 1;
    const bool zero = j < pattern.size() && pattern[j] == '0';
    if (zero) ++j;
    int width = 0;
    while (j < pattern.size() && std::isdigit(static_cast<unsigned char>(pattern[j])) &&
           width < 100)
      width = width * 10 + (pattern[j++] - '0');
    if (j >= pattern.size() || pattern[j] != 'd' || width > 20) return "";
    std::string digits = std::to_string(index);
    if (int(digits.size()) < width)
      digits.insert(0, size_t(width) - digits.size(), zero ? '0' : ' ');
    out += digits;
    ++conversions;
    i = j;
  }
  return conversions == 1 ? out : "";
}

std::unique_ptr<SceneRun> StartScene(const SceneRunOptions& o, std::ostream& err, int* exit) {
  auto loaded = LoadScene(o.path, o.defines, o.maxErrors, err, exit, o.strict);
  if (!loaded) return nullptr;
  auto run = std::make_unique<SceneRun>(o.threads);
  run->scene = std::move(*loaded);
  scene::BuildOptions buildOptions;
  buildOptions.pool = &run->pool;
  buildOptions.sides = o.sides;
  scene::BuildResult built = scene::Build(run->scene, buildOptions);
  *exit = Report(built.diagnostics, err, o.maxErrors, o.strict);
  if (!built.scene) {
    if (*exit == kExitOk) *exit = kExitRuntime;
    return nullptr;
  }
  if (*exit != kExitOk) return nullptr;
  run->built = std::move(*built.scene);
  DiagnosticList warnings;
  scene::SimulationOptions simOptions;
  simOptions.pool = &run->pool;
  auto sim = scene::Simulation::Create(run->scene, run->built, simOptions, warnings);
  *exit = Report(warnings, err, o.maxErrors, o.strict);
  if (!sim) {
    *exit = Report(sim.error(), err);
    return nullptr;
  }
  if (*exit != kExitOk) return nullptr;
  run->simulation = std::move(*sim);
  return run;
}

int RunSimulate(const SimulateCommand& cmd, std::ostream& out, std::ostream& err,
                const FrameWriter& writeFrame) {
  if (!cmd.output.empty() && FramePath(cmd.output, 0).empty()) {
    err << "sylva: error: -o '" << cmd.output
        << "': a frame pattern needs exactly one %d (such as frames/%04d.png; %% for a percent "
           "sign)\n";
    return kExitBadInput;
  }
  int exit = kExitOk;
  const auto run = StartScene(
      {cmd.file, cmd.defines, cmd.maxErrors, cmd.strict, cmd.threads, /*sides=*/8}, err, &exit);
  if (!run) return exit;
  const scene::Scene& sc = run->scene;
  scene::Simulation* const sim = run->simulation.get();
  const double duration = cmd.duration.value_or(sc.simulation.duration);
  const double fps = cmd.fps.value_or(sc.simulation.fps);

  // Bounded before any work: the steps the clock takes and the frames.
  const double steps = duration / sim->stepLength();
  if (steps > scene::kMaxStepsPerAdvance || duration * fps > 1e6) {
    err << "sylva: error: --duration " << duration << " s would take " << uint64_t(steps)
        << " simulation steps and " << uint64_t(duration * fps)
        << " frames, more than the limits (1e7 steps, 1e6 frames); lower --duration, --fps or "
           "the scene's fps and substeps\n";
    return kExitBadInput;
  }
  const int frames = int(std::floor(duration * fps + 1e-9)) + 1;
  const bool progress = isatty(2);
  for (int k = 0; k < frames; ++k) {
    const double t = double(k) / fps;
    if (Status s = sim->AdvanceTo(t); !s.ok()) return Report(s.error(), err);
    if (writeFrame) {
      const SimulationFrame frame{sc, run->built, *sim, k};
      const std::string path = FramePath(cmd.output, k);
      if (Status s = writeFrame(frame, path); !s.ok()) return Report(s.error(), err);
    }
    if (progress) {
      char line[160];
      std::snprintf(line, sizeof line, "\rframe %d/%d  t = %.2f s  %zu points", k + 1, frames,
                    sim->time(), sim->Count());
      err << line << std::flush;
    }
  }
  if (progress) err << "\n";
  err << sim->warnings().FormatAll();
  if (!cmd.dump.empty()) {
    std::ostringstream csv;
    sim->WriteCsv(csv);
    AtomicFile f;
    Status s = f.Open(cmd.dump);
    if (s.ok()) s = f.Write(csv.str());
    if (s.ok()) s = f.Commit();
    if (!s.ok()) return Report(s.error(), err);
  }
  char line[200];
  std::snprintf(line, sizeof line, "simulated %.3f s (%d frames%s), %zu points at the end\n",
                sim->time(), frames, writeFrame ? " written" : "", sim->Count());
  err << line;
  (void)out;
  return kExitOk;
}

int RunCheckScene(const DeriveFlags& flags, std::ostream& out, std::ostream& err) {
  int exit = kExitOk;
  const auto scene =
      LoadScene(flags.file, flags.defines, flags.maxErrors, err, &exit, flags.strict);
  return scene ? kExitOk : exit;
}

}  // namespace sylva::app
