// cpfg files of the second corpus (issue 18): turtle symbols cpfg
// interprets that Sylva warns about, random #defines, `#(` at a line start,
// depth limits, continued contexts.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "lsys/parser.h"
#include "lsys_test_util.h"

namespace sylva::lsys {
namespace {

using testing::DiagnosticLines;
using testing::Joined;

// "line:col message" of every diagnostic.
std::vector<std::string> Diagnostics(const std::string& text) {
  return DiagnosticLines(ParseGrammarText(text, "c.l"));
}

TEST(CpfgSymbols, UnderscoreIsReadSilentlyAndWarnsOnlyForExtraParameters) {
  EXPECT_TRUE(Diagnostics("axiom: _ F _ F\n").empty()) << Joined(Diagnostics("axiom: _ F _ F\n"));
  EXPECT_TRUE(Diagnostics("axiom: _(0.3) F _(1)\n").empty())
      << Joined(Diagnostics("axiom: _(0.3) F _(1)\n"));
  auto w = Diagnostics("axiom: F _(1,2)\n");
  ASSERT_EQ(w.size(), 1u) << Joined(w);
  EXPECT_EQ(w[0].rfind("1:10 '_' (cpfg: set the tropism elasticity) uses 1 parameter", 0), 0u)
      << w[0];
}

TEST(CpfgSymbols, BracesWithAParameterAreSplinesAndWarnOnlyForExtraParameters) {
  // cpfg's `{(type, rings)` ... `}(type)` spline is drawn by the turtle.
  for (const char* text : {"axiom: F {(1) F . F }(1) {(0) F }(0)\n", "axiom: {(3,8) F }(3)\n"}) {
    auto none = Diagnostics(text);
    EXPECT_TRUE(none.empty()) << text << Joined(none);
  }
  auto w = Diagnostics("axiom: F {(1,4,2) F }(1,2)\n");
  ASSERT_EQ(w.size(), 2u) << Joined(w);
  EXPECT_EQ(w[0].rfind("1:10 '{' (a polygon, or with a type other than 0 a spline) uses 2", 0), 0u)
      << w[0];
  EXPECT_EQ(w[1].rfind("1:21 '}' (the end of a polygon", 0), 0u) << w[1];
}

TEST(CpfgSymbols, SetHeadingWarnsOnlyForArgumentCountsCpfgDoesNotRead) {
  for (const char* text :
       {"axiom: @R(0,0,1) F\n", "axiom: @R(1,0) F\n", "axiom: @R(1,0,0,0,1,0) F\n"}) {
    auto none = Diagnostics(text);
    EXPECT_TRUE(none.empty()) << text << Joined(none);
  }
  auto one = Diagnostics("axiom: F @R(1)\n");
  ASSERT_EQ(one.size(), 1u) << Joined(one);
  EXPECT_NE(one[0].find("needs 2 parameters (x, y), 3 (x, y, z) or 6"), std::string::npos)
      << one[0];
  EXPECT_NE(one[0].find("it does nothing"), std::string::npos) << one[0];
  auto five = Diagnostics("axiom: F @R(1,0,0,0,1)\n");
  ASSERT_EQ(five.size(), 1u) << Joined(five);
  EXPECT_NE(five[0].find("the last 2 are ignored"), std::string::npos) << five[0];
}

TEST(CpfgDefines, RandomValueIsSubstitutedAsTextAndDrawnAnewAtEachUse) {
  // LeafRandom/leaf.l: `#define ANGLE nran(80,4)`. cpfg's preprocessor pastes
  // the text, so every use draws its own number.
  std::string axiom;
  for (int i = 0; i < 200; ++i) axiom += "A";
  Grammar g = testing::MustParse("#define ANGLE nran(80,4)\n#define R ran(1)\naxiom: " + axiom +
                                 "\nA --> B(ANGLE) C(R)\n");
  ASSERT_EQ(g.main.bySymbol.size(), g.symbols.size());
  DeriveOptions opt;
  opt.steps = 1;
  DeriveResult r = testing::MustDerive(g, opt);
  ASSERT_EQ(r.word.size(), 400u);
  double sum = 0, sum2 = 0, lo = 1e9, hi = -1e9, cmin = 1e9, cmax = -1e9;
  for (size_t i = 0; i < r.word.size(); i += 2) {
    const double a = r.word.ParamsOf(i)[0], c = r.word.ParamsOf(i + 1)[0];
    sum += a;
    sum2 += a * a;
    lo = std::min(lo, a);
    hi = std::max(hi, a);
    cmin = std::min(cmin, c);
    cmax = std::max(cmax, c);
  }
  const double mean = sum / 200, sd = std::sqrt(sum2 / 200 - mean * mean);
  EXPECT_NEAR(mean, 80, 1.5) << "sd " << sd;
  EXPECT_NEAR(sd, 4, 1.2) << "mean " << mean;
  EXPECT_LT(lo, hi);
  EXPECT_GE(cmin, 0);
  EXPECT_LE(cmax, 1);
  EXPECT_GT(cmax - cmin, 0.5) << cmin << " " << cmax;
  // A constant #define stays a constant.
  Grammar k = testing::MustParse("#define N 2*3\naxiom: F(N)\n");
  EXPECT_EQ(k.constants.count("N"), 1u);
}

TEST(CpfgPreprocessor, ContinuedLineBeginningWithTheWidthModuleIsNoDirective) {
  // ArticulatedLamp/lamp.l: a successor continued on a line that begins
  // with `#(0.06)`. cpfg's preprocessor takes `#` as a directive only before
  // a name, a number or the end of the line.
  EXPECT_EQ(testing::DeriveText("axiom: A\nA --> F(1)\n\t#(0.06)\tf(0.1) &(90)\n\t#(2) F\n", 1),
            "F(1)#(0.06)f(0.1)&(90)#(2)F");
  EXPECT_EQ(testing::FirstError("axiom: A\n  #pragma x\n"), "2:3 unknown directive '#pragma'");
}

TEST(CpfgDepth, DecompositionRunsPastAThousandLevels) {
  // Ridley/spiral.l and LilyLeaf ask for `maximum depth: 3000`; each level is
  // one pass over the word, so the depth costs time, not stack.
  const std::string w = testing::DeriveText(
      "axiom: A(0)\nderivation length: 1\ndecomposition\nmaximum depth: 3000\n"
      "A(n) : n < 2500 --> B A(n+1)\n",
      1);
  EXPECT_EQ(std::count(w.begin(), w.end(), 'B'), 2500) << w.substr(0, 80);
  EXPECT_NE(w.find("A(2500)"), std::string::npos) << w.substr(w.size() - 40);
  EXPECT_EQ(testing::FirstError("axiom: A\ndecomposition\nmaximum depth: 100001\n"),
            "3:16 maximum depth must be a whole number from 1 to 100000");
}

TEST(CpfgLines, ContextContinuedOnTheNextLine) {
  // ShootRoot/tree.l: `N > [I(...)=]` / `\t[I(...)=] : ` / `\tcondition` /
  // `\t{...} -->` / `\t\tN`.
  EXPECT_EQ(testing::DeriveText("axiom: N [A(1)] [B(2)]\nN > [A(a)]\n\t[B(b)] :\n\ta < b\n"
                                "\t{c = a + b;} -->\n\t\tM(c)\n",
                                1),
            "M(3)[A(1)][B(2)]");
  // An indented production after a line without an arrow stays its own.
  const std::string e = testing::FirstError("axiom: A\nA B\n\tC --> D\n");
  EXPECT_EQ(e.rfind("2:1 expected a production", 0), 0u) << e;
}

TEST(CpfgUnsupported, RingInASubLsystemAndCurvesWithoutFilesSayWhatTheyAreWhereTheyAre) {
  const std::string ring = testing::FirstError(
      "Lsystem: 0\naxiom: A\nendlsystem\nLsystem: 1\nring lsystem\naxiom: B\nendlsystem\n");
  EXPECT_EQ(ring.rfind("5:1 'ring lsystem' in a sub-L-system is not supported by Sylva", 0), 0u)
      << ring;
  const std::string curve = testing::FirstError("Start: {L=curveGAL(1);}\naxiom: A\n");
  EXPECT_EQ(curve.rfind("1:11 curveGAL needs cpfg curve files: name them with 'curve: FILE.con' "
                        "lines in the view file; no view file was read",
                        0),
            0u)
      << curve;
}

TEST(CpfgLines, StatementBlockOpenedBeforeCommentLines) {
  // Ridley/spiral.l: `A(s,a) : s<L {` then comment-only lines, then the
  // statements, the block's `}` and the arrow lines below.
  EXPECT_EQ(testing::DeriveText("axiom: A(1)\nA(s) : s<3 {   // go on\n\t\t// comment\n\n"
                                "\tt = s + 1;\n\t} --> B(t)\n",
                                1),
            "B(2)");
}

TEST(CpfgSymbols, PositionModuleSWarnsInAGrammarWithQueries) {
  // cpfg's environment pass fills s(x, y[, z]) with the turtle's position.
  auto w = Diagnostics("axiom: F s(0,0) ?P(0,0)\n");
  ASSERT_EQ(w.size(), 1u) << Joined(w);
  EXPECT_EQ(w[0].rfind("1:10 module 's' with 2 or 3 parameters: in a grammar with '?' modules", 0),
            0u)
      << w[0];
  EXPECT_TRUE(Diagnostics("axiom: F s(0,0)\n").empty());
}

}  // namespace
}  // namespace sylva::lsys
