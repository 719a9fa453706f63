#include "plant/plant.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>

#include "core/atomic_file.h"
#include "lsys/parser.h"
#include "plant/plant_test_util.h"
#include "plant/surface_library.h"

namespace sylva::plant {
namespace {

namespace fs = std::filesystem;

std::string Source(const std::string& rel) {
  return std::string(SYLVA_SOURCE_DIR) + "/" + rel;
}

std::string Text(const Plant& p, const lsys::Word& w) {
  return lsys::FormatWord(w, p.grammar.symbols);
}

// A folder of its own under the temp directory, removed at the end.
struct TempDir {
  fs::path path;
  TempDir() {
    path =
        fs::temp_directory_path() /
        ("sylva_plant_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
         "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
  std::string Write(const std::string& name, const std::string& text) const {
    std::ofstream(path / name) << text;
    return (path / name).string();
  }
};

TEST(Plant, WordIsTheDerivationOfTheGrammar) {
  PlantSpec spec;
  spec.path = Source("grammars/abop/fig2_06a_monopodial.lsys");
  spec.steps = 1;
  spec.until = Stage::kWord;
  PlantResult r = BuildPlant(spec);
  ASSERT_TRUE(r.plant) << r.diagnostics.FormatAll();
  EXPECT_EQ(Text(*r.plant, r.plant->word), "!(10)F(1)[&(45)B(0.6,7.07)]/(137.5)A(0.9,7.07)");
  EXPECT_EQ(r.plant->steps.size(), 2u);
  EXPECT_TRUE(r.plant->geometry.segments.empty()) << "Stage::kWord must not run the turtle";
  EXPECT_EQ(r.plant->mesh.triangleCount(), 0u);
}

TEST(Plant, InterpretationRulesReachTheTurtle) {
  // A is drawn only through the interpretation rule A --> F F.
  const char* g = "axiom: A\nA --> AA\ninterpretation:\nA --> FF\n";
  auto p = sylva::testing::PlantFromText(g, 2, Stage::kMesh);
  ASSERT_TRUE(p);
  EXPECT_EQ(Text(*p, p->word), "AAAA");
  EXPECT_EQ(Text(*p, p->DrawnWord()), "FFFFFFFF");
  EXPECT_EQ(p->geometry.segments.size(), 8u);
  EXPECT_GT(p->mesh.triangleCount(), 0u);
}

TEST(Plant, StepwiseGrowthMatchesOneCall) {
  PlantSpec spec;
  spec.path = Source("grammars/abop/fig1_27_stochastic_plant.lsys");
  spec.steps = 5;
  spec.seed = 7;
  spec.until = Stage::kMesh;
  PlantResult whole = BuildPlant(spec);
  ASSERT_TRUE(whole.plant) << whole.diagnostics.FormatAll();

  DiagnosticList diags;
  std::optional<Grower> grower = Grower::Start(spec, diags);
  ASSERT_TRUE(grower) << diags.FormatAll();
  EXPECT_EQ(grower->steps(), 5);
  size_t lastSegments = 0;
  while (!grower->done()) {
    ASSERT_TRUE(grower->Step().ok());
    // The turtle between steps sees the word of this step.
    auto geometry = grower->Draw();
    ASSERT_TRUE(geometry.ok()) << geometry.error().Format();
    EXPECT_GE(geometry->segments.size(), lastSegments) << "step " << grower->step();
    lastSegments = geometry->segments.size();
  }
  PlantResult stepped = std::move(*grower).Finish();
  ASSERT_TRUE(stepped.plant) << stepped.diagnostics.FormatAll();
  EXPECT_EQ(Text(*stepped.plant, stepped.plant->word), Text(*whole.plant, whole.plant->word));
  EXPECT_EQ(lastSegments, whole.plant->geometry.segments.size());
  EXPECT_EQ(stepped.plant->mesh.triangleCount(), whole.plant->mesh.triangleCount());
}

TEST(Plant, SameSpecSameMeshForAnyThreadCount) {
  PlantSpec spec;
  spec.path = Source("grammars/abop/fig2_06b_monopodial.lsys");
  spec.steps = 9;
  std::vector<size_t> triangles;
  std::string first;
  for (int threads : {1, 2, 4}) {
    spec.threads = threads;
    PlantResult r = BuildPlant(spec);
    ASSERT_TRUE(r.plant) << r.diagnostics.FormatAll();
    const std::string word = Text(*r.plant, r.plant->word);
    if (first.empty()) first = word;
    EXPECT_EQ(word, first) << threads << " threads";
    triangles.push_back(r.plant->mesh.triangleCount());
  }
  EXPECT_EQ(triangles[0], triangles[1]);
  EXPECT_EQ(triangles[0], triangles[2]);
}

TEST(Plant, BadNumbersInTheSpecAreDiagnosticsNotClamps) {
  PlantSpec spec;
  spec.path = Source("grammars/abop/fig1_24a_bracketed_plant.lsys");
  spec.steps = -3;
  spec.threads = 999;
  spec.detail.sides = 2;
  spec.limits.maxModules = 0;
  DiagnosticList list = Validate(spec);
  ASSERT_EQ(list.ErrorCount(), 4u) << list.FormatAll();
  const std::string all = list.FormatAll();
  for (const char* want : {"steps -3", "threads 999", "sides 2", "max modules 0"}) {
    EXPECT_NE(all.find(want), std::string::npos) << "missing '" << want << "' in:\n" << all;
  }
  PlantResult r = BuildPlant(spec);
  EXPECT_FALSE(r.plant);
  EXPECT_EQ(r.diagnostics.ErrorCount(), 4u) << r.diagnostics.FormatAll();
}

TEST(Plant, ParseErrorsComeBackWithTheirLocation) {
  PlantSpec spec;
  spec.path = "bad.lsys";
  spec.text = "axiom: A(1)\nA(x) --> A(x*r3)\n";
  PlantResult r = BuildPlant(spec);
  ASSERT_FALSE(r.plant);
  const std::string all = r.diagnostics.FormatAll();
  EXPECT_NE(all.find("bad.lsys:2:"), std::string::npos) << all;
  EXPECT_NE(all.find("r3"), std::string::npos) << all;
}

TEST(Plant, ModuleLimitStopsTheDerivation) {
  PlantSpec spec;
  spec.path = "big.lsys";
  spec.text = "axiom: F\nF --> FF\n";
  spec.steps = 30;
  spec.limits.maxModules = 1000;
  PlantResult r = BuildPlant(spec);
  ASSERT_FALSE(r.plant);
  EXPECT_NE(r.diagnostics.FormatAll().find("1000"), std::string::npos) << r.diagnostics.FormatAll();
}

TEST(Plant, StepsAfterTheWordSettlesAreSkippedWithANote) {
  // cpfg files ask for `derivation length: 1000000` and mean "until it stops".
  PlantSpec spec;
  spec.path = "long.l";
  spec.text = "derivation length: 1000000\naxiom: A(0)\nA(n) : n < 3 --> A(n+1)\n";
  spec.until = Stage::kWord;
  PlantResult r = BuildPlant(spec);
  ASSERT_TRUE(r.plant) << r.diagnostics.FormatAll();
  ASSERT_FALSE(r.plant->steps.empty());
  EXPECT_EQ(r.plant->steps.back().step, 1000000);
  EXPECT_NE(r.diagnostics.FormatAll().find("long.l: note: step 4 of 1000000 changed nothing (no "
                                           "random numbers, no global variable changed): the "
                                           "remaining 999996 steps give the same word and are "
                                           "skipped"),
            std::string::npos)
      << r.diagnostics.FormatAll();
}

TEST(Plant, FilesComeThroughTheReaderWhenOneIsGiven) {
  // Includes and surfaces from memory: what fuzzers and embedders use.
  std::map<std::string, std::string> files = {
      {"mem/main.lsys", "#include \"rules.lsys\"\naxiom: F~blob\n"},
      {"mem/rules.lsys", "F --> FF\n"},
      {"mem/blob.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"},
  };
  PlantSpec spec;
  spec.path = "mem/main.lsys";
  spec.steps = 2;
  spec.readFile = [&](const std::string& path) -> std::optional<std::string> {
    auto it = files.find(path);
    if (it == files.end()) return std::nullopt;
    return it->second;
  };
  PlantResult r = BuildPlant(spec);
  ASSERT_TRUE(r.plant) << r.diagnostics.FormatAll();
  EXPECT_EQ(Text(*r.plant, r.plant->word), "FFFF~blob");
  ASSERT_EQ(r.plant->geometry.surfaces.size(), 1u);
  EXPECT_GE(r.plant->mesh.triangleCount(), 1u + 4 * 2 * 8);
}

TEST(Plant, ADataFileReadShortIsAWarningNamingTheFile) {
  // cpfg's fscanf at the end of its data file leaves the variables as they
  // were (C's rule); the plant says so after the derivation.
  std::map<std::string, std::string> files{
      {"mem/p.l",
       "Start: { fp = fopen(\"len.dat\", \"r\"); i = 0;\n"
       "  while (i < 3) { fscanf(fp, \"%lf\", &len); i = i + 1; } }\n"
       "axiom: F(len)\n"},
      {"mem/len.dat", "2\n"},
  };
  PlantSpec spec;
  spec.path = "mem/p.l";
  spec.until = Stage::kWord;
  spec.readFile = [&](const std::string& path) -> std::optional<std::string> {
    auto it = files.find(path);
    if (it == files.end()) return std::nullopt;
    return it->second;
  };
  PlantResult r = BuildPlant(spec);
  ASSERT_TRUE(r.plant) << r.diagnostics.FormatAll();
  EXPECT_EQ(Text(*r.plant, r.plant->word), "F(2)");
  const std::string all = r.diagnostics.FormatAll();
  EXPECT_NE(all.find("mem/len.dat: warning: fscanf stopped before the end of its format 2 times"),
            std::string::npos)
      << all;
}

TEST(SurfaceLibrary, CallerFoldersComeFirstThenTheGrammarsThenTheBundledOnes) {
  TempDir dir;
  fs::create_directories(dir.path / "mine");
  const std::string grammar = dir.Write("g.lsys", "axiom: ~leaf\n");
  // A one-triangle leaf in the caller's folder hides the bundled leaf.
  std::ofstream(dir.path / "mine" / "leaf.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  PlantSpec spec;
  spec.path = grammar;
  spec.surfacePath = {(dir.path / "mine").string()};
  PlantResult mine = BuildPlant(spec);
  ASSERT_TRUE(mine.plant) << mine.diagnostics.FormatAll();
  EXPECT_EQ(mine.plant->mesh.triangleCount(), 1u);

  spec.surfacePath.clear();
  PlantResult bundled = BuildPlant(spec);
  ASSERT_TRUE(bundled.plant) << bundled.diagnostics.FormatAll();
  EXPECT_GT(bundled.plant->mesh.triangleCount(), 1u) << "the bundled grammars/surfaces/leaf.obj";

  SurfaceLibrary lib(grammar, {"extra"});
  ASSERT_EQ(lib.searchPath().size(), 4u);
  EXPECT_EQ(lib.searchPath()[0], "extra");
  EXPECT_EQ(lib.searchPath()[1], dir.path.string());
  EXPECT_EQ(lib.searchPath()[2], (dir.path / "surfaces").string());
}

TEST(SurfaceLibrary, UnknownSurfaceIsAWarningAtItsUseAndDrawsNothing) {
  PlantSpec spec;
  spec.path = "s.lsys";
  spec.text = "axiom: F\nF --> F[+F~nosuch]~nosuch\n";
  spec.steps = 1;
  PlantResult r = BuildPlant(spec);
  ASSERT_TRUE(r.plant) << r.diagnostics.FormatAll();
  const std::string all = r.diagnostics.FormatAll();
  EXPECT_NE(all.find("s.lsys:2:11: warning: unknown surface 'nosuch' is not drawn (as in cpfg)"),
            std::string::npos)
      << all;
  EXPECT_EQ(r.diagnostics.items.size(), 1u) << all;  // once per name
  // Nothing is drawn for it: the mesh is the one without the surfaces.
  PlantSpec plain = spec;
  plain.text = "axiom: F\nF --> F[+F]\n";
  PlantResult p = BuildPlant(plain);
  ASSERT_TRUE(p.plant) << p.diagnostics.FormatAll();
  EXPECT_EQ(r.plant->mesh.triangleCount(), p.plant->mesh.triangleCount());
}

}  // namespace
}  // namespace sylva::plant

namespace sylva::plant {
namespace {

TEST(Plant, PixelWidthsWithoutWidthScaleGetAWarningNamingTheFix) {
  // ABOP Fig. 2.6a without its `width scale:` line: a brown cone.
  std::string text =
      *ReadFile(std::string(SYLVA_SOURCE_DIR) + "/grammars/abop/fig2_06a_monopodial.lsys");
  const size_t at = text.find("width scale:");
  ASSERT_NE(at, std::string::npos);
  text.erase(at, text.find('\n', at) - at);
  PlantSpec spec;
  spec.path = "cone.lsys";
  spec.text = text;
  spec.steps = 6;
  PlantResult r = BuildPlant(spec);
  ASSERT_TRUE(r.plant) << r.diagnostics.FormatAll();
  const std::string all = r.diagnostics.FormatAll();
  EXPECT_NE(all.find("warning:"), std::string::npos) << all;
  EXPECT_NE(all.find("width scale: 0.015"), std::string::npos) << all;

  spec.text = std::nullopt;
  spec.path = std::string(SYLVA_SOURCE_DIR) + "/grammars/abop/fig2_06a_monopodial.lsys";
  PlantResult scaled = BuildPlant(spec);
  ASSERT_TRUE(scaled.plant);
  EXPECT_EQ(scaled.diagnostics.items.size(), 0u) << scaled.diagnostics.FormatAll();
}

}  // namespace
}  // namespace sylva::plant

namespace sylva::plant {
namespace {

// F --> FF at n=25 made 33 M segments and aborted at 3.3 GB in meshing.
TEST(Plant, MeshAndTurtleAreBoundedBeforeTheyAllocate) {
  PlantSpec spec;
  spec.path = "ff.lsys";
  spec.text = "axiom: F\nF --> FF\n";
  spec.steps = 25;
  PlantResult r = BuildPlant(spec);
  ASSERT_FALSE(r.plant);
  std::string all = r.diagnostics.FormatAll();
  EXPECT_NE(all.find("ff.lsys: error: the word draws 33554432 primitives"), std::string::npos)
      << all;
  EXPECT_EQ(r.diagnostics.items.back().kind, ErrorKind::kRuntime);

  spec.steps = 10;  // 1024 segments at 8 sides: 16,400 triangles
  spec.limits.maxTriangles = 10000;
  r = BuildPlant(spec);
  ASSERT_FALSE(r.plant);
  all = r.diagnostics.FormatAll();
  EXPECT_NE(all.find("the mesh would have 16400 triangles, more than the limit of 10000"),
            std::string::npos)
      << all;
  spec.limits.maxTriangles = 16400;
  r = BuildPlant(spec);
  ASSERT_TRUE(r.plant) << r.diagnostics.FormatAll();
  EXPECT_EQ(r.plant->mesh.triangleCount(), 16400u);
}

TEST(Plant, AnEmptyMeshIsAWarningNotSilence) {
  auto p = sylva::testing::PlantFromText("axiom: f\n", -1, Stage::kGeometry);
  ASSERT_TRUE(p);
  PlantSpec spec;
  spec.path = "empty.lsys";
  spec.text = "axiom: f\n";
  PlantResult r = BuildPlant(spec);
  ASSERT_TRUE(r.plant) << r.diagnostics.FormatAll();
  EXPECT_EQ(r.plant->mesh.triangleCount(), 0u);
  EXPECT_NE(r.diagnostics.FormatAll().find("warning: the plant draws nothing"), std::string::npos)
      << r.diagnostics.FormatAll();
}

}  // namespace
}  // namespace sylva::plant

namespace sylva::plant {
namespace {

// Colour index of each segment of a one-line grammar drawn from `path`.
std::vector<int> SegmentColors(const std::string& path, const std::string& text) {
  PlantSpec spec;
  spec.path = path;
  spec.text = text;
  spec.until = Stage::kGeometry;
  PlantResult r = BuildPlant(spec);
  std::vector<int> out;
  if (!r.plant) {
    ADD_FAILURE() << r.diagnostics.FormatAll();
    return out;
  }
  for (const auto& s : r.plant->geometry.segments) out.push_back(s.color);
  return out;
}

TEST(Plant, QuoteStepsTheColourInSylvaGrammarsAndIsNoCommandInCpfgFiles) {
  // cpfg's turtle (vlab interpret.c, InterpretSymbol) has no case for `'`:
  // in a cpfg file it is a module that draws nothing.
  EXPECT_EQ(SegmentColors("q.lsys", "axiom: F'F'(5)F\n"), (std::vector<int>{0, 1, 5}));
  EXPECT_EQ(SegmentColors("q.l", "axiom: F'F'(5)F;F\n"), (std::vector<int>{0, 0, 0, 1}));
}

}  // namespace
}  // namespace sylva::plant
