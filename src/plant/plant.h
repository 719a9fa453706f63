// A plant in one call: grammar file or text -> parse -> derive ->
// interpretation rules -> turtle -> surfaces -> tessellation.
//
// Every Sylva front end (the CLI, the viewer, tests, benchmarks, scenes)
// builds plants through this file, so they all run the same chain:
//
//   PlantSpec spec;
//   spec.path = "grammars/abop/fig2_06a_monopodial.lsys";
//   spec.steps = 8;
//   plant::PlantResult r = plant::BuildPlant(spec);
//   if (!r.plant) { std::cerr << r.diagnostics.FormatAll(); return 2; }
//   mesh::WriteMesh(r.plant->mesh, r.plant->palette, "tree.glb");
//
// Derivation can also be driven one step at a time (Grower), so a caller
// can draw the word between steps: the environmental queries of open
// L-systems (?P ?H ?L ?U ?E) are answered that way.
//
// Bad numbers in a spec (a negative step count, 2 sides) are reported by
// Validate() as diagnostics before any work: never clamped, never aborted
// on (docs/design.md, "Bad numbers").
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/diagnostic.h"
#include "core/status.h"
#include "lsys/deriver.h"
#include "lsys/grammar.h"
#include "lsys/parser.h"
#include "lsys/word.h"
#include "mesh/export.h"
#include "mesh/plant_geometry.h"
#include "mesh/tessellator.h"
#include "mesh/triangle_mesh.h"
#include "plant/cpfg_surface.h"
#include "plant/environment.h"
#include "plant/ground_environment.h"
#include "plant/queries.h"
#include "turtle/interpreter.h"

namespace sylva::plant {

// How far BuildPlant goes.
enum class Stage {
  kGrammar,      // parse and check only
  kWord,         // derive (Plant::word)
  kInterpreted,  // the interpretation rules (Plant::interpreted)
  kGeometry,     // the turtle (Plant::geometry)
  kMesh,         // surfaces and tessellation (Plant::mesh)
};

struct Limits {
  // The derived word (and every interpretation pass) stops with an error
  // past this many modules. 2^28 modules: 512 MiB of symbols.
  uint64_t maxModules = lsys::kDefaultMaxModules;
  // The mesh stops with an error, before it is allocated, past this many
  // triangles (2^26: about 2 GiB), and the turtle past a quarter as many
  // drawn primitives (2^24 segments: 1.75 GiB).
  uint64_t maxTriangles = mesh::kDefaultMaxTriangles;
};

// Reads a file's text (the grammar, #include, surfaces); nullopt when it
// cannot. Default: the file system.
using FileReader = std::function<std::optional<std::string>(const std::string& path)>;

struct PlantSpec {
  std::string path;                 // the grammar file; with `text`, the name used in diagnostics
  std::optional<std::string> text;  // grammar source; when set, `path` is not read
  std::optional<int> steps;         // default: the grammar's derivation length; 0..2^31-1
  std::optional<uint64_t> seed;     // default: the grammar's `seed:`
  std::map<std::string, double> defines;  // -D NAME=VALUE: overrides `#define NAME`
  // Folders searched for NAME.obj before the grammar's own folder, its
  // surfaces/ folder and the bundled grammars/surfaces (SurfaceLibrary).
  std::vector<std::string> surfacePath;
  // cpfg surfaces by letter (a view file's `surface:` lines; app/view_file.h).
  std::vector<CpfgSurfaceDef> cpfgSurfaces;
  // cpfg function files for func(id, x) when the grammar names none (a view
  // file's `function:` lines; lsys::ParseOptions::functionFiles).
  std::vector<lsys::ParseOptions::FunctionFile> cpfgFunctions;
  // cpfg curve files for curveX/Y/Z(id, t) and curveGAL(id) (a view file's
  // `curve:` lines; lsys::ParseOptions::curveFiles).
  std::vector<lsys::ParseOptions::CurveFile> cpfgCurves;
  // The view file those come from (lsys::ParseOptions::viewFile).
  std::string cpfgViewFile;
  int threads = 0;  // derivation threads; 0: all hardware threads; at most 256
  // When set, derivation, interpretation and tessellation run on this pool
  // (the process's, core/parallel.h SharedPool; not owned) and `threads` is
  // not used. The plant is the same either way.
  ThreadPool* pool = nullptr;
  Limits limits;
  turtle::DrawOptions draw;  // what the turtle records besides geometry
  mesh::Detail detail;       // tessellation detail (sides 3..256)
  // Screen-space detail for one view (docs/lod.md); replaces `detail` when
  // set. eps > 0 pixels, viewport 1..16384 pixels.
  std::optional<mesh::ScreenView> view;
  bool cull = true;  // with a view: drop what lies outside its frustum
  // With a view: each chain's level in the last frame, read and updated
  // (hysteresis: mesh::TessellateOptions::history); not owned. Null: none.
  mesh::DetailHistory* history = nullptr;
  Stage until = Stage::kMesh;
  FileReader readFile;  // empty: the file system
  // Answers ?E instead of the environment the grammar's `environment:`
  // names (not owned; outlives the growth). Null: the grammar's, if any.
  Environment* environment = nullptr;
  // The ground `environment: terrain` answers from, in the plant's own
  // coordinates (a scene's terrain under the plant). Unset: the plane y = 0.
  std::optional<Ground> ground;
  // Called once the grammar is parsed, before derivation: a front end's
  // settings from outside the grammar (a cpfg view file, app/view_file.h)
  // go in here. Its diagnostics join the plant's; an error stops the build.
  std::function<void(lsys::Grammar& grammar, DiagnosticList& diagnostics)> amendGrammar;
  // Called once the plant is drawn (Stage::kGeometry), before it is
  // tessellated: a front end adds what it draws with the plant (a cpfg view
  // file's background scene, app/cpfg_background.h) and its colours.
  std::function<void(mesh::PlantGeometry& geometry, mesh::Palette& palette)> amendGeometry;
  // Called after each derivation step, from the calling thread.
  std::function<void(int step, int steps, uint64_t modules)> progress;
};

// Reports every bad number in `spec` (steps, threads, sides, limits) as an
// error diagnostic; empty when the spec is usable.
DiagnosticList Validate(const PlantSpec& spec);

// Wall-clock milliseconds of each stage that ran.
struct Timings {
  double parse = 0, derive = 0, interpret = 0, turtle = 0, tessellate = 0;
};

struct Plant {
  lsys::Grammar grammar;
  lsys::Word word;                     // the derived word
  std::vector<lsys::StepStats> steps;  // steps[0] is the axiom
  // The word through the interpretation rules (what the turtle read); empty
  // when the grammar has no interpretation section: use DrawnWord().
  lsys::Word interpreted;
  mesh::PlantGeometry geometry;  // Stage::kGeometry and later
  mesh::TriangleMesh mesh;       // Stage::kMesh
  mesh::Palette palette;         // the grammar's, or the default one (linear RGB)
  Timings time;

  // The word the turtle reads (from Stage::kInterpreted on).
  const lsys::Word& DrawnWord() const {
    return grammar.interpretation.empty() ? word : interpreted;
  }
};

struct PlantResult {
  std::optional<Plant> plant;  // set when there is no error
  DiagnosticList diagnostics;  // errors and warnings of every stage, in order
};

// Builds the plant `spec` describes, up to spec.until.
PlantResult BuildPlant(const PlantSpec& spec);

// Loads the surfaces plant.geometry places and tessellates it into
// plant.mesh (replacing what it held) at spec.detail. Warnings go to
// `diagnostics`; an error is returned. With a `stream`, the mesh goes to
// it in pieces (mesh::MeshStream, for mesh::WriteGlbStreamed) and
// plant.mesh is left empty.
Status Tessellate(Plant& plant, const PlantSpec& spec, DiagnosticList& diagnostics,
                  const mesh::MeshStream* stream = nullptr);

// The box every triangle of plant.geometry's mesh lies in, at any detail
// (mesh::TessellatedBounds, with the plant's surfaces loaded): a camera can
// be framed on it before tessellating. An error when a surface cannot be
// loaded.
Expected<mesh::Box> MeshBounds(const Plant& plant, const PlantSpec& spec);

// True when the geometry is a flat line figure (every point in z = 0,
// nothing but segments, and not cpfg's line style cylinder): ABOP's 2D
// figures, drawn as lines, not tubes.
bool IsLineFigure(const mesh::PlantGeometry& geometry);

// The grammar's palette (`palette:`, written in sRGB) in linear RGB, or the
// exporters' default one.
mesh::Palette PaletteOf(const lsys::Grammar& g);

// A plant grown one derivation step at a time. When the grammar has query
// modules (?P ?H ?L ?U ?E, plant/queries.h) Start() answers those of the
// axiom and every Step() those of the new word (drawing it with the turtle),
// so each step's productions read where the previous word put them.
//
//   DiagnosticList diags;
//   auto grower = Grower::Start(spec, diags);
//   while (grower && !grower->done()) {
//     if (Status s = grower->Step(); !s.ok()) ...
//     auto geometry = grower->Draw();   // the turtle on this step's word
//   }
//   PlantResult r = std::move(*grower).Finish();
class Grower {
 public:
  // Validates the spec, parses the grammar (diagnostics, warnings included,
  // go to `diagnostics`) and builds the axiom. nullopt on an error.
  static std::optional<Grower> Start(const PlantSpec& spec, DiagnosticList& diagnostics);

  Status Step();  // one derivation step; an error ends the growth
  int step() const;
  int steps() const;  // the length asked for (spec.steps or the grammar's)
  // The length is reached, or the grammar called cpfg's stop(v), v not 1.
  bool done() const;
  // When the word has stopped changing (lsys::Derivation::settled), takes
  // the growth to steps() at once and returns the steps skipped; else 0.
  // BuildPlant does; a caller that draws each step steps instead.
  int SkipSettled();

  const lsys::Grammar& grammar() const { return *grammar_; }
  const lsys::Word& word() const;
  lsys::Word& MutableWord();  // to fill query parameters between steps

  // The current word through the interpretation rules and the turtle.
  // Turtle warnings go to `warnings` when given.
  Expected<mesh::PlantGeometry> Draw(DiagnosticList* warnings = nullptr) const;

  // Runs the stages after derivation that spec.until asks for (without
  // stepping further) and returns the plant.
  PlantResult Finish() &&;

  Grower(Grower&&) noexcept;
  Grower& operator=(Grower&&) noexcept;
  ~Grower();

 private:
  Grower() = default;
  PlantSpec spec_;
  std::unique_ptr<lsys::Grammar> grammar_;  // the derivation points into it
  std::optional<lsys::Derivation> derivation_;
  int steps_ = 0;
  DiagnosticList diagnostics_;  // those Start reported, handed on by Finish
  Timings time_;
  Status AnswerQueries();
  QueryTable queries_;
  std::unique_ptr<Environment> ownEnvironment_;  // the grammar's `environment:`
  Environment* environment_ = nullptr;
};

}  // namespace sylva::plant
