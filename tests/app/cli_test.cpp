#include <gtest/gtest.h>

#include <filesystem>

#include "cli_test_util.h"
#include "core/atomic_file.h"
#include "core/status.h"

namespace sylva::app {
namespace {

using testing::RunSylva;
using testing::Scratch;
using testing::Source;
using testing::WriteFile;

TEST(Cli, DerivePrintsTheCanonicalWord) {
  auto r = RunSylva({"derive", Source("grammars/abop/fig2_06a_monopodial.lsys"), "-n", "1"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out, "!(10)F(1)[&(45)B(0.6,7.07)]/(137.5)A(0.9,7.07)\n");
  EXPECT_EQ(r.err, "");
}

TEST(Cli, DefinesSeedsAndSteps) {
  std::string f =
      WriteFile("d.lsys", "#define x 1\nseed: 3\naxiom: A(x)\nA(a) --> A(a+ran(1)*0+1)\n");
  auto r = RunSylva({"derive", f, "-D", "x=5", "-n", "2", "--seed", "9", "--threads", "1"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out, "A(7)\n");
}

TEST(Cli, StatsReportCountsPerStepAndSymbol) {
  auto r = RunSylva({"derive", Source("grammars/abop/fig1_06_koch_island.lsys"), "--stats"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("modules: 3803\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("   3          3803"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("  F                     2048\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("million modules/s"), std::string::npos) << r.out;
}

TEST(Cli, InterpretAppliesInterpretationRules) {
  auto r = RunSylva(
      {"derive", Source("grammars/abop/fig1_10a_dragon_curve.lsys"), "-n", "1", "--interpret"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out, "F+F+\n");
}

TEST(Cli, OutputFileIsWrittenWhole) {
  std::string out = (Scratch() / "word.txt").string();
  auto r = RunSylva(
      {"derive", Source("grammars/abop/fig1_24a_bracketed_plant.lsys"), "-n", "1", "-o", out});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(*ReadFile(out), "F[+F]F[-F]F\n");
}

TEST(Cli, UnwritableOutputIsExitOneAndLeavesNothing) {
  auto r = RunSylva({"derive", Source("grammars/abop/fig1_24a_bracketed_plant.lsys"), "-o",
                     "/nonexistent-dir/word.txt"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("/nonexistent-dir/word.txt: error: cannot create output file"),
            std::string::npos)
      << r.err;
}

TEST(Cli, FailedDerivationKeepsThePreviousOutputFile) {
  std::string out = (Scratch() / "keep.txt").string();
  ASSERT_EQ(RunSylva({"derive", Source("grammars/abop/fig1_24a_bracketed_plant.lsys"), "-n", "0",
                      "-o", out})
                .code,
            0);
  auto r = RunSylva({"derive", Source("grammars/abop/fig1_06_koch_island.lsys"), "--max-modules",
                     "100", "-o", out});
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(*ReadFile(out), "F\n");
}

TEST(Cli, LimitReachedIsExitOne) {
  auto r = RunSylva(
      {"derive", Source("grammars/abop/fig1_06_koch_island.lsys"), "--max-modules", "1000"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("derivation step 3 would make the word 3803 modules long"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.out, "");
}

TEST(Cli, CheckPrintsWarningsAndSucceeds) {
  std::string f = WriteFile("warn.lsys", "#define unused 3\naxiom: A\nA --> B\n");
  auto r = RunSylva({"check", f});
  EXPECT_EQ(r.code, 0);
  EXPECT_EQ(r.out, "");
  EXPECT_NE(r.err.find("warn.lsys:1:9: warning: constant 'unused' is never used"),
            std::string::npos)
      << r.err;
}

TEST(Cli, CheckOnEveryCatalogueGrammarIsSilent) {
  for (auto& e : std::filesystem::directory_iterator(Source("grammars/abop"))) {
    auto r = RunSylva({"check", e.path().string()});
    EXPECT_EQ(r.code, 0) << e.path();
    EXPECT_EQ(r.err, "") << e.path();
  }
}

TEST(Cli, BadUsageIsExitTwo) {
  EXPECT_EQ(RunSylva({}).code, 2);
  EXPECT_EQ(RunSylva({"frobnicate"}).code, 2);
  EXPECT_EQ(RunSylva({"derive"}).code, 2);
  EXPECT_EQ(RunSylva({"derive", Source("grammars/abop/fig1_25_bush.lsys"), "-n", "-3"}).code, 2);
  EXPECT_EQ(RunSylva({"derive", Source("grammars/abop/fig1_25_bush.lsys"), "--threads", "x"}).code,
            2);
  auto d = RunSylva({"derive", Source("grammars/abop/fig1_25_bush.lsys"), "-D", "novalue"});
  EXPECT_EQ(d.code, 2);
  EXPECT_NE(d.err.find("-D expects NAME=VALUE"), std::string::npos) << d.err;
  auto m = RunSylva({"derive", "/no/such/grammar.lsys"});
  EXPECT_EQ(m.code, 2);
  EXPECT_NE(m.err.find("/no/such/grammar.lsys: error: cannot read file"), std::string::npos)
      << m.err;
}

TEST(Cli, HelpIsExitZero) {
  auto r = RunSylva({"--help"});
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("derive"), std::string::npos);
}

TEST(Cli, ACommandsHelpIsPrintedOnce) {
  for (const char* command : {"view", "render", "derive"}) {
    auto r = RunSylva({command, "--help"});
    EXPECT_EQ(r.code, 0) << command;
    size_t count = 0;
    for (size_t at = r.out.find("Usage:"); at != std::string::npos;
         at = r.out.find("Usage:", at + 1))
      ++count;
    EXPECT_EQ(count, 1u) << command << " --help printed its usage " << count << " times:\n"
                         << r.out;
  }
}

}  // namespace
}  // namespace sylva::app

namespace sylva::app {
namespace {

TEST(CliMesh, WritesTheMeshAndASummary) {
  std::string out = (Scratch() / "tree.ply").string();
  auto r = RunSylva({"mesh", Source("grammars/abop/fig2_06a_monopodial.lsys"), "-n", "3", "--sides",
                     "4", "-o", out});
  EXPECT_EQ(r.code, 0) << r.err;
  auto text = ReadFile(out);
  ASSERT_TRUE(text.ok());
  EXPECT_EQ(text->rfind("ply\nformat binary_little_endian 1.0\n", 0), 0u);
  EXPECT_NE(r.err.find(" vertices, "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("time: derive"), std::string::npos) << r.err;
}

TEST(CliMesh, UnknownExtensionIsExitTwo) {
  auto r = RunSylva(
      {"mesh", Source("grammars/abop/fig1_25_bush.lsys"), "-o", (Scratch() / "x.stl").string()});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("unknown mesh format"), std::string::npos) << r.err;
}

TEST(CliMesh, UnwritableOutputIsExitOneWithNoPartialFile) {
  auto r = RunSylva(
      {"mesh", Source("grammars/abop/fig1_25_bush.lsys"), "-o", "/nonexistent-dir/bush.glb"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("/nonexistent-dir/bush.glb: error: cannot create output file"),
            std::string::npos)
      << r.err;
}

TEST(CliMesh, UnknownSurfaceIsAWarningAtTheTildeAndAnErrorWithStrict) {
  // cpfg draws nothing for a surface its view file does not name (vlab's
  // insect-realistic: `~b`); Sylva draws the rest and says where.
  std::string f = WriteFile("surf.lsys", "axiom: F\nF --> F[+~lef(2)]F\n");
  std::string out = (Scratch() / "surf.obj").string();
  auto r = RunSylva({"mesh", f, "-n", "1", "-o", out});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err.rfind(f + ":2:10: warning: unknown surface 'lef' is not drawn (as in cpfg)", 0),
            0u)
      << r.err;
  EXPECT_TRUE(std::filesystem::exists(out));
  std::filesystem::remove(out);
  auto strict = RunSylva({"mesh", "--strict", f, "-n", "1", "-o", out});
  EXPECT_EQ(strict.code, 2) << strict.err;
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(Cli, ArrayIndexOutOfBoundsIsAWarningAfterTheDerivationAndAnErrorWithStrict) {
  // vlab's CelticKnot reads turn0[7] of a 7-element array: cpfg uses the
  // last element; so does Sylva, with a warning at the index (once per array).
  std::string f = WriteFile("knot.l",
                            "define: { array t[2] = {5, 6}; }\naxiom: A(0)\n"
                            "A(i) --> B(t[i]) A(i+1)\n");
  auto plain = RunSylva({"derive", f, "-n", "3"});
  EXPECT_EQ(plain.code, 0) << plain.err;
  EXPECT_NE(plain.out.find("B(5)B(6)B(6)A(3)"), std::string::npos) << plain.out;
  EXPECT_NE(plain.err.find("knot.l:3:12: warning: index 2 of array 't' is outside 0 to 1: Sylva "
                           "uses element 1 instead, as cpfg does"),
            std::string::npos)
      << plain.err;
  auto strict = RunSylva({"derive", "--strict", f, "-n", "3"});
  EXPECT_EQ(strict.code, 2) << strict.err;
  EXPECT_EQ(strict.out, "");
}

TEST(Cli, StrictMakesWarningsErrorsOnEveryCommand) {
  std::string f = WriteFile("gc.l", "axiom: A\nA --> F@D F@PS A\n");
  auto plain = RunSylva({"check", f});
  EXPECT_EQ(plain.code, 0) << plain.err;
  EXPECT_NE(plain.err.find("gc.l:2:8: warning: '@D' (cpfg: scale factor) is "
                           "not implemented in Sylva: it does nothing"),
            std::string::npos)
      << plain.err;
  auto strict = RunSylva({"check", "--strict", f});
  EXPECT_EQ(strict.code, 2) << strict.err;
  EXPECT_NE(strict.err.find("sylva: error: --strict: 2 warnings are treated as errors"),
            std::string::npos)
      << strict.err;
  auto derive = RunSylva({"derive", "--strict", f, "-n", "1"});
  EXPECT_EQ(derive.code, 2) << derive.err;
  EXPECT_EQ(derive.out, "");
  std::string out = (Scratch() / "gc.obj").string();
  auto mesh = RunSylva({"mesh", "--strict", f, "-n", "1", "-o", out});
  EXPECT_EQ(mesh.code, 2) << mesh.err;
  EXPECT_FALSE(std::filesystem::exists(out));
  auto meshPlain = RunSylva({"mesh", f, "-n", "1", "-o", out});
  EXPECT_EQ(meshPlain.code, 0) << meshPlain.err;
#ifdef SYLVA_TESTS_WITH_GRAPHICS
  std::string png = (Scratch() / "gc.png").string();
  auto render = RunSylva({"render", "--strict", f, "-n", "1", "-o", png, "--size", "64x64"});
  EXPECT_EQ(render.code, 2) << render.err;
  EXPECT_FALSE(std::filesystem::exists(png));
#endif
}

TEST(Cli, StrictIsQuietOnACleanGrammar) {
  auto r = RunSylva({"check", "--strict", Source("grammars/abop/fig1_24a_bracketed_plant.lsys")});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
}

TEST(CliMesh, CpfgOneLetterSurfaceBesideTheGrammar) {
  // ~lF with l.obj beside the grammar: cpfg's surface l, then F.
  WriteFile("l.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  std::string f = WriteFile("onel.l", "axiom: ~lF\n");
  std::string out = (Scratch() / "onel.obj").string();
  auto r = RunSylva({"mesh", "--strict", f, "-o", out});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("1 segments"), std::string::npos) << r.err;
}

TEST(CliMesh, SummaryCountsContourTubesAndTheirTriangles) {
  // A cpfg generalized cylinder with a contour (ctube.v beside the file:
  // cylinder line style): one contour tube of 2 + 1 rings of 8 sides + 1
  // points (an open contour), whose 2 x 8 quads are the mesh's only
  // triangles; no segment.
  WriteFile("ctube.con", "5 3 open\n-1 0 0\n-1 0 0\n0 0.2 0\n1 0 0\n1 0 0\n");
  WriteFile("ctube.v", "line style: cylinder\ncontour: 1 ctube.con\n");
  std::string f = WriteFile("ctube.l", "axiom: #(2) @#(1) @Gs f(2) @Ge(2)\n");
  std::string out = (Scratch() / "ctube.obj").string();
  auto r = RunSylva({"mesh", "--strict", f, "-o", out});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find(" 32 triangles, 0 segments, 0 polygons, 0 spheres, 0 surfaces, 1 contour "
                       "tubes (5 modules)"),
            std::string::npos)
      << r.err;
}

TEST(CliMesh, UnknownLongSurfaceNameMentionsCpfgOneLetterNames) {
  std::string f = WriteFile("lq.l", "axiom: ~qF\n");
  std::string out = (Scratch() / "lq.obj").string();
  auto r = RunSylva({"mesh", "--strict", f, "-o", out});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("with q.obj there, '~qF' is read as '~q' followed by 'F'"),
            std::string::npos)
      << r.err;
}

TEST(Cli, StrictAppliesToTheGrammarsOfAScene) {
  std::string g = WriteFile("scene_gc.l", "axiom: F@PS\n");
  std::string f = WriteFile("strict_scene.xml",
                            "<scene version=\"1\">\n  <plant id=\"p\" grammar=\"scene_gc.l\" "
                            "position=\"0 0 0\"/>\n</scene>\n");
  auto plain = RunSylva({"check", f});
  EXPECT_EQ(plain.code, 0) << plain.err;
  EXPECT_NE(plain.err.find("scene_gc.l:1:9: warning: '@PS'"), std::string::npos) << plain.err;
  auto strict = RunSylva({"check", "--strict", f});
  EXPECT_EQ(strict.code, 2) << strict.err;
  // One warning; the note that names the <plant> is not counted.
  EXPECT_NE(strict.err.find("sylva: error: --strict: 1 warning is treated as an error"),
            std::string::npos)
      << strict.err;
}

}  // namespace
}  // namespace sylva::app
