// Scene files on the command line (SCENE.md, docs/scene.md): `sylva check
// scene.xml` reads the scene strictly and parses every grammar it names.
#include <ostream>

#include "app/cli.h"
#include "app/commands.h"
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

int RunCheckScene(const DeriveFlags& flags, std::ostream& out, std::ostream& err) {
  int exit = kExitOk;
  const auto scene =
      LoadScene(flags.file, flags.defines, flags.maxErrors, err, &exit, flags.strict);
  return scene ? kExitOk : exit;
}

}  // namespace sylva::app
