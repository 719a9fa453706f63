// libFuzzer target: the whole chain users run, grammar -> derivation ->
// interpretation rules -> turtle -> surfaces -> tessellation -> every
// exporter, through the plant library. Must never crash, hang or leak.
//
// The input is a small file system: the main grammar, then any number of
// further files, each introduced by a line `#file NAME` (an #include or a
// surface NAME.obj finds it by that name). For example:
//   axiom: F~s
//   #include "r.lsys"
//   #file r.lsys
//   F --> F[+F]F
//   #file s.obj
//   v 0 0 0 ...
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <map>
#include <string>
#include <string_view>

#include "mesh/export.h"
#include "plant/plant.h"

namespace {

std::map<std::string, std::string> SplitFiles(const std::string& input) {
  std::map<std::string, std::string> files;
  std::string* current = &files["fuzz.lsys"];
  size_t pos = 0;
  while (pos < input.size()) {
    const size_t eol = input.find('\n', pos);
    const size_t end = eol == std::string::npos ? input.size() : eol + 1;
    const std::string_view line(input.data() + pos, end - pos);
    if (line.substr(0, 6) == "#file ") {
      std::string_view name = line.substr(6);
      if (!name.empty() && name.back() == '\n') name.remove_suffix(1);
      current = &files[std::string(name)];
    } else {
      current->append(line);
    }
    pos = end;
  }
  return files;
}

// One scratch folder a process for the exporters' files.
const std::string& ScratchDir() {
  static const std::string dir = [] {
    std::string t = "/tmp/sylva_fuzz_plant_" + std::to_string(getpid());
    if (mkdir(t.c_str(), 0700) != 0 && errno != EEXIST) std::abort();
    return t;
  }();
  return dir;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace sylva;
  const std::string input(reinterpret_cast<const char*>(data), size);
  const std::map<std::string, std::string> files = SplitFiles(input);
  plant::PlantSpec spec;
  spec.path = "fuzz.lsys";
  spec.readFile = [&](const std::string& path) -> std::optional<std::string> {
    // The grammar's folder is "."; includes and surfaces come by name.
    std::string name = path.rfind("./", 0) == 0 ? path.substr(2) : path;
    auto it = files.find(name);
    if (it == files.end()) return std::nullopt;
    return it->second;
  };
  spec.threads = 1;
  spec.limits.maxModules = 20000;
  spec.detail.sides = 3 + int(size % 14);
  // Parse first to bound the derivation length.
  spec.until = plant::Stage::kGrammar;
  plant::PlantResult parsed = plant::BuildPlant(spec);
  for (const auto& d : parsed.diagnostics.items) (void)d.Format();
  if (!parsed.plant) return 0;
  spec.steps = std::min(parsed.plant->grammar.derivationLength, 8);
  spec.until = plant::Stage::kMesh;
  plant::PlantResult r = plant::BuildPlant(spec);
  for (const auto& d : r.diagnostics.items) (void)d.Format();
  if (!r.plant) return 0;
  for (const char* ext : {".obj", ".ply", ".glb", ".gltf"}) {
    const std::string out = ScratchDir() + "/plant" + ext;
    Status s = mesh::WriteMesh(r.plant->mesh, r.plant->palette, out);
    if (!s.ok()) (void)s.error().Format();
  }
  return 0;
}
