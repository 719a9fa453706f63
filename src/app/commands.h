// Subcommand options and runners, shared by cli.cpp (which declares the
// flags with CLI11) and the files that implement each subcommand.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "core/diagnostic.h"
#include "lsys/deriver.h"
#include "lsys/grammar.h"
#include "mesh/export.h"
#include "mesh/plant_geometry.h"
#include "mesh/triangle_mesh.h"

namespace sylva::app {

// Flags shared by every command that derives a grammar.
struct DeriveFlags {
  std::string file;
  std::optional<int> steps;
  std::optional<uint64_t> seed;
  std::vector<std::string> defines;  // NAME=VALUE
  int threads = 0;
  uint64_t maxModules = 0;  // 0: the library default
  int maxErrors = 20;       // errors (and warnings) printed; 0: all
};

struct DeriveCommand {
  DeriveFlags derive;
  bool stats = false;
  bool interpret = false;
  std::string output;  // empty: standard output
};

struct MeshCommand {
  DeriveFlags derive;
  std::string output;  // .obj .ply .glb .gltf
  int sides = 8;
};

struct RenderCommand {
  DeriveFlags derive;
  std::string output;          // .png
  std::string size = "960x540";
  std::string camera;          // "azimuth,elevation,distance"; empty or distance 0: framed
  int sides = 12;
};

int RunDerive(const DeriveCommand& cmd, std::ostream& out, std::ostream& err);
int RunRender(const RenderCommand& cmd, std::ostream& out, std::ostream& err);
int RunMesh(const MeshCommand& cmd, std::ostream& out, std::ostream& err);

// Parses the grammar named by the flags (with -D), printing diagnostics.
// Returns the grammar, or nullopt with the exit status in *exit.
std::optional<lsys::Grammar> LoadGrammar(const DeriveFlags& f, std::ostream& err, int* exit);
lsys::DeriveOptions DeriveOptionsFrom(const DeriveFlags& f);

// Grammar -> derived word -> interpretation rules -> turtle, as `mesh` and
// `render` need it, printing diagnostics and the turtle's warnings; nullopt
// with *exit set on failure. Times in milliseconds: derive (with the
// interpretation rules) and turtle.
struct DrawnPlant {
  lsys::Grammar grammar;
  uint64_t modules = 0;  // of the word the turtle read
  mesh::PlantGeometry geometry;
  double deriveMs = 0, turtleMs = 0;
};
std::optional<DrawnPlant> DeriveAndDraw(const DeriveFlags& f, std::ostream& err, int* exit);

// The grammar's palette, or the default one.
mesh::Palette PaletteOf(const lsys::Grammar& g);
// Loads the surfaces `geometry` places and tessellates it, printing
// diagnostics and warnings; false with *exit set on failure.
bool BuildMesh(const lsys::Grammar& g, const mesh::PlantGeometry& geometry, int sides,
               mesh::TriangleMesh* out, std::ostream& err, int* exit);
int RunCheck(const DeriveFlags& flags, std::ostream& out, std::ostream& err);

// Prints diagnostics; returns the exit status they call for (0 when there
// are only warnings).
int Report(const DiagnosticList& list, std::ostream& err, int maxErrors = 0);
int Report(const Diagnostic& d, std::ostream& err);

}  // namespace sylva::app
