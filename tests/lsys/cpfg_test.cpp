// Reading cpfg files (docs/cpfg.md): what Sylva does not implement is said,
// with its location, once per symbol; the rest reads as cpfg reads it.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "lsys/parser.h"
#include "lsys_test_util.h"

namespace sylva::lsys {
namespace {

using testing::DeriveText;
using testing::Joined;
using testing::MustParse;

// "line:col message" of every diagnostic (all must be warnings).
std::vector<std::string> Warnings(const std::string& text, const ParseOptions& opt = {}) {
  ParseResult r = ParseGrammarText(text, "c.l", opt);
  EXPECT_TRUE(r.grammar) << r.diagnostics.FormatAll();
  std::vector<std::string> out;
  for (const auto& d : r.diagnostics.items) {
    EXPECT_EQ(d.severity, Severity::kWarning) << d.Format();
    out.push_back(std::to_string(d.loc.line) + ":" + std::to_string(d.loc.column) + " " +
                  d.message);
  }
  return out;
}

TEST(Cpfg, UnimplementedCommandsWarnOncePerSymbolAtTheirFirstUse) {
  auto w = Warnings(
      "axiom: A\n"
      "A --> F@Gr(1,2,3) F@Gt(2,3,4)@Gt(5,6,7)@PS(1) A\n"
      "F --> @Gs F @Tf @Ts(1,2) @o(1) @c(1) @v @M(1,2) @O(2) @Ge\n");
  const std::string all = Joined(w);
  ASSERT_EQ(w.size(), 4u) << all;
  EXPECT_EQ(w[0].rfind("2:8 '@Gr' (generalized cylinder radius tangents) with 3 parameters: the "
                       "third is ignored",
                       0),
            0u)
      << all;
  // @Gt(2,3,4) has one parameter too many (said once).
  EXPECT_EQ(w[1].rfind("2:20 '@Gt' (generalized cylinder tangents) uses the arriving and leaving "
                       "factors; the other 1 are ignored",
                       0),
            0u)
      << all;
  EXPECT_EQ(w[2].rfind("2:40 '@PS'", 0), 0u) << all;
  EXPECT_EQ(w[3].rfind("3:41 '@M' (move to) needs 3 parameters", 0), 0u) << all;
}

TEST(Cpfg, TextureAndBackColourCommandsWarnAndContourCommandsLexAsOneModule) {
  // vlab's lily and thatcheria: @#(contour) @!(sides) @;(back colour) @Tx(texture).
  // @# and @! are drawn (turtle/interpreter.h); @#(2,3) has one parameter too many.
  auto w = Warnings("axiom: @#(2)F @!(5) @;(7)F @Tx(1)F @#(3) @#(2,3)\n");
  const std::string all = Joined(w);
  // @# with 1 and with 2 parameters: no production names @#, so the count
  // cannot change what matches (Parser.MixedArityWarnsOnlyWhereAProductionNamesTheModule).
  ASSERT_EQ(w.size(), 3u) << all;
  EXPECT_EQ(w[0].rfind("1:21 '@;' (cpfg: back-side colour)", 0), 0u) << all;
  EXPECT_EQ(w[1].rfind("1:28 '@Tx' (cpfg: texture)", 0), 0u) << all;
  EXPECT_EQ(w[2].rfind("1:42 '@#' (generalized cylinder contour) uses the contour's id; the "
                       "other 1 are ignored",
                       0),
            0u)
      << all;
  // One module each: no stray 'x' or '#' module in the word.
  EXPECT_EQ(DeriveText("axiom: @Tx(1)F@#(2)@;(3)\n", 0), "@Tx(1)F@#(2)@;(3)");
}

TEST(Cpfg, ImplementedCommandsWarnAboutParametersTheyDoNotUse) {
  auto w = Warnings("axiom: @o(1,2) @c(1) @Gs(3) @Gc(2) @Ge(1,1) @Ts(1,2,3) @Ti(1) @Td @v\n");
  const std::string all = Joined(w);
  ASSERT_EQ(w.size(), 4u) << all;
  EXPECT_EQ(w[0].rfind("1:8 '@o' (disc) uses the diameter; the other 1 are ignored", 0), 0u) << all;
  EXPECT_EQ(w[1].rfind("1:22 '@Gs' (start of a generalized cylinder) uses no parameters", 0), 0u)
      << all;
  EXPECT_EQ(w[2].rfind("1:36 '@Ge'", 0), 0u) << all;
  EXPECT_EQ(w[3].rfind("1:45 '@Ts'", 0), 0u) << all;
}

TEST(Cpfg, BracketsInConsiderAreAcceptedAndKeepTheBranching) {
  // B and the branch [C] are skipped: A sees A as its left context.
  EXPECT_EQ(DeriveText("consider: [ ] A\naxiom: A B [C] A\nA < A --> D\n", 1), "AB[C]D");
  // Without the consider: list B stands between them.
  EXPECT_EQ(DeriveText("axiom: A B [C] A\nA < A --> D\n", 1), "AB[C]A");
}

TEST(Cpfg, QueryModulesWarnOnlyWhereTheyAreNotAnswered) {
  // ?P ?H ?L ?U with 2 or 3 parameters are answered (plant/queries.h).
  auto none = Warnings("axiom: A ?P(0,0,0)\nA --> F ?H(0,0) ?L(0,0,0) ?U(1,1) ?P(1,1,1)\n");
  EXPECT_TRUE(none.empty()) << Joined(none);
  auto w = Warnings("axiom: A ?P(0)\nA --> F ?H(0,0,0,0) ?E(1) ?X(1)\n");
  ASSERT_EQ(w.size(), 4u) << Joined(w);
  EXPECT_EQ(w[0].rfind("1:10 query module '?P' takes 2 parameters (x, y) or 3", 0), 0u) << w[0];
  EXPECT_EQ(w[1].rfind("2:9 query module '?H' takes 2 parameters", 0), 0u) << w[1];
  EXPECT_EQ(w[2].rfind("2:27 query module '?X' is not answered", 0), 0u) << w[2];
  // ?E without an `environment:` statement, at its first use.
  EXPECT_EQ(
      w[3].rfind("2:21 query module '?E' is not answered: the grammar has no 'environment:'", 0),
      0u)
      << w[3];
}

TEST(Cpfg, EnvironmentStatementIsReadAsKindAndItems) {
  auto r = lsys::ParseGrammarText(
      "#define h 2\nenvironment: light cell=0.25 depth=h+1 box(0,0,0, 1,h,3)\naxiom: A ?E(1)\n",
      "env.lsys");
  ASSERT_TRUE(r.grammar) << r.diagnostics.FormatAll();
  ASSERT_TRUE(r.grammar->environment.has_value());
  const auto& e = *r.grammar->environment;
  EXPECT_EQ(e.kind, "light");
  EXPECT_EQ(e.loc.line, 2);
  EXPECT_EQ(e.loc.column, 14);
  ASSERT_EQ(e.items.size(), 3u);
  EXPECT_TRUE(e.items[0].keyValue);
  EXPECT_EQ(e.items[0].name, "cell");
  EXPECT_EQ(e.items[0].values, std::vector<double>{0.25});
  EXPECT_EQ(e.items[1].values, std::vector<double>{3});
  EXPECT_TRUE(e.items[2].call);
  EXPECT_EQ(e.items[2].name, "box");
  EXPECT_EQ(e.items[2].values, (std::vector<double>{0, 0, 0, 1, 2, 3}));
  EXPECT_EQ(e.items[2].loc.column, 40);
}

TEST(Cpfg, EnvironmentStatementErrorsHaveAPosition) {
  auto two = lsys::ParseGrammarText(
      "environment: shape sphere(0,0,0,1)\nenvironment: light\naxiom: A\n", "e.lsys");
  ASSERT_FALSE(two.grammar);
  EXPECT_NE(two.diagnostics.FormatAll().find("e.lsys:2:1: error: a second 'environment:'"),
            std::string::npos)
      << two.diagnostics.FormatAll();
  auto bad = lsys::ParseGrammarText("environment: shape box(0,0,0 1)\naxiom: A\n", "e.lsys");
  ASSERT_FALSE(bad.grammar);
  EXPECT_NE(bad.diagnostics.FormatAll().find("e.lsys:1:30: error: expected ',' or ')'"),
            std::string::npos)
      << bad.diagnostics.FormatAll();
  auto random = lsys::ParseGrammarText("environment: light cell=ran(1)\naxiom: A\n", "e.lsys");
  ASSERT_FALSE(random.grammar);
  EXPECT_NE(random.diagnostics.FormatAll().find("constant expression"), std::string::npos)
      << random.diagnostics.FormatAll();
}

TEST(Cpfg, SurfaceWithTwoScalesWarns) {
  EXPECT_TRUE(Warnings("axiom: ~leaf(1) ~petal(1,2,3) ~flower\n").empty());
  auto w = Warnings("axiom: F ~leaf(1,2)\n");
  ASSERT_EQ(w.size(), 1u) << Joined(w);
  EXPECT_EQ(w[0].rfind("1:10 surface '~leaf' takes 1 scale or 3", 0), 0u) << w[0];
}

TEST(Cpfg, TextAfterEndlsystemWarnsWhereItStarts) {
  auto w = Warnings("axiom: F\nendlsystem\n\n  F --> FF\nG --> GG\n");
  ASSERT_EQ(w.size(), 1u) << Joined(w);
  EXPECT_EQ(w[0], "4:3 text after 'endlsystem' is ignored (it is not an 'lsystem:' block)");
  // ... and it is ignored: F is not rewritten.
  EXPECT_EQ(DeriveText("axiom: F\nendlsystem\nF --> FF\n", 1), "F");
}

TEST(Cpfg, SecondLsystemBlockIsASubLsystem) {
  // Read, not warned about (tests/lsys/cpfg_sub_lsystem_test.cpp).
  EXPECT_TRUE(
      Warnings("Lsystem: 1\naxiom: F\nendlsystem\nLsystem: 2\naxiom: G\nendlsystem\n").empty());
}

TEST(Cpfg, BlankLinesAndCommentsAfterEndlsystemAreSilent) {
  EXPECT_TRUE(Warnings("axiom: F\nendlsystem\n\n/* done */\n// end\n").empty());
}

TEST(Cpfg, OneLetterSurfaceNameWhenOnlyItIsKnown) {
  ParseOptions opt;
  opt.isSurface = [](const std::string& n) { return n == "l" || n == "leaf"; };
  Grammar g = MustParse("axiom: ~lF ~leaf(2) ~leafF ~lx\n", opt);
  // ~lF: l is a surface and lF is not, so ~l then F (cpfg); ~leaf is whole;
  // ~leafF: leafF is not a surface, l is, so ~l then e a f F; ~lx: ~l x.
  std::string names;
  for (SymbolId s : g.axiom.symbols) names += g.symbols.name(s) + " ";
  EXPECT_EQ(names, "~l F ~leaf ~l e a f F ~l x ");
}

TEST(Cpfg, SurfaceNamesAreWholeWithoutALibrary) {
  Grammar g = MustParse("axiom: ~lF\n");
  ASSERT_EQ(g.axiom.symbols.size(), 1u);
  EXPECT_EQ(g.symbols.name(g.axiom.symbols[0]), "~lF");
}

TEST(Cpfg, ColourAndWidthSymbolsAreModules) {
  EXPECT_EQ(DeriveText("axiom: A\nA --> ;(2)F,#!;,(1)#(3)A\n", 1), ";(2)F,#!;,(1)#(3)A");
  EXPECT_EQ(DeriveText("axiom: A(1)\nA(x) --> F(x),A(x+1)\n", 2), "F(1),F(2),A(3)");
}

TEST(Cpfg, WidthIncrementMustBePositive) {
  ParseResult r = ParseGrammarText("width increment: 0\naxiom: F\n", "c.l");
  ASSERT_FALSE(r.grammar);
  EXPECT_EQ(r.diagnostics.items[0].message, "width increment must be positive");
  EXPECT_EQ(MustParse("width increment: 0.5\naxiom: F\n").widthIncrement, 0.5);
}

TEST(Cpfg, TrailingBackslashContinuesALine) {
  EXPECT_EQ(DeriveText("axiom: A\nA --> B\\\n  C \\\nD\n", 1), "BCD");
  // On any line: a #define, an axiom.
  EXPECT_EQ(DeriveText("#define n \\\n 3\naxiom: A(n) \\\n B\n", 0), "A(3)B");
}

TEST(Cpfg, BackslashBeforeAStatementOrProductionIsTheRollModule) {
  EXPECT_EQ(DeriveText("axiom: A\\\nA --> F\\\nB --> C\n", 1), "F\\\\");
  EXPECT_EQ(DeriveText("axiom: A\\\n\n", 0), "A\\");  // last line, then blank
  EXPECT_EQ(DeriveText("axiom: A\nA(n) \\\n--> B\nA --> C\n", 1), "C");
}

TEST(Cpfg, IndentedLinesContinueAProduction) {
  EXPECT_EQ(DeriveText("axiom: A\nA --> B\n\t[+C]\n\tD\nB --> E\n", 1), "B[+C]D");
  // The arrow on the line after the predecessor and condition.
  EXPECT_EQ(DeriveText("axiom: A(2)\nA(n) : n > 0\n\t--> B A(n-1)\n", 3), "BBA(0)");
  // A weight on its own line.
  EXPECT_EQ(DeriveText("axiom: A\nA --> B\n    : 1\n", 1), "B");
}

TEST(Cpfg, IndentedLinesContinueTheAxiom) {
  // As vlab's tri-bar and natica objects write a long axiom.
  EXPECT_EQ(DeriveText("axiom: A\n\tB[C]\n\t  D(2)\nA --> E\n", 0), "AB[C]D(2)");
  EXPECT_EQ(DeriveText("axiom: A\n\tB\nA --> E\n", 1), "EB");
  // An indented production after the axiom stays a production.
  EXPECT_EQ(DeriveText("axiom: A\n\tA --> E\n", 1), "E");
  ParseResult r = ParseGrammarText("axiom: A\n\tB(1 +)\n", "c.l");
  ASSERT_FALSE(r.grammar);
  EXPECT_EQ(r.diagnostics.items[0].loc.line, 2) << r.diagnostics.items[0].Format();
  EXPECT_EQ(r.diagnostics.items[0].sourceLine, "\tB(1 +)") << r.diagnostics.items[0].Format();
}

TEST(Cpfg, IndentedProductionsAndStatementsStayLinesOfTheirOwn) {
  EXPECT_EQ(DeriveText("axiom: A\n  A --> B\n  B --> C\n", 2), "C");
  Grammar g = MustParse("axiom: A\nA --> B\n  derivation length: 2\n\tdecomposition\nB --> C\n");
  EXPECT_EQ(g.derivationLength, 2);
  EXPECT_EQ(g.decomposition.productions.size(), 1u);
}

TEST(Cpfg, ErrorsOnAContinuationLinePointAtThatLine) {
  ParseResult r = ParseGrammarText("axiom: A\nA --> B\n\t[+C(1 +)]\n", "c.l");
  ASSERT_FALSE(r.grammar);
  const Diagnostic& d = r.diagnostics.items[0];
  EXPECT_EQ(d.loc.line, 3) << d.Format();
  EXPECT_EQ(d.loc.column, 9) << d.Format();
  EXPECT_EQ(d.sourceLine, "\t[+C(1 +)]") << d.Format();

  ParseResult b = ParseGrammarText("axiom: A\nA --> B \\\n C(2, @)\n", "c.l");
  ASSERT_FALSE(b.grammar);
  EXPECT_EQ(b.diagnostics.items[0].loc.line, 3) << b.diagnostics.items[0].Format();
  EXPECT_EQ(b.diagnostics.items[0].loc.column, 7) << b.diagnostics.items[0].Format();
}

TEST(Cpfg, RunTimeErrorsOnAContinuationLinePointAtThatLine) {
  Grammar g = MustParse("axiom: A(0)\nA(x) -->\n\tB(1/x)\n");
  DeriveOptions opt;
  opt.steps = 1;
  auto r = Derive(g, opt);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().loc.line, 3) << r.error().Format();
  EXPECT_EQ(r.error().loc.column, 5) << r.error().Format();
  EXPECT_EQ(r.error().sourceLine, "\tB(1/x)") << r.error().Format();
}

TEST(Cpfg, NranIsTheNormalDistribution) {
  const std::string a = DeriveText("seed: 3\naxiom: A(nran(5, 2), nran(0, 1))\n", 0);
  EXPECT_EQ(a, DeriveText("seed: 3\naxiom: A(normal(5, 2), normal(0, 1))\n", 0));
  EXPECT_NE(a, DeriveText("seed: 4\naxiom: A(nran(5, 2), nran(0, 1))\n", 0));
}

TEST(Cpfg, UnsupportedCpfgFunctionsAreNamedAsSuch) {
  ParseResult r = ParseGrammarText("axiom: A\nA --> B(srand(1, 2))\n", "c.l");
  ASSERT_FALSE(r.grammar);
  const Diagnostic& d = r.diagnostics.items[0];
  EXPECT_EQ(d.message, "cpfg function 'srand' is not supported by Sylva");
  EXPECT_EQ(d.loc.line, 2);
  EXPECT_EQ(d.loc.column, 9);
}

TEST(Cpfg, DefineWithArgumentsIsAFunction) {
  EXPECT_EQ(DeriveText("#define sq(x) ((x)*(x))\n#define k 3\n#define lin(a, b) (a*k + b)\n"
                       "axiom: A(2)\nA(n) --> B(sq(n+1), lin(n, sq(2)))\n",
                       1),
            "B(9,10)");
  // A random argument is drawn once per use, as the preprocessor would.
  const std::string twice = DeriveText("seed: 5\n#define d(x) (x - x)\naxiom: A(d(ran(1)))\n", 0);
  EXPECT_NE(twice, "A(0)");
}

TEST(Cpfg, DefineWithArgumentsErrorsAreLocated) {
  // A .lsys file: in a cpfg file (.l) an undefined name is a warning.
  auto firstError = [](const std::string& text) {
    ParseResult r = ParseGrammarText(text, "c.lsys");
    EXPECT_FALSE(r.grammar);
    if (r.diagnostics.items.empty()) return std::string("<none>");
    const Diagnostic& d = r.diagnostics.items[0];
    return std::to_string(d.loc.line) + ":" + std::to_string(d.loc.column) + " " + d.message;
  };
  // A body that is not an expression of its parameters is text (cpfg's
  // preprocessor): its errors are found where it is used.
  EXPECT_EQ(firstError("#define f(x) (x + y)\naxiom: A(f(1))\n"),
            "2:10 unknown name 'y' in expression (in the text of '#define f' at line 1)");
  EXPECT_EQ(firstError("#define f(x, x) x\naxiom: A\n"), "1:14 parameter 'x' appears twice");
  EXPECT_EQ(firstError("#define f(x) x\naxiom: A(f(1, 2))\n"),
            "2:10 'f' (#define) takes 1 argument, given 2");
  EXPECT_EQ(firstError("#define f(x) x\n#define f(y) y\naxiom: A\n"),
            "2:9 redefinition of 'f' (first defined at line 1)");
  // A run-time error inside the body points at the call.
  Grammar g = MustParse("#define inv(x) (1/x)\naxiom: A(0)\nA(n) --> B(inv(n))\n");
  DeriveOptions opt;
  opt.steps = 1;
  auto r = Derive(g, opt);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().loc.line, 3) << r.error().Format();
  EXPECT_EQ(r.error().loc.column, 12) << r.error().Format();
}

TEST(Cpfg, UnusedDefineWithArgumentsWarns) {
  auto w = Warnings("#define f(x) x\naxiom: A\n");
  ASSERT_EQ(w.size(), 1u) << Joined(w);
  EXPECT_EQ(w[0], "1:9 constant 'f' is never used");
}

}  // namespace
}  // namespace sylva::lsys
