#include "scene/plants.h"

#include <set>

#include "core/rng.h"

namespace sylva::scene {
namespace {

std::map<std::string, double> Defines(const std::vector<Define>& defines) {
  std::map<std::string, double> out;
  for (const Define& d : defines) out[d.name] = d.value;
  return out;
}

void Check(const plant::PlantSpec& spec, const SourceLoc& where, const std::string& element,
           DiagnosticList& out) {
  plant::PlantSpec s = spec;
  s.until = plant::Stage::kGrammar;
  const plant::PlantResult r = plant::BuildPlant(s);
  if (r.diagnostics.items.empty()) return;
  for (const Diagnostic& d : r.diagnostics.items) out.Add(d);
  Diagnostic note = MakeError(where, "in the grammar of this <" + element + ">");
  note.severity = Severity::kNote;
  out.Add(std::move(note));
}

}  // namespace

plant::PlantSpec SpecFor(const PlantDef& p) {
  plant::PlantSpec s;
  s.path = p.grammar;
  s.steps = p.steps;
  s.seed = p.seed;
  s.defines = Defines(p.defines);
  return s;
}

uint64_t ElementSeed(uint64_t sceneSeed, const std::string& id, const char* kind, size_t index) {
  // FNV-1a of the key: stable across compilers, unlike std::hash.
  const std::string key = id.empty() ? std::string(kind) + "#" + std::to_string(index) : id;
  uint64_t h = 0xcbf29ce484222325ull;
  for (unsigned char c : key) h = (h ^ c) * 0x100000001b3ull;
  return CounterHash(sceneSeed, h) >> 11;  // 53 bits, as the CLI allows
}

plant::PlantSpec SpecFor(const ForestDef& f, uint64_t forestSeed, int variant) {
  plant::PlantSpec s;
  s.path = f.grammar;
  s.steps = f.steps;
  s.seed = CounterHash(forestSeed, uint64_t(variant)) >> 11;  // 53 bits, as the CLI allows
  s.defines = Defines(f.defines);
  return s;
}

DiagnosticList CheckGrammars(const Scene& scene) {
  DiagnosticList out;
  std::set<std::pair<std::string, std::map<std::string, double>>> seen;
  auto once = [&](const plant::PlantSpec& s, const SourceLoc& where, const char* element) {
    if (seen.emplace(s.path, s.defines).second) Check(s, where, element, out);
  };
  for (const PlantDef& p : scene.plants) once(SpecFor(p), p.grammarLoc, "plant");
  for (size_t i = 0; i < scene.forests.size(); ++i) {
    const ForestDef& f = scene.forests[i];
    const uint64_t seed = f.seed.value_or(ElementSeed(scene.seed, f.id, "forest", i));
    once(SpecFor(f, seed, 0), f.grammarLoc, "forest");
  }
  return out;
}

}  // namespace sylva::scene
