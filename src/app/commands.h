// Subcommand options and runners, shared by cli.cpp (which declares the
// flags with CLI11) and the files that implement each subcommand.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "core/diagnostic.h"
#include "plant/plant.h"

namespace sylva::app {

// Flags shared by every command that derives a grammar.
struct DeriveFlags {
  std::string file;
  std::optional<int> steps;
  std::optional<uint64_t> seed;
  std::vector<std::string> defines;  // NAME=VALUE
  int threads = 0;
  uint64_t maxModules = 0;    // 0: the library default
  uint64_t maxTriangles = 0;  // mesh and render only; 0: the library default
  int maxErrors = 20;         // errors (and warnings) printed; 0: all
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
  // Screen-space detail for the view `size` and `camera` describe (as
  // `sylva render` frames it); unset: uniform `sides`.
  std::optional<double> lodEps;
  std::string size = "960x540";
  std::string camera;
};

struct RenderCommand {
  DeriveFlags derive;
  std::string output;  // .png
  std::string size = "960x540";
  std::string camera;        // "azimuth,elevation,distance"; empty or distance 0: framed
  double lodEps = 0.5;       // screen-space detail tolerance, output pixels
  std::optional<int> sides;  // set: uniform sides, no screen-space detail
  int supersample = 1;       // render K x K larger, box-filter down
  bool stats = false;        // `triangles: N` and stage times on stdout
};

int RunDerive(const DeriveCommand& cmd, std::ostream& out, std::ostream& err);
int RunRender(const RenderCommand& cmd, std::ostream& out, std::ostream& err);
int RunMesh(const MeshCommand& cmd, std::ostream& out, std::ostream& err);
// `sylva mesh --lod-eps` (sylva-graphics: the view is framed by render::Camera).
int RunMeshForView(const MeshCommand& cmd, std::ostream& out, std::ostream& err);
// Writes plant.mesh to cmd.output and its summary to `err` (both mesh runners).
int WriteMeshOf(const MeshCommand& cmd, const plant::Plant& plant, std::ostream& err);

// The plant spec the flags describe (steps, seed, -D, threads, limits);
// nullopt with *exit set when a flag is malformed (printed to `err`).
std::optional<plant::PlantSpec> SpecFrom(const DeriveFlags& f, std::ostream& err, int* exit);

// Builds the plant up to `spec.until`, printing its diagnostics (at most
// maxErrors of them, 0: all); nullopt
// with *exit set on an error.
std::optional<plant::Plant> BuildPlant(const plant::PlantSpec& spec, int maxErrors,
                                       std::ostream& err, int* exit);

int RunCheck(const DeriveFlags& flags, std::ostream& out, std::ostream& err);

// Prints diagnostics; returns the exit status they call for (0 when there
// are only warnings).
int Report(const DiagnosticList& list, std::ostream& err, int maxErrors = 0);
int Report(const Diagnostic& d, std::ostream& err);

}  // namespace sylva::app
