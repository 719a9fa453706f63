// sylva derive / sylva check
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <ostream>

#include <map>
#include "app/cli.h"
#include "app/commands.h"
#include "core/atomic_file.h"
#include "core/parallel.h"

namespace sylva::app {

bool ParseDefines(const std::vector<std::string>& defs, std::map<std::string, double>* overrides,
                  std::ostream& err) {
  for (const auto& d : defs) {
    size_t eq = d.find('=');
    std::string name = d.substr(0, eq);
    bool okName =
        !name.empty() && (std::isalpha(static_cast<unsigned char>(name[0])) || name[0] == '_');
    for (char ch : name) okName &= std::isalnum(static_cast<unsigned char>(ch)) || ch == '_';
    if (eq == std::string::npos || !okName) {
      err << "sylva: error: -D expects NAME=VALUE, got '" << d << "'\n";
      return false;
    }
    std::string value = d.substr(eq + 1);
    char* end = nullptr;
    double v = std::strtod(value.c_str(), &end);
    if (value.empty() || *end != '\0' || !std::isfinite(v)) {
      err << "sylva: error: -D " << name << ": '" << value << "' is not a number\n";
      return false;
    }
    (*overrides)[name] = v;
  }
  return true;
}

std::optional<plant::PlantSpec> SpecFrom(const DeriveFlags& f, std::ostream& err, int* exit,
                                         std::shared_ptr<const ViewFile>* view) {
  plant::PlantSpec spec;
  spec.path = f.file;
  if (!ParseDefines(f.defines, &spec.defines, err)) {
    *exit = kExitBadInput;
    return std::nullopt;
  }
  spec.steps = f.steps;
  spec.seed = f.seed;
  spec.threads = f.threads;
  if (f.maxModules) spec.limits.maxModules = f.maxModules;
  if (f.maxTriangles) spec.limits.maxTriangles = f.maxTriangles;
  std::shared_ptr<const ViewFile> v = LoadViewFiles(f.file, f.view);
  AttachViewFile(v, spec);
  if (view) *view = std::move(v);
  return spec;
}

std::optional<plant::Plant> BuildPlant(const plant::PlantSpec& spec, int maxErrors,
                                       std::ostream& err, int* exit, bool strict) {
  plant::PlantResult r = plant::BuildPlant(spec);
  *exit = Report(r.diagnostics, err, maxErrors, strict);
  if (!r.plant && *exit == kExitOk) *exit = kExitBadInput;
  if (*exit != kExitOk) return std::nullopt;
  return std::move(r.plant);
}

int RunCheck(const DeriveFlags& flags, std::ostream& out, std::ostream& err) {
  if (IsSceneFile(flags.file)) return RunCheckScene(flags, out, err);
  int exit = kExitOk;
  auto spec = SpecFrom(flags, err, &exit);
  if (!spec) return exit;
  spec->until = plant::Stage::kGrammar;
  auto p = BuildPlant(*spec, flags.maxErrors, err, &exit, flags.strict);
  return p ? kExitOk : exit;
}

static void PrintStats(const plant::Plant& p, int threads, uint64_t seed, std::ostream& out) {
  const lsys::Grammar& g = p.grammar;
  char line[256];
  out << "grammar: " << g.path << " (" << g.name << ")\n";
  std::snprintf(line, sizeof line, "steps: %d  seed: %llu  threads: %d\n", int(p.steps.size()) - 1,
                static_cast<unsigned long long>(seed), threads);
  out << line;
  out << "step       modules      time\n";
  uint64_t produced = 0;
  double seconds = 0;
  for (const auto& s : p.steps) {
    seconds += s.seconds;
    if (s.step > 0) produced += s.modules;
    std::snprintf(line, sizeof line, "%4d %13llu %9.4f s\n", s.step,
                  static_cast<unsigned long long>(s.modules), s.seconds);
    out << line;
  }
  std::vector<uint64_t> count(g.symbols.size(), 0);
  for (lsys::SymbolId s : p.word.symbols) ++count[s];
  out << "modules: " << p.word.size() << "\n";
  out << "per symbol:\n";
  for (size_t s = 0; s < count.size(); ++s) {
    if (!count[s]) continue;
    std::string name = g.symbols.name(lsys::SymbolId(s));
    int a = g.symbols.arity(lsys::SymbolId(s));
    if (a) name += "/" + std::to_string(a);
    std::snprintf(line, sizeof line, "  %-12s %13llu\n", name.c_str(),
                  static_cast<unsigned long long>(count[s]));
    out << line;
  }
  double rate = seconds > 0 ? double(produced) / seconds : 0;
  std::snprintf(line, sizeof line, "time: %.4f s (%llu modules produced, %.1f million modules/s)\n",
                seconds, static_cast<unsigned long long>(produced), rate / 1e6);
  out << line;
  std::snprintf(line, sizeof line, "word memory: %.1f MiB\n",
                double(p.word.MemoryBytes()) / (1 << 20));
  out << line;
}

int RunDerive(const DeriveCommand& cmd, std::ostream& out, std::ostream& err) {
  int exit = kExitOk;
  auto spec = SpecFrom(cmd.derive, err, &exit);
  if (!spec) return exit;
  spec->until = cmd.interpret ? plant::Stage::kInterpreted : plant::Stage::kWord;
  // Progress on a terminal, once a derivation has run for a second.
  const bool tty = &err == &std::cerr && isatty(2);
  const auto start = std::chrono::steady_clock::now();
  bool shown = false;
  if (tty) {
    spec->progress = [&](int step, int steps, uint64_t modules) {
      double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (t < 1.0) return;
      shown = true;
      std::fprintf(stderr, "\rstep %d/%d: %llu modules   ", step, steps,
                   static_cast<unsigned long long>(modules));
    };
  }
  auto p = BuildPlant(*spec, cmd.derive.maxErrors, err, &exit, cmd.derive.strict);
  if (shown) std::fprintf(stderr, "\r%60s\r", "");
  if (!p) return exit;
  const lsys::Grammar* g = &p->grammar;
  const lsys::Word* word = cmd.interpret ? &p->DrawnWord() : &p->word;
  if (cmd.stats) {
    int threads =
        cmd.derive.threads > 0 ? cmd.derive.threads : sylva::ThreadPool::HardwareThreads();
    PrintStats(*p, threads, spec->seed.value_or(g->seed), out);
    return kExitOk;
  }
  if (cmd.output.empty()) {
    lsys::FormatWord(*word, g->symbols, [&](std::string_view s) { out.write(s.data(), s.size()); });
    out << '\n';
    out.flush();
    if (!out) {
      err << "sylva: error: cannot write to standard output\n";
      return kExitRuntime;
    }
    return kExitOk;
  }
  AtomicFile file;
  if (Status s = file.Open(cmd.output); !s.ok()) return Report(s.error(), err);
  Status ws;
  lsys::FormatWord(*word, g->symbols, [&](std::string_view s) {
    if (ws.ok()) ws = file.Write(s);
  });
  if (ws.ok()) ws = file.Write("\n");
  if (ws.ok()) ws = file.Commit();
  if (!ws.ok()) return Report(ws.error(), err);
  return kExitOk;
}

}  // namespace sylva::app
