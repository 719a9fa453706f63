// cpfg's random functions beyond ran and nran (docs/cpfg.md): bran (beta)
// and biran (binomial), drawn from the seeded generator.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <string>

#include "lsys/cpfg_function.h"
#include "lsys/expr_parser.h"
#include "lsys_test_util.h"

namespace sylva::lsys {
namespace {

using testing::DeriveText;

Expr MustCompile(const std::string& text) {
  ExprScope scope;
  Expr e;
  ExprParseError err;
  size_t pos = 0;
  EXPECT_TRUE(ParseExpr(text, &pos, scope, &e, &err)) << text << ": " << err.message;
  return e;
}

// Mean and variance of n draws of `text`, each from its own stream.
void Moments(const std::string& text, int n, double* mean, double* var, double* lo, double* hi) {
  Expr e = MustCompile(text);
  double sum = 0, sum2 = 0;
  *lo = INFINITY;
  *hi = -INFINITY;
  for (int i = 0; i < n; ++i) {
    RandomStream rng{7, 1, 0, uint64_t(i), 0};
    double v = 0;
    EvalError err;
    ASSERT_TRUE(e.Eval(nullptr, rng, &v, &err)) << err.message;
    sum += v;
    sum2 += v * v;
    *lo = std::min(*lo, v);
    *hi = std::max(*hi, v);
  }
  *mean = sum / n;
  *var = sum2 / n - *mean * *mean;
}

TEST(CpfgFunctions, BranIsTheBetaDistribution) {
  // Beta(2, 6): mean 2/8 = 0.25, variance 2*6/(8^2*9) = 0.0208333.
  double mean, var, lo, hi;
  Moments("bran(2, 6)", 40000, &mean, &var, &lo, &hi);
  EXPECT_NEAR(mean, 0.25, 0.003) << "mean " << mean;
  EXPECT_NEAR(var, 0.0208333, 0.001) << "variance " << var;
  EXPECT_GE(lo, 0) << lo;
  EXPECT_LE(hi, 1) << hi;
  // Shapes below 1 (U-shaped): Beta(0.5, 0.5) has mean 0.5, variance 0.125.
  Moments("bran(0.5, 0.5)", 40000, &mean, &var, &lo, &hi);
  EXPECT_NEAR(mean, 0.5, 0.006) << "mean " << mean;
  EXPECT_NEAR(var, 0.125, 0.003) << "variance " << var;
}

TEST(CpfgFunctions, BiranIsTheBinomialDistribution) {
  // Binomial(10, 0.3): mean 3, variance 2.1, whole numbers in [0, 10].
  double mean, var, lo, hi;
  Moments("biran(10, 0.3)", 40000, &mean, &var, &lo, &hi);
  EXPECT_NEAR(mean, 3, 0.03) << "mean " << mean;
  EXPECT_NEAR(var, 2.1, 0.06) << "variance " << var;
  EXPECT_GE(lo, 0);
  EXPECT_LE(hi, 10);
  Expr e = MustCompile("biran(10, 0.3)");
  for (int i = 0; i < 100; ++i) {
    RandomStream rng{7, 1, 0, uint64_t(i), 0};
    double v = 0;
    EvalError err;
    ASSERT_TRUE(e.Eval(nullptr, rng, &v, &err));
    EXPECT_EQ(v, std::floor(v)) << v;
  }
}

TEST(CpfgFunctions, RandomFunctionsAreReproducibleFromTheSeed) {
  const std::string g = "seed: 3\naxiom: A(bran(2, 5), biran(20, 0.5))\n";
  const std::string a = DeriveText(g, 0);
  EXPECT_EQ(a, DeriveText(g, 0));
  EXPECT_NE(a, DeriveText("seed: 4\naxiom: A(bran(2, 5), biran(20, 0.5))\n", 0));
}

TEST(CpfgFunctions, BadArgumentsAreErrorsAtTheCall) {
  for (const char* text : {"bran(0, 1)", "bran(1, -2)", "biran(-1, 0.5)", "biran(3, 1.5)"}) {
    Expr e = MustCompile(std::string("1 + ") + text);
    RandomStream rng{1, 0, 0, 0, 0};
    double v = 0;
    EvalError err;
    EXPECT_FALSE(e.Eval(nullptr, rng, &v, &err)) << text << " gave " << v;
    EXPECT_EQ(err.column, 5) << text << ": " << err.message;
  }
}

// A symmetric hump: the cubic B-spline of 4 points is their Bezier curve,
// so at the parameter 1/2 it is at x = (0 + 3*0.3 + 3*0.7 + 1)/8 = 0.5,
// y = (0 + 3 + 3 + 0)/8 = 0.75.
const char* kHump =
    "fver 1 1\nname: hump\nsamples: 0\nflip: off\npoints: 4\n0 0\n0.3 1\n0.7 1\n1 0\n";
const char* kLine = "range: 0.0 1.0\npoints: 4\n0 0\n0.333333 0.333333\n0.666667 0.666667\n1 1\n";

ParseOptions Files() {
  ParseOptions opt;
  opt.readFile = [](const std::string& path) -> std::optional<std::string> {
    if (path == "hump.func") return std::string(kHump);
    if (path == "line.func") return std::string(kLine);
    if (path == "set.fset")  // a function set: hump, then the line, by name
      return std::string("funcgalleryver 1 1\nitems: 2\n") + kHump +
             "fver 1 1\nname: LINE.func\nsamples: 100\nflip: on\npoints: 4\n0 0\n"
             "0.333333 0.333333\n0.666667 0.666667\n1 1\n";
    if (path == "sampled.func")
      return "fver 1 1\nname: s\nsamples: 3\nflip: off\npoints: 4\n0 0\n0.3 1\n0.7 1\n1 0\n";
    return std::nullopt;
  };
  return opt;
}

TEST(CpfgFunctions, FuncEvaluatesTheFunctionFileSplineAsCpfg) {
  auto f = CpfgFunction::Parse(kHump, "hump.func");
  ASSERT_TRUE(f) << f.error().Format();
  EXPECT_DOUBLE_EQ(f->Value(0.5), 0.75);
  // cpfg stops the bisection within 0.001 of x; the hump rises as 3x there.
  EXPECT_NEAR(f->Value(0), 0, 0.004) << f->Value(0);
  // Symmetric: f(0.2) = f(0.8), to the bisection's 0.001 in x.
  EXPECT_NEAR(f->Value(0.2), f->Value(0.8), 0.004) << f->Value(0.2) << " " << f->Value(0.8);
  auto line = CpfgFunction::Parse(kLine, "line.func");
  ASSERT_TRUE(line) << line.error().Format();
  for (double x : {0.1, 0.25, 0.6, 0.9})
    EXPECT_NEAR(line->Value(x), x, 0.0015) << "x " << x << " gave " << line->Value(x);
  // Outside [0, 1]: clamped.
  EXPECT_EQ(line->Value(-3), line->Value(0));
}

TEST(CpfgFunctions, SamplesInterpolateLinearlyBetweenPrecomputedValues) {
  // samples: 3 -> values at 0, 0.5, 1: 0, 0.75, ~0; f(0.25) is their mean.
  const std::string g = "functions: sampled.func\naxiom: A(func(1, 0.5), func(1, 0.25))\n";
  ParseResult r = ParseGrammarText(g, "c.l", Files());
  ASSERT_TRUE(r.grammar) << r.diagnostics.FormatAll();
  DeriveOptions opt;
  opt.steps = 0;
  auto w = Derive(*r.grammar, opt);
  ASSERT_TRUE(w);
  EXPECT_DOUBLE_EQ(w->word.params[0], 0.75);
  EXPECT_NEAR(w->word.params[1], 0.375, 0.002) << w->word.params[1];
}

TEST(CpfgFunctions, FuncInAProductionReadsTheFilesInOrder) {
  const std::string g =
      "functions: hump.func \"line.func\"\naxiom: A(0.5)\nA(x) --> B(func(1, x), func(2, x/2))\n";
  ParseResult r = ParseGrammarText(g, "c.l", Files());
  ASSERT_TRUE(r.grammar) << r.diagnostics.FormatAll();
  DeriveOptions opt;
  opt.steps = 1;
  auto w = Derive(*r.grammar, opt);
  ASSERT_TRUE(w);
  EXPECT_EQ(w->word.params[0], 0.75);
  EXPECT_NEAR(w->word.params[1], 0.25, 0.0015) << w->word.params[1];
}

TEST(CpfgFunctions, AViewFilesFunctionLinesServeAGrammarWithoutFunctions) {
  ParseOptions opt = Files();
  opt.functionFiles = {{"line.func", "p.v", 3, 11}, {"hump.func", "p.v", 4, 11}};
  ParseResult r = ParseGrammarText("axiom: A(func(1, 0.25), func(2, 0.5))\n", "c.l", opt);
  ASSERT_TRUE(r.grammar) << r.diagnostics.FormatAll();
  auto w = Derive(*r.grammar, DeriveOptions{});
  ASSERT_TRUE(w);
  EXPECT_NEAR(w->word.params[0], 0.25, 0.0015) << w->word.params[0];
  EXPECT_DOUBLE_EQ(w->word.params[1], 0.75);
  // The grammar's own `functions:` wins: func(1) is the hump there.
  ParseResult own = ParseGrammarText("functions: hump.func\naxiom: A(func(1, 0.5))\n", "c.l", opt);
  ASSERT_TRUE(own.grammar) << own.diagnostics.FormatAll();
  ASSERT_EQ(own.grammar->functions.size(), 1u);
  // A file the view names that cannot be read: an error at the view's line.
  opt.functionFiles.push_back({"missing.func", "p.v", 5, 11});
  ParseResult bad = ParseGrammarText("axiom: A\n", "c.l", opt);
  ASSERT_FALSE(bad.grammar);
  const Diagnostic& d = bad.diagnostics.items[0];
  EXPECT_EQ(d.loc.file + ":" + std::to_string(d.loc.line) + ":" + std::to_string(d.loc.column),
            "p.v:5:11")
      << d.Format();
  EXPECT_NE(d.message.find("cannot read function file 'missing.func'"), std::string::npos)
      << d.Format();
}

TEST(CpfgFunctions, FuncErrorsAreLocated) {
  auto first = [](const std::string& g) {
    ParseResult r = ParseGrammarText(g, "c.l", Files());
    EXPECT_FALSE(r.grammar);
    if (r.diagnostics.items.empty()) return std::string("<none>");
    const Diagnostic& d = r.diagnostics.items[0];
    return std::to_string(d.loc.line) + ":" + std::to_string(d.loc.column) + " " + d.message;
  };
  EXPECT_EQ(first("axiom: A\nA --> B(func(1, 0.5))\n"),
            "2:9 func(id, x) needs cpfg function files: name them with 'functions: FILE.func "
            "...' before the productions, or with 'function: FILE.func' lines in the view file; "
            "no view file was read (sylva looks for c.v, or takes --view FILE)");
  EXPECT_EQ(first("functions: hump.func\naxiom: A\nA --> B(func(2, 0.5))\n"),
            "3:9 func(id, x): id must be a whole number from 1 to 1 (the files of 'functions:')");
  EXPECT_EQ(first("functions: hump.func missing.func\naxiom: A\n"),
            "1:22 cannot read function file 'missing.func': cannot read file");
  auto bad = CpfgFunction::Parse("fver 1 1\nname: x\nsamples: 0\nflip: off\npoints: 4\n0 0\n1\n",
                                 "bad.func");
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().loc.line, 7);
  EXPECT_EQ(bad.error().message, "expected a point 'x y'");
}

TEST(CpfgFunctions, AFunctionSetGivesItsFunctionsInOrderAndByName) {
  // cpfg (generate.c, PreprocessLsystem) defines each name of the set as
  // its number, the name cut at its last '.': func(LINE, x) is func(2, x).
  ParseOptions opt = Files();
  opt.functionFiles = {{"set.fset", "p.v", 7, 15, /*set=*/true}};
  ParseResult r = ParseGrammarText(
      "axiom: A(func(hump, 0.5), func(LINE, 0.25), func(2, 0.75), LINE)\n", "c.l", opt);
  ASSERT_TRUE(r.grammar) << r.diagnostics.FormatAll();
  ASSERT_EQ(r.grammar->functions.size(), 2u);
  auto w = Derive(*r.grammar, DeriveOptions{});
  ASSERT_TRUE(w);
  ASSERT_EQ(w->word.params.size(), 4u);
  EXPECT_DOUBLE_EQ(w->word.params[0], 0.75);
  EXPECT_NEAR(w->word.params[1], 0.25, 0.002) << w->word.params[1];  // samples: 100
  EXPECT_NEAR(w->word.params[2], 0.75, 0.002) << w->word.params[2];
  EXPECT_EQ(w->word.params[3], 2);
  // As with cpp's -D, the grammar may #undef a name and define it again
  // (vlab's fern-leaf: `#undef int_length` then `#define int_length(x) ...`).
  ParseResult redefined = ParseGrammarText(
      "#undef LINE\n#define LINE(x) (10 * func(2, x))\n#define hump 2\n"
      "axiom: A(LINE(0.5), func(hump, 0.5))\n",
      "c.l", opt);
  ASSERT_TRUE(redefined.grammar) << redefined.diagnostics.FormatAll();
  auto w2 = Derive(*redefined.grammar, DeriveOptions{});
  ASSERT_TRUE(w2);
  EXPECT_NEAR(w2->word.params[0], 5, 0.02) << w2->word.params[0];
  EXPECT_NEAR(w2->word.params[1], 0.5, 0.002) << w2->word.params[1];  // the line, not the hump
  // Errors: a set that cannot be read, at the view file's line; a malformed
  // set, with the line in the set.
  opt.functionFiles = {{"gone.fset", "p.v", 7, 15, true}};
  ParseResult gone = ParseGrammarText("axiom: A\n", "c.l", opt);
  ASSERT_FALSE(gone.grammar);
  EXPECT_EQ(gone.diagnostics.items[0].loc.line, 7);
  EXPECT_NE(gone.diagnostics.items[0].message.find("cannot read function set 'gone.fset'"),
            std::string::npos)
      << gone.diagnostics.FormatAll();
  auto count = CpfgFunction::ParseSet(std::string("funcgalleryver 1 1\nitems: 3\n") + kHump, "s");
  ASSERT_FALSE(count);
  EXPECT_EQ(count.error().loc.line, 2);
  EXPECT_EQ(count.error().message, "'items: 3' but the set has 1 functions ('fver' lines)");
  auto point =
      CpfgFunction::ParseSet(std::string("funcgalleryver 1 1\nitems: 2\n") + kHump +
                                 "fver 1 1\nname: b\nsamples: 0\nflip: off\npoints: 4\n0 0\n1\n",
                             "s");
  ASSERT_FALSE(point);
  EXPECT_EQ(point.error().loc.line, 18);  // the 18th line of the set
  EXPECT_EQ(point.error().message, "expected a point 'x y'");
  EXPECT_FALSE(CpfgFunction::ParseSet(kHump, "s"));  // not a set
}

}  // namespace
}  // namespace sylva::lsys
