#include "plant/plant.h"

#include <algorithm>
#include <chrono>
#include <utility>

#include "core/parallel.h"
#include "lsys/parser.h"
#include "mesh/color.h"
#include "plant/cpfg_environment.h"
#include "plant/surface_library.h"

namespace sylva::plant {
namespace {

using Clock = std::chrono::steady_clock;

double MsSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// The turtle and the tessellator report warnings as text naming the
// module; they become warnings about the grammar file.
void AddWarnings(const std::vector<std::string>& warnings, const std::string& path,
                 DiagnosticList& out) {
  for (const std::string& w : warnings) {
    Diagnostic d;
    d.severity = Severity::kWarning;
    d.loc.file = path;
    d.message = w;
    out.Add(std::move(d));
  }
}

// The turtle's warnings: those about a module written in the grammar are
// placed where the grammar first writes that module's name.
void AddTurtleWarnings(const mesh::PlantGeometry& geometry, const lsys::Grammar& g,
                       DiagnosticList& out) {
  AddWarnings(geometry.warnings, g.path, out);
  for (const mesh::PlantGeometry::ModuleWarning& w : geometry.moduleWarnings) {
    Diagnostic d;
    d.severity = Severity::kWarning;
    d.loc.file = g.path;
    if (auto it = g.symbolLoc.find(w.symbol); it != g.symbolLoc.end()) {
      d.loc = it->second.loc;
      SetExcerpt(d, g.SourceLine(d.loc));
      d.length = int(w.symbol.size());
    }
    d.message = w.message;
    out.Add(std::move(d));
  }
}

// cpfg and ABOP grammars give widths in pixels of their renderer (Fig. 2.6
// starts at !(10) on unit internodes): drawn as world units, a tree becomes
// a cone. When most segments are far wider than long and the grammar has no
// `width scale:`, say so and name the fix.
void WarnAboutPixelWidths(const lsys::Grammar& g, const mesh::PlantGeometry& geometry,
                          DiagnosticList& out) {
  if (g.widthScale != 1 || geometry.widthInPixels || geometry.segments.size() < 4) return;
  size_t fat = 0;
  for (const mesh::Segment& s : geometry.segments) {
    const double diameter = 2.0 * std::max(s.radiusStart, s.radiusEnd);
    if (diameter > 3 * (s.end - s.start).norm()) ++fat;
  }
  if (fat * 2 <= geometry.segments.size()) return;
  Diagnostic d;
  d.severity = Severity::kWarning;
  d.loc.file = g.path;
  d.message = std::to_string(fat) + " of " + std::to_string(geometry.segments.size()) +
              " segments are more than 3 times wider than long: widths in cpfg and ABOP grammars "
              "are pixels; add 'width scale: 0.015' to draw them as printed (docs/grammar.md)";
  out.Add(std::move(d));
}

Diagnostic SpecError(const std::string& message) {
  Diagnostic d;
  d.message = message;
  return d;
}

// The turtle is bounded with the mesh: a drawn segment becomes at least a
// few triangles, so a word may draw at most a quarter of maxTriangles.
turtle::DrawOptions DrawOptionsOf(const PlantSpec& spec) {
  turtle::DrawOptions o = spec.draw;
  o.maxPrimitives = std::max<uint64_t>(1, spec.limits.maxTriangles / 4);
  return o;
}

lsys::DeriveOptions DeriveOptionsOf(const PlantSpec& spec) {
  lsys::DeriveOptions o;
  o.seed = spec.seed;
  o.threads = spec.threads;
  o.pool = spec.pool;
  o.maxModules = spec.limits.maxModules;
  return o;
}

}  // namespace

DiagnosticList Validate(const PlantSpec& spec) {
  DiagnosticList list;
  if (!spec.text && spec.path.empty()) list.Add(SpecError("no grammar: give a file or a text"));
  if (spec.steps && (*spec.steps < 0 || *spec.steps > lsys::kMaxDerivationLength)) {
    list.Add(SpecError("steps " + std::to_string(*spec.steps) + " is outside 0.." +
                       std::to_string(lsys::kMaxDerivationLength)));
  }
  if (spec.threads < 0 || spec.threads > 256) {
    list.Add(SpecError("threads " + std::to_string(spec.threads) + " is outside 0..256"));
  }
  if (spec.detail.sides < 3 || spec.detail.sides > 256) {
    list.Add(SpecError("sides " + std::to_string(spec.detail.sides) + " is outside 3..256"));
  }
  if (spec.view) {
    const mesh::ScreenView& v = *spec.view;
    if (!(v.eps > 0 && v.eps <= 1e6)) {
      list.Add(SpecError("lod eps " + std::to_string(v.eps) + " is outside (0, 1e6] pixels"));
    }
    if (v.width < 1 || v.height < 1 || v.width > 16384 || v.height > 16384) {
      list.Add(SpecError("viewport " + std::to_string(v.width) + "x" + std::to_string(v.height) +
                         " is outside 1x1..16384x16384"));
    }
    if (!v.viewProjection.allFinite()) {
      list.Add(SpecError("the view-projection matrix has a non-finite entry"));
    }
  }
  if (spec.limits.maxTriangles < 1) list.Add(SpecError("max triangles 0 is outside 1.."));
  if (spec.limits.maxModules < 1 || spec.limits.maxModules > lsys::kMaxModulesCap) {
    list.Add(SpecError("max modules " + std::to_string(spec.limits.maxModules) + " is outside 1.." +
                       std::to_string(lsys::kMaxModulesCap)));
  }
  return list;
}

mesh::Palette PaletteOf(const lsys::Grammar& g) {
  if (g.palette.empty()) return mesh::DefaultPalette();
  mesh::Palette p;
  for (const auto& c : g.palette) p.push_back(mesh::Srgb(c[0], c[1], c[2]));  // written sRGB
  return p;
}

Expected<mesh::Box> MeshBounds(const Plant& plant, const PlantSpec& spec) {
  SurfaceLibrary surfaces(plant.grammar.path, spec.surfacePath, spec.readFile);
  surfaces.Define(spec.cpfgSurfaces);
  if (Status s = surfaces.LoadFor(plant.geometry, plant.grammar); !s.ok()) return s.error();
  return mesh::TessellatedBounds(plant.geometry, &surfaces.meshes());
}

bool IsLineFigure(const mesh::PlantGeometry& geometry) {
  return geometry.planar && !geometry.cylinderStyle && geometry.polygons.empty() &&
         geometry.surfaces.empty() && geometry.spheres.empty() && geometry.tubes.empty();
}

Status Tessellate(Plant& plant, const PlantSpec& spec, DiagnosticList& diagnostics,
                  const mesh::MeshStream* stream) {
  const auto t0 = Clock::now();
  SurfaceLibrary surfaces(plant.grammar.path, spec.surfacePath, spec.readFile);
  surfaces.Define(spec.cpfgSurfaces);
  if (Status s = surfaces.LoadFor(plant.geometry, plant.grammar, &diagnostics); !s.ok()) return s;
  mesh::TessellateOptions options;
  options.detail = spec.detail;
  options.view = spec.view;
  options.cull = spec.cull;
  options.history = spec.history;
  ThreadPool ownPool(spec.pool ? 1 : spec.threads);
  options.pool = spec.pool ? spec.pool : &ownPool;
  options.surfaces = &surfaces.meshes();
  options.maxTriangles = spec.limits.maxTriangles;
  mesh::TessellateStats stats;
  plant.mesh = mesh::TriangleMesh();
  size_t streamed = 0;  // triangles handed to `stream`
  mesh::MeshStream counted;
  if (stream) {
    counted = *stream;
    counted.piece = [&](const mesh::TriangleMesh& piece, size_t first) {
      streamed += piece.triangleCount();
      return stream->piece(piece, first);
    };
    options.stream = &counted;
  }
  if (Status s = mesh::Tessellate(plant.geometry, options, plant.mesh, &stats); !s.ok()) {
    Diagnostic d = s.error();
    d.loc.file = plant.grammar.path;
    return d;
  }
  if (plant.mesh.triangleCount() + streamed == 0) {
    Diagnostic d;
    d.severity = Severity::kWarning;
    d.loc.file = plant.grammar.path;
    d.message = "the plant draws nothing: the mesh is empty";
    diagnostics.Add(std::move(d));
  }
  AddWarnings(stats.warnings, plant.grammar.path, diagnostics);
  WarnAboutPixelWidths(plant.grammar, plant.geometry, diagnostics);
  plant.time.tessellate = MsSince(t0);
  return {};
}

Grower::Grower(Grower&&) noexcept = default;
Grower& Grower::operator=(Grower&&) noexcept = default;
Grower::~Grower() = default;

std::optional<Grower> Grower::Start(const PlantSpec& spec, DiagnosticList& diagnostics) {
  DiagnosticList bad = Validate(spec);
  if (bad.HasErrors()) {
    for (auto& d : bad.items) diagnostics.Add(std::move(d));
    return std::nullopt;
  }
  const auto t0 = Clock::now();
  lsys::ParseOptions popt;
  popt.overrides = spec.defines;
  popt.readFile = spec.readFile;
  popt.environmentGiven = spec.environment != nullptr;
  // A cpfg folder names its environment program in a .e file
  // (plant/cpfg_environment.h); it answers ?E when the grammar names none.
  std::optional<CpfgEnvironmentRef> cpfgEnv;
  if (!spec.environment && (!spec.text || spec.readFile)) {
    cpfgEnv = FindCpfgEnvironment(spec.path, spec.readFile);
    if (cpfgEnv) popt.environmentGiven = true;  // its own warnings say what is answered
  }
  popt.functionFiles = spec.cpfgFunctions;
  popt.curveFiles = spec.cpfgCurves;
  popt.viewFile = spec.cpfgViewFile;
  // `~lF`: cpfg's one-letter surface `l` then `F` when l.obj exists and lF.obj does not.
  SurfaceLibrary surfaces(spec.path, spec.surfacePath, spec.readFile);
  surfaces.Define(spec.cpfgSurfaces);
  popt.isSurface = [&surfaces](const std::string& name) { return surfaces.Has(name); };
  lsys::ParseResult parsed = spec.text ? lsys::ParseGrammarText(*spec.text, spec.path, popt)
                                       : lsys::ParseGrammarFile(spec.path, popt);
  for (auto& d : parsed.diagnostics.items) diagnostics.Add(d);
  if (!parsed.grammar) return std::nullopt;

  Grower g;
  g.spec_ = spec;
  g.grammar_ = std::make_unique<lsys::Grammar>(std::move(*parsed.grammar));
  g.diagnostics_ = std::move(parsed.diagnostics);
  if (spec.amendGrammar) {
    DiagnosticList amended;
    spec.amendGrammar(*g.grammar_, amended);
    for (const Diagnostic& d : amended.items) {
      diagnostics.Add(d);
      g.diagnostics_.Add(d);
    }
    if (amended.HasErrors()) return std::nullopt;
  }
  g.time_.parse = MsSince(t0);
  g.steps_ = spec.steps.value_or(g.grammar_->derivationLength);
  const lsys::Grammar& grammar = *g.grammar_;
  g.queries_ = QueryTableOf(grammar.symbols);
  if (g.queries_.any) {
    if (Status s = CheckQueriesSurviveInterpretation(grammar, g.queries_); !s.ok()) {
      diagnostics.Add(s.error());
      return std::nullopt;
    }
  }
  if (grammar.environment) {
    auto env =
        MakeEnvironment(*grammar.environment, grammar, spec.ground ? &*spec.ground : nullptr);
    if (!env) {
      diagnostics.Add(env.error());
      return std::nullopt;
    }
    g.ownEnvironment_ = std::move(*env);
  }
  if (!grammar.environment && !spec.environment && cpfgEnv && g.queries_.environment) {
    DiagnosticList envDiags;
    g.ownEnvironment_ = LoadCpfgEnvironment(*cpfgEnv, spec.readFile, envDiags);
    for (const Diagnostic& d : envDiags.items) {
      diagnostics.Add(d);
      g.diagnostics_.Add(d);
    }
  }
  g.environment_ = spec.environment ? spec.environment : g.ownEnvironment_.get();
  if (spec.until == Stage::kGrammar) return g;
  const auto t1 = Clock::now();
  auto derivation = lsys::Derivation::Start(*g.grammar_, DeriveOptionsOf(spec));
  if (!derivation) {
    diagnostics.Add(derivation.error());
    return std::nullopt;
  }
  g.derivation_ = std::move(*derivation);
  if (Status s = g.AnswerQueries(); !s.ok()) {
    Diagnostic d = s.error();
    if (d.loc.file.empty()) d.loc.file = grammar.path;
    diagnostics.Add(std::move(d));
    return std::nullopt;
  }
  g.time_.derive = MsSince(t1);
  return g;
}

int Grower::step() const {
  return derivation_ ? derivation_->step() : 0;
}
int Grower::steps() const {
  return derivation_ ? steps_ : 0;
}
const lsys::Word& Grower::word() const {
  SYLVA_ASSERT(derivation_.has_value());  // not with Stage::kGrammar
  return derivation_->word();
}
lsys::Word& Grower::MutableWord() {
  SYLVA_ASSERT(derivation_.has_value());
  return derivation_->MutableWord();
}

// cpfg: after each step the word is drawn (interpretation rules first) and
// each query module takes the turtle's state at it (plant/queries.h).
Status Grower::AnswerQueries() {
  if (!queries_.any) return {};
  const lsys::Grammar& g = *grammar_;
  std::optional<lsys::Word> interpreted;
  if (!g.interpretation.empty()) {
    auto w = derivation_->Interpreted();
    if (!w) return w.error();
    interpreted = std::move(*w);
  }
  turtle::DrawOptions options = DrawOptionsOf(spec_);
  options.recordModules = true;
  lsys::Word& word = derivation_->MutableWord();
  const lsys::Word& drawn = interpreted ? *interpreted : word;
  auto geometry = turtle::Interpret(drawn, g.symbols, turtle::TurtleDefFrom(g), options);
  if (!geometry) return geometry.error();
  return plant::AnswerQueries(queries_, word, drawn, *geometry, environment_);
}

bool Grower::done() const {
  return step() >= steps() || (derivation_ && derivation_->stopped());
}

int Grower::SkipSettled() {
  if (!derivation_ || done() || !derivation_->settled()) return 0;
  const int from = step();
  derivation_->SkipToStep(steps_);
  return steps_ - from;
}

Status Grower::Step() {
  SYLVA_ASSERT(derivation_.has_value());
  const auto t0 = Clock::now();
  Status s = derivation_->Step();
  if (s.ok()) s = AnswerQueries();
  time_.derive += MsSince(t0);
  if (s.ok() && spec_.progress) spec_.progress(step(), steps_, word().size());
  return s;
}

Expected<mesh::PlantGeometry> Grower::Draw(DiagnosticList* warnings) const {
  const lsys::Grammar& g = *grammar_;
  std::optional<lsys::Word> interpreted;
  if (!g.interpretation.empty()) {
    auto w = derivation_->Interpreted();
    if (!w) return w.error();
    interpreted = std::move(*w);
  }
  auto geometry = turtle::Interpret(interpreted ? *interpreted : word(), g.symbols,
                                    turtle::TurtleDefFrom(g), DrawOptionsOf(spec_));
  if (geometry && warnings) AddTurtleWarnings(*geometry, g, *warnings);
  return geometry;
}

PlantResult Grower::Finish() && {
  PlantResult r;
  r.diagnostics = std::move(diagnostics_);
  Plant p;
  p.time = time_;
  p.palette = PaletteOf(*grammar_);
  if (derivation_) {
    lsys::DeriveResult derived = std::move(*derivation_).Finish();
    derivation_.reset();
    p.word = std::move(derived.word);
    p.steps = std::move(derived.steps);
  }
  p.grammar = std::move(*grammar_);
  grammar_.reset();
  const lsys::Grammar& g = p.grammar;
  if (spec_.until >= Stage::kInterpreted && !g.interpretation.empty()) {
    const auto t0 = Clock::now();
    auto w = lsys::Interpret(g, p.word, DeriveOptionsOf(spec_));
    if (!w) {
      r.diagnostics.Add(w.error());
      return r;
    }
    p.interpreted = std::move(*w);
    p.time.interpret = MsSince(t0);
  }
  // cpfg data files that fscanf read less of than its formats asked.
  if (g.dataFiles)
    for (Diagnostic& d : g.dataFiles->ShortReads()) r.diagnostics.Add(std::move(d));
  // cpfg arrays indexed out of bounds (read at the nearest element).
  if (g.arrayBounds)
    for (Diagnostic& d : g.arrayBounds->Warnings()) r.diagnostics.Add(std::move(d));
  if (spec_.until >= Stage::kGeometry) {
    const auto t0 = Clock::now();
    auto geometry =
        turtle::Interpret(p.DrawnWord(), g.symbols, turtle::TurtleDefFrom(g), DrawOptionsOf(spec_));
    if (!geometry) {
      Diagnostic d = geometry.error();
      if (d.loc.file.empty()) d.loc.file = g.path;
      r.diagnostics.Add(std::move(d));
      return r;
    }
    p.geometry = std::move(*geometry);
    AddTurtleWarnings(p.geometry, g, r.diagnostics);
    if (spec_.amendGeometry) spec_.amendGeometry(p.geometry, p.palette);
    p.time.turtle = MsSince(t0);
  }
  if (spec_.until >= Stage::kMesh) {
    if (Status s = Tessellate(p, spec_, r.diagnostics); !s.ok()) {
      r.diagnostics.Add(s.error());
      return r;
    }
  }
  r.plant = std::move(p);
  return r;
}

// BuildPlant notes skipped steps (Grower::SkipSettled) from this many on.
constexpr int kSkippedStepsNoted = 1000;

PlantResult BuildPlant(const PlantSpec& spec) {
  DiagnosticList diagnostics;
  std::optional<Grower> grower = Grower::Start(spec, diagnostics);
  if (!grower) return PlantResult{std::nullopt, std::move(diagnostics)};
  std::optional<Diagnostic> note;  // Finish() hands on the Grower's own diagnostics
  while (!grower->done()) {
    const int from = grower->step();
    if (const int skipped = grower->SkipSettled(); skipped > 0) {
      // Said when it is many (cpfg files ask for 1000000 steps and stop(0)).
      if (skipped >= kSkippedStepsNoted) {
        Diagnostic d;
        d.severity = Severity::kNote;
        d.loc.file = grower->grammar().path;
        d.message = "step " + std::to_string(from) + " of " + std::to_string(grower->steps()) +
                    " changed nothing (no random numbers, no global variable changed): the "
                    "remaining " +
                    std::to_string(skipped) + " steps give the same word and are skipped";
        note = std::move(d);
      }
      break;
    }
    if (Status s = grower->Step(); !s.ok()) {
      Diagnostic d = s.error();
      if (d.loc.file.empty()) d.loc.file = grower->grammar().path;
      diagnostics.Add(std::move(d));
      return PlantResult{std::nullopt, std::move(diagnostics)};
    }
  }
  PlantResult r = std::move(*grower).Finish();
  if (note) r.diagnostics.Add(std::move(*note));
  return r;
}

}  // namespace sylva::plant
