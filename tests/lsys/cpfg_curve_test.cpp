// cpfg's curve files and curveX/Y/Z, curveGAL (docs/cpfg.md): the curve at
// arc length t, and its length, as cpfg's curveXYZ.cpp measures them.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <string>

#include "lsys/cpfg_curve.h"
#include "lsys_test_util.h"

namespace sylva::lsys {
namespace {

// A straight line from (0, 0) to (3, 0), its end points tripled (the fourth
// column) as vlab's cuspy writes them (Ridley/profile.con's form).
const char* kLine =
    "version: 1.4\ncontact: 0 0 0\nend: 0 0 0\nheading: 0 1 0\nup: 0 0 -1\nsize: 1\n"
    "points: 4\nrange: 0.0 1.0\ndimension: 4\ntype: bspline\n"
    "0 0 0 3\n1 0 0 1\n2 0 0 1\n3 0 0 3\n";
// A quarter of the unit circle as one cubic Bezier piece (k = 0.5523).
const char* kQuarter =
    "points: 4\ndimension: 3\ntype: bezier\n1 0 0\n1 0.5523 0\n0.5523 1 0\n0 1 0\n";

ParseOptions Files() {
  ParseOptions opt;
  opt.readFile = [](const std::string& path) -> std::optional<std::string> {
    if (path == "line.con") return std::string(kLine);
    if (path == "quarter.con") return std::string(kQuarter);
    if (path == "short.con") return std::string("points: 4\n0 0\n1 0\n2 0\n");
    return std::nullopt;
  };
  opt.curveFiles = {{"line.con", "p.v", 7, 8}, {"quarter.con", "p.v", 8, 8}};
  return opt;
}

TEST(CpfgCurve, TakesThePointAtArcLengthNotAtTheParameter) {
  auto c = CpfgCurve::Parse(kLine, "line.con");
  ASSERT_TRUE(c) << c.error().Format();
  EXPECT_EQ(c->points(), 8u);  // multiplicities 3 + 1 + 1 + 3
  EXPECT_NEAR(c->Length(), 3.0, 1e-5) << c->Length();
  EXPECT_NEAR(c->AtLength(0).x(), 0.0, 1e-9) << c->AtLength(0).x();
  EXPECT_NEAR(c->AtLength(1).x(), 3.0, 1e-5) << c->AtLength(1).x();
  // A quarter of the length is x = 0.75; the B-spline's parameter 0.25 is
  // elsewhere: u = 4.25 on the knots, weights (0.0703, 0.6120, 0.3151,
  // 0.0026) of x = 0, 0, 1, 2, so x = 0.3203 (tripled ends slow it there).
  EXPECT_NEAR(c->AtLength(0.25).x(), 0.75, 1e-3) << c->AtLength(0.25).x();
  EXPECT_NEAR(c->AtParameter(0.25).x(), 0.3203, 1e-4) << c->AtParameter(0.25).x();
  // Outside 0..1: clamped, as in cpfg.
  EXPECT_EQ(c->AtLength(-2).x(), c->AtLength(0).x());
  EXPECT_EQ(c->AtLength(7).x(), c->AtLength(1).x());
}

TEST(CpfgCurve, BezierQuarterCircleHasLengthHalfPi) {
  auto c = CpfgCurve::Parse(kQuarter, "quarter.con");
  ASSERT_TRUE(c) << c.error().Format();
  EXPECT_NEAR(c->Length(), M_PI / 2, 5e-4) << c->Length();
  // A quarter of the arc: 22.5 degrees.
  const Vec3 q = c->AtLength(0.25);
  EXPECT_NEAR(q.x(), std::cos(M_PI / 8), 1e-3) << q.transpose();
  EXPECT_NEAR(q.y(), std::sin(M_PI / 8), 1e-3) << q.transpose();
  EXPECT_NEAR(q.z(), 0, 1e-12) << q.transpose();
}

TEST(CpfgCurve, ClosedAndEndpointSplinesFollowTheirTypes) {
  // bspline-endpoint interpolates its ends without tripled points.
  auto e = CpfgCurve::Parse("points: 4\ntype: bspline-endpoint\n0 0\n1 1\n2 1\n3 0\n", "e.con");
  ASSERT_TRUE(e) << e.error().Format();
  EXPECT_NEAR(e->AtParameter(0).x(), 0, 1e-9) << e->AtParameter(0).transpose();
  EXPECT_NEAR(e->AtParameter(1).x(), 3, 1e-5) << e->AtParameter(1).transpose();
  // bspline-closed: a loop, back where it started.
  auto c = CpfgCurve::Parse("points: 4\ntype: bspline-closed\n0 0\n1 0\n1 1\n0 1\n", "c.con");
  ASSERT_TRUE(c) << c.error().Format();
  const Vec3 a = c->AtParameter(0), b = c->AtParameter(1);
  EXPECT_NEAR((a - b).norm(), 0, 1e-5) << a.transpose() << " / " << b.transpose();
}

// A bspline-endpoint curve sums only the four basis functions of a span:
// 10^6 control points (10^5 lines, each 10 times) at 10^5 samples used to
// take 10^11 basis evaluations (hours); now 4 a sample.
TEST(CpfgCurve, LongEndpointCurveEvaluatesOnlyItsSpan) {
  std::string text = "points: 100000\ntype: bspline-endpoint\ndimension: 4\n";
  for (int i = 0; i < 100000; ++i) text += std::to_string(i) + " 0 0 10\n";
  auto c = CpfgCurve::Parse(text, "long.con", 100000);
  ASSERT_TRUE(c) << c.error().Format();
  EXPECT_EQ(c->points(), 1000000u);
  EXPECT_NEAR(c->Length(), 99999, 1e-3) << c->Length();
  EXPECT_NEAR(c->AtLength(0.5).x(), 49999.5, 1.0) << c->AtLength(0.5).transpose();
  EXPECT_NEAR(c->AtParameter(1).x(), 99999, 1e-3) << c->AtParameter(1).transpose();
}

// Coordinates beyond the turtle's +-1e15 are an error at their line: the
// fuzzer found points at +-1e308 accepted with an infinite length.
TEST(CpfgCurve, CoordinatesBeyondTheTurtlesRangeAreErrors) {
  auto c = CpfgCurve::Parse("points: 4\n-1e308 0\n1e308 0\n-1e308 1\n1e308 1\n", "h.con");
  ASSERT_FALSE(c) << c->Length();
  EXPECT_EQ(c.error().loc.line, 2) << c.error().Format();
  EXPECT_EQ(c.error().message, "'-1e308' is beyond +-1e15") << c.error().Format();
  auto ok = CpfgCurve::Parse("points: 4\n-1e15 0\n1e15 0\n-1e15 1\n1e15 1\n", "k.con");
  ASSERT_TRUE(ok) << ok.error().Format();
  EXPECT_TRUE(std::isfinite(ok->Length())) << ok->Length();
}

TEST(CpfgCurve, ViewFileCurvesServeCurveXYAndGal) {
  const std::string g =
      "Start: {L = curveGAL(1);}\naxiom: A(L, curveX(1, 0.25), curveY(2, 0.5))\n"
      "A(l, x, y) --> B(curveX(1, x / l / 2), curveGAL(2))\n";
  ParseResult r = ParseGrammarText(g, "c.l", Files());
  ASSERT_TRUE(r.grammar) << r.diagnostics.FormatAll();
  DeriveOptions opt;
  opt.steps = 0;
  auto w = Derive(*r.grammar, opt);
  ASSERT_TRUE(w) << w.error().Format();
  ASSERT_EQ(w->word.params.size(), 3u);
  EXPECT_NEAR(w->word.params[0], 3.0, 1e-5) << w->word.params[0];
  EXPECT_NEAR(w->word.params[1], 0.75, 1e-3) << w->word.params[1];
  EXPECT_NEAR(w->word.params[2], std::sin(M_PI / 4), 1e-3) << w->word.params[2];
  opt.steps = 1;
  w = Derive(*r.grammar, opt);
  ASSERT_TRUE(w) << w.error().Format();
  ASSERT_EQ(w->word.params.size(), 2u);
  EXPECT_NEAR(w->word.params[0], 0.375, 1e-3) << w->word.params[0];  // an eighth of 3
  EXPECT_NEAR(w->word.params[1], M_PI / 2, 5e-4) << w->word.params[1];
}

TEST(CpfgCurve, StatementBlocksReadCurvesAsRidleysSpiralDoes) {
  // vlab's Ridley/spiral.l walks the curve in a while loop of a block.
  const std::string g =
      "Start: {L = curveGAL(1);}\naxiom: A(0)\n"
      "A(s) : s < L {x = 0; while (s < 0.75 * L) {s = s + 0.5; x = curveX(1, s / L);}} "
      "--> B(s, x)\n";
  ParseResult r = ParseGrammarText(g, "c.l", Files());
  ASSERT_TRUE(r.grammar) << r.diagnostics.FormatAll();
  DeriveOptions opt;
  opt.steps = 1;
  auto w = Derive(*r.grammar, opt);
  ASSERT_TRUE(w) << w.error().Format();
  ASSERT_EQ(w->word.params.size(), 2u);
  EXPECT_DOUBLE_EQ(w->word.params[0], 2.5);
  EXPECT_NEAR(w->word.params[1], 2.5, 1e-3) << w->word.params[1];  // x at length 2.5 of 3
}

TEST(CpfgCurve, ErrorsAreLocated) {
  auto first = [](const std::string& g, const ParseOptions& opt) {
    ParseResult r = ParseGrammarText(g, "c.l", opt);
    EXPECT_FALSE(r.grammar) << g;
    if (r.diagnostics.items.empty()) return std::string("<none>");
    const Diagnostic& d = r.diagnostics.items[0];
    return d.loc.file + ":" + std::to_string(d.loc.line) + ":" + std::to_string(d.loc.column) +
           " " + d.message;
  };
  EXPECT_EQ(first("axiom: A(curveX(3, 0.5))\n", Files()),
            "c.l:1:10 curveX: id must be a whole number from 1 to 2 (the view file's 'curve:' "
            "lines)");
  EXPECT_EQ(first("axiom: A(curveY(1))\n", Files()),
            "c.l:1:18 curveY takes 2 arguments: curveY(id, t)");
  ParseOptions missing = Files();
  missing.curveFiles.push_back({"gone.con", "p.v", 9, 8});
  const std::string m = first("axiom: A(curveX(1, 0.5))\n", missing);
  EXPECT_EQ(m.rfind("p.v:9:8 cannot read curve file 'gone.con'", 0), 0u) << m;
  ParseOptions bad = Files();
  bad.curveFiles = {{"short.con", "p.v", 3, 8}};
  EXPECT_EQ(first("axiom: A\n", bad),
            "p.v:3:8 in curve file short.con:1: 'points: 4' but the file gives 3");
  // A multiplicity of 1.5 was read as 1 without a word.
  auto half = CpfgCurve::Parse(
      "points: 4\ndimension: 4\ntype: bspline\n0 0 0 1\n1 0 0 1.5\n2 0 0 1\n3 0 0 1\n", "h.con");
  ASSERT_FALSE(half);
  EXPECT_EQ(half.error().loc.line, 5) << half.error().Format();
  EXPECT_EQ(half.error().message, "a point's multiplicity must be a whole number from 1 to 100");
  auto surface = CpfgCurve::Parse("points: 16\ntype: bezier-surface\n", "s.con");
  ASSERT_FALSE(surface);
  EXPECT_EQ(surface.error().loc.line, 2) << surface.error().Format();
}

}  // namespace
}  // namespace sylva::lsys
