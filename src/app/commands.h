// Subcommand options and runners, shared by cli.cpp (which declares the
// flags with CLI11) and the files that implement each subcommand.
#pragma once

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/view_file.h"
#include "core/diagnostic.h"
#include "core/parallel.h"
#include "draw/draw_list.h"
#include "plant/plant.h"
#include "scene/build.h"
#include "scene/scene.h"
#include "scene/simulation.h"

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
  bool strict = false;        // --strict: any warning is an error (exit 2)
  std::string view;           // --view: cpfg view file (default: FILE's NAME.v beside it)
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
  std::optional<double> time;  // scenes: simulated seconds (default 0)
};

struct RenderCommand {
  DeriveFlags derive;
  std::string output;  // .png
  std::string size = "960x540";
  std::string camera;            // "azimuth,elevation,distance"; empty or distance 0: framed
  std::optional<double> lodEps;  // screen-space detail tolerance, output pixels (0.5)
  std::optional<int> sides;      // set: uniform sides, no screen-space detail
  int supersample = 1;           // render K x K larger, box-filter down
  bool stats = false;            // `triangles: N` and stage times on stdout
  bool wireframe = false;        // triangle edges over the mesh
  double time = 0;               // scenes: simulated seconds before the picture
};

int RunDerive(const DeriveCommand& cmd, std::ostream& out, std::ostream& err);
int RunRender(const RenderCommand& cmd, std::ostream& out, std::ostream& err);
// `sylva render scene.xml` (cli_render_scene.cpp).
int RunRenderScene(const RenderCommand& cmd, std::ostream& out, std::ostream& err);
// "WxH", 1x1..8192x8192.
bool ParseSize(const std::string& s, int* w, int* h);
// "azimuth,elevation,distance": finite, elevation in (-90, 90), distance >= 0.
bool ParseCamera(const std::string& s, double v[3]);
int RunMesh(const MeshCommand& cmd, std::ostream& out, std::ostream& err);
// `sylva mesh --lod-eps` (sylva-graphics: the view is framed by render::Camera).
int RunMeshForView(const MeshCommand& cmd, std::ostream& out, std::ostream& err);
// Tessellates plant (built to its geometry) at spec's detail into
// cmd.output and prints its summary to `err` (both mesh runners); a .glb
// is streamed (mesh::WriteGlbStreamed), never holding the whole mesh.
int TessellateAndWrite(const MeshCommand& cmd, plant::Plant& plant, const plant::PlantSpec& spec,
                       std::ostream& err);
// `sylva mesh scene.xml` (cli_mesh_scene.cpp): glTF with instances as nodes.
int RunMeshScene(const MeshCommand& cmd, std::ostream& out, std::ostream& err);

// The plant spec the flags describe (steps, seed, -D, threads, limits);
// nullopt with *exit set when a flag is malformed (printed to `err`).
// The cpfg view file (and .map/.mat) of the grammar is read here and
// attached to the spec (app/view_file.h); `view`, when given, receives it
// (nullptr when there is none).
std::optional<plant::PlantSpec> SpecFrom(const DeriveFlags& f, std::ostream& err, int* exit,
                                         std::shared_ptr<const ViewFile>* view = nullptr);
// -D NAME=VALUE arguments into `overrides`; false (the error printed) on a
// bad name or number.
bool ParseDefines(const std::vector<std::string>& defs, std::map<std::string, double>* overrides,
                  std::ostream& err);
// A 2D figure (plant::IsLineFigure) as lines: the grammar's palette as
// written, the default one darkened so lines read on white.
draw::Lines LinesOf(const plant::Plant& plant);

// Builds the plant up to `spec.until`, printing its diagnostics (at most
// maxErrors of them, 0: all); nullopt with *exit set on an error (or, with
// `strict`, on a warning).
std::optional<plant::Plant> BuildPlant(const plant::PlantSpec& spec, int maxErrors,
                                       std::ostream& err, int* exit, bool strict = false);

int RunCheck(const DeriveFlags& flags, std::ostream& out, std::ostream& err);

// `sylva simulate scene.xml`: run the clock, write frames and the state.
struct SimulateCommand {
  std::string file;
  std::vector<std::string> defines;  // -D NAME=VALUE: scene parameters
  int threads = 0;
  int maxErrors = 20;
  bool strict = false;
  std::optional<double> duration;  // default: the scene's <simulation duration>
  std::optional<double> fps;       // frames a second written; default: the scene's fps
  std::string output;              // frame pattern, e.g. frames/%04d.png; empty: no frames
  std::string dump;                // CSV of every particle at the end
  std::string size = "960x540";
};

// One frame of a running simulation, for the graphics side to draw.
struct SimulationFrame {
  const scene::Scene& scene;
  const scene::BuiltScene& built;
  const scene::Simulation& simulation;
  int index;
};
// Writes the picture of a frame to `path` (sylva-graphics provides it).
using FrameWriter = std::function<Status(const SimulationFrame& frame, const std::string& path)>;
// Without a writer, no frames are drawn (no OpenGL is needed).
int RunSimulate(const SimulateCommand& cmd, std::ostream& out, std::ostream& err,
                const FrameWriter& writeFrame);
// The runner with frames (cli_render_scene.cpp).
int RunSimulateWithFrames(const SimulateCommand& cmd, std::ostream& out, std::ostream& err);
// The frame path of a pattern with one %d conversion (a 0 flag and a width
// allowed, %% for a percent sign); empty when the pattern is not one.
std::string FramePath(const std::string& pattern, int index);

// Scene files (.xml): read strictly, every grammar they name parsed; with
// `strict`, a warning (of the scene or a grammar) is an error too.
bool IsSceneFile(const std::string& path);
std::optional<scene::Scene> LoadScene(const std::string& path,
                                      const std::vector<std::string>& defines, int maxErrors,
                                      std::ostream& err, int* exit, bool strict = false);
int RunCheckScene(const DeriveFlags& flags, std::ostream& out, std::ostream& err);

// A scene read, built and its simulation created at t = 0: the sequence
// that render, mesh and simulate share. It lives on the heap and never
// moves (the simulation keeps references to the scene, the built scene and
// the pool).
struct SceneRun {
  explicit SceneRun(int threads) : pool(threads) {}
  ThreadPool pool;  // one pool for the command: derivation, tessellation, simulation
  scene::Scene scene;
  scene::BuiltScene built;
  std::unique_ptr<scene::Simulation> simulation;
};
struct SceneRunOptions {
  std::string path;
  std::vector<std::string> defines;
  int maxErrors = 0;
  bool strict = false;  // a warning of the scene, a grammar, the build or the simulation fails
  int threads = 0;
  int sides = 8;  // uniform tube sides of the built plants
};
// Reports every diagnostic to `err`; null with *exit set on an error (or a
// warning under `strict`).
std::unique_ptr<SceneRun> StartScene(const SceneRunOptions& options, std::ostream& err, int* exit);

// Prints diagnostics; returns the exit status they call for (0 when there
// are only warnings, 2 when there are warnings and `strict`, saying so).
int Report(const DiagnosticList& list, std::ostream& err, int maxErrors = 0, bool strict = false);
int Report(const Diagnostic& d, std::ostream& err);

}  // namespace sylva::app
