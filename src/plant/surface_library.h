// Predefined surfaces (`~leaf`, `~petal`, your own `~name`): the meshes a
// plant's SurfaceInstances place, found by name in one place.
//
// A surface `~name` is the Wavefront OBJ file `name.obj`, searched in order
// in: the folders the caller adds (PlantSpec::surfacePath), the grammar's
// folder, its `surfaces/` folder, and the bundled `grammars/surfaces`.
// The first file found wins. Meshes are loaded once per library.
// A cpfg surface (plant/cpfg_surface.h: a view file's `surface: l leaf.s
// ...`) defined with Define() wins over an OBJ of the same name.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "core/status.h"
#include "lsys/grammar.h"
#include "mesh/plant_geometry.h"
#include "mesh/triangle_mesh.h"
#include "plant/cpfg_surface.h"

namespace sylva::plant {

// The folder of bundled data (grammars/surfaces, shaders): $SYLVA_DATA_DIR,
// else share/sylva beside the executable (an installed `sylva`) or where
// `cmake --install` put it, else the source tree of the build.
std::string BundledDataDir();

class SurfaceLibrary {
 public:
  using FileReader = std::function<std::optional<std::string>(const std::string& path)>;

  // `extra` folders first, then those of the grammar at `grammarPath`, then
  // the bundled ones. `readFile` (optional) reads a file's text instead of
  // the file system (tests, fuzzers).
  SurfaceLibrary(const std::string& grammarPath, const std::vector<std::string>& extra = {},
                 FileReader readFile = {});

  // Names cpfg .s surfaces (a view file's `surface:` lines).
  void Define(const std::vector<CpfgSurfaceDef>& defs);

  // Loads every surface `geometry` places that is not loaded yet. A surface
  // that is nowhere (no view-file `surface:` line, no NAME.obj) draws
  // nothing, as in cpfg, with a warning in `warnings` (when given) at its
  // first use in `g`, once per name. An error (a bad OBJ file, an unreadable
  // .s file) points at the surface's file or its `surface:` line.
  Status LoadFor(const mesh::PlantGeometry& geometry, const lsys::Grammar& g,
                 DiagnosticList* warnings = nullptr);

  // Whether NAME.obj is in the search path (what the grammar parser asks
  // to read cpfg's one-letter `~lF` as `~l` then `F`).
  bool Has(const std::string& name) const;

  // Surfaces by name (without `~`): what mesh::TessellateOptions takes.
  const std::unordered_map<std::string, mesh::TriangleMesh>& meshes() const { return meshes_; }
  const std::vector<std::string>& searchPath() const { return searchPath_; }

 private:
  // The path of NAME.obj in the search path (empty when none) and, with a
  // FileReader, its text.
  std::string Locate(const std::string& name, std::optional<std::string>* text) const;

  std::vector<std::string> searchPath_;
  FileReader readFile_;
  std::unordered_map<std::string, mesh::TriangleMesh> meshes_;
  std::unordered_map<std::string, CpfgSurfaceDef> cpfg_;
  Status LoadCpfg(const CpfgSurfaceDef& def);
};

}  // namespace sylva::plant
