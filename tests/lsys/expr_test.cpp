#include <gtest/gtest.h>

#include <cmath>

#include "lsys/expr_parser.h"

namespace sylva::lsys {
namespace {

struct Compiled {
  bool ok = false;
  Expr expr;
  ExprParseError error;
};

Compiled Compile(const std::string& text, const std::vector<std::string>& formals = {}) {
  static const std::unordered_map<std::string, double> constants = {{"r1", 0.9}, {"a0", 45}};
  ExprScope scope{&constants, nullptr, &formals};
  Compiled c;
  size_t pos = 0;
  c.ok = ParseExpr(text, &pos, scope, &c.expr, &c.error);
  if (c.ok && pos != text.size()) {
    c.ok = false;
    c.error.column = int(pos) + 1;
    c.error.message = "trailing text";
  }
  return c;
}

double Eval(const std::string& text, std::vector<double> formals = {},
            std::vector<std::string> names = {}) {
  Compiled c = Compile(text, names);
  EXPECT_TRUE(c.ok) << text << ": " << c.error.message;
  RandomStream rng{1, 0, 0, 0, 0};
  double v = NAN;
  EvalError e;
  EXPECT_TRUE(c.expr.Eval(formals.data(), rng, &v, &e)) << text << ": " << e.message;
  return v;
}

TEST(Expr, PrecedenceAndAssociativity) {
  EXPECT_EQ(Eval("1+2*3"), 7);
  EXPECT_EQ(Eval("(1+2)*3"), 9);
  EXPECT_EQ(Eval("2^3^2"), 512);  // right-associative
  EXPECT_EQ(Eval("-2^2"), -4);
  EXPECT_EQ(Eval("10-4-3"), 3);
  EXPECT_EQ(Eval("7 % 4"), 3);
  EXPECT_EQ(Eval("1 < 2 && 3 >= 3"), 1);
  EXPECT_EQ(Eval("1 > 2 || 0"), 0);
  EXPECT_EQ(Eval("!0 + !5"), 1);
  EXPECT_EQ(Eval("1 == 1 ? 10 : 20"), 10);
  EXPECT_EQ(Eval("0 ? 10 : 1 ? 20 : 30"), 20);
}

TEST(Expr, ConstantsAndPiFoldAtCompileTime) {
  Compiled c = Compile("r1 * 2 + a0 + pi - pi");
  ASSERT_TRUE(c.ok);
  EXPECT_TRUE(c.expr.IsConstant());
  EXPECT_DOUBLE_EQ(c.expr.constant(), 0.9 * 2 + 45);
}

TEST(Expr, TrigonometryIsInDegreesAsInCpfg) {
  EXPECT_NEAR(Eval("sin(30)"), 0.5, 1e-15);
  EXPECT_NEAR(Eval("cos(60)"), 0.5, 1e-15);
  EXPECT_NEAR(Eval("atan2(1, 1)"), 45, 1e-12);
  EXPECT_NEAR(Eval("asin(1)"), 90, 1e-12);
}

TEST(Expr, Functions) {
  EXPECT_EQ(Eval("sqrt(16) + abs(-2) + floor(2.7) + ceil(2.1)"), 4 + 2 + 2 + 3);
  EXPECT_EQ(Eval("min(3, 4) + max(3, 4) + clamp(9, 0, 5)"), 3 + 4 + 5);
  EXPECT_NEAR(Eval("exp(log(5))"), 5, 1e-12);
  EXPECT_EQ(Eval("pow(2, 10)"), 1024);
}

TEST(Expr, FormalsAreLoadedFromSlots) {
  EXPECT_EQ(Eval("l*r1 + w", {10, 1}, {"l", "w"}), 10);
  Compiled c = Compile("w", {"l", "w"});
  ASSERT_TRUE(c.ok);
  EXPECT_EQ(c.expr.kind(), Expr::Kind::kFormal);
}

TEST(Expr, ShortCircuitGuardsDivision) {
  EXPECT_EQ(Eval("x != 0 && 1/x > 2", {0}, {"x"}), 0);
  EXPECT_EQ(Eval("x == 0 || 1/x > 2", {0}, {"x"}), 1);
  EXPECT_EQ(Eval("x == 0 ? 0 : 1/x", {0}, {"x"}), 0);
}

TEST(Expr, RuntimeDivisionByZeroReportsColumn) {
  Compiled c = Compile("1 + 2/x", {"x"});
  ASSERT_TRUE(c.ok);
  double x = 0, v;
  RandomStream rng{1, 0, 0, 0, 0};
  EvalError e;
  EXPECT_FALSE(c.expr.Eval(&x, rng, &v, &e));
  EXPECT_EQ(e.message, "division by zero");
  EXPECT_EQ(e.column, 6);
}

TEST(Expr, DomainErrorsAreErrorsNotNaN) {
  for (const char* text : {"sqrt(x - 1)", "log(x)", "asin(x + 2)", "pow(x - 1, 0.5)"}) {
    Compiled c = Compile(text, {"x"});
    ASSERT_TRUE(c.ok) << text;
    double x = 0, v;
    RandomStream rng{1, 0, 0, 0, 0};
    EvalError e;
    EXPECT_FALSE(c.expr.Eval(&x, rng, &v, &e)) << text << " gave " << v;
    EXPECT_FALSE(e.message.empty()) << text;
  }
}

TEST(Expr, ConstantDivisionByZeroIsACompileError) {
  Compiled c = Compile("4 / (2 - 2)");
  EXPECT_FALSE(c.ok);
  EXPECT_EQ(c.error.message, "division by zero");
  EXPECT_EQ(c.error.column, 3);
}

TEST(Expr, ParseErrorsNameTheProblemAndColumn) {
  struct Case {
    const char* text;
    int column;
    const char* message;
  } cases[] = {
      {"r3 + 1", 1, "unknown name 'r3' in expression"},
      {"1 + ", 5, "expected an expression"},
      {"min(1)", 1, "function 'min' takes 2 arguments, given 1"},
      {"foo(1)", 1, "unknown function 'foo'"},
      {"1.2.3", 1, "malformed number '1.2.3'"},
      {"(1 + 2", 7, "expected ')'"},
      {"1e+", 1, "malformed number: exponent has no digits"},
      {"sqrt", 1, "function 'sqrt' needs arguments"},
  };
  for (const auto& k : cases) {
    Compiled c = Compile(k.text);
    EXPECT_FALSE(c.ok) << k.text;
    EXPECT_EQ(c.error.message, k.message) << k.text;
    EXPECT_EQ(c.error.column, k.column) << k.text << ": " << c.error.message;
  }
}

TEST(Expr, DeepNestingIsAnErrorNotACrash) {
  std::string deep(500, '(');
  deep += "1";
  deep += std::string(500, ')');
  Compiled c = Compile(deep);
  EXPECT_FALSE(c.ok);
  EXPECT_EQ(c.error.message, "expression nested deeper than 48");
}

std::string Chain(const std::string& term, const std::string& op, int n) {
  std::string s = term;
  for (int i = 1; i < n; ++i) s += op + term;
  return s;
}

TEST(Expr, FlatOperatorChainsOf50000TermsCompileAndEvaluate) {
  // Used to overflow the stack: the fold, the code emission and the tree's
  // destructor recursed once per term.
  Compiled folded = Compile(Chain("1", "+", 50000));
  ASSERT_TRUE(folded.ok) << folded.error.message;
  ASSERT_TRUE(folded.expr.IsConstant());
  EXPECT_EQ(folded.expr.constant(), 50000);
  EXPECT_EQ(Eval(Chain("x", "+", 50000), {0.5}, {"x"}), 25000);
  EXPECT_EQ(Eval(Chain("x", "*", 50000), {1.0}, {"x"}), 1);
  EXPECT_EQ(Eval(Chain("x > 0", " && ", 50000), {1.0}, {"x"}), 1);
  EXPECT_EQ(Eval(Chain("x < 0", " || ", 50000), {1.0}, {"x"}), 0);
  EXPECT_EQ(Eval(Chain("x", "-", 50001), {2.0}, {"x"}), -2.0 * 49999);
}

TEST(Expr, EveryKindOfNestingStopsAtTheLimitWithItsColumn) {
  const int n = 100000;
  std::string parens = std::string(n, '(') + "1" + std::string(n, ')');
  std::string minus = Chain("-", " ", n) + " 1";
  std::string nots = std::string(n, '!') + "1";
  std::string power = Chain("2", "^", n);
  std::string calls = Chain("sin(", "", n) + "1" + std::string(n, ')');
  std::string ternary = Chain("1 ? 2 :", " ", n) + " 3";
  for (const std::string* text : {&parens, &minus, &nots, &power, &calls, &ternary}) {
    Compiled c = Compile(*text);
    EXPECT_FALSE(c.ok) << text->substr(0, 20);
    EXPECT_EQ(c.error.message, "expression nested deeper than 48") << text->substr(0, 20);
    EXPECT_GT(c.error.column, 1) << text->substr(0, 20);
    EXPECT_LT(c.error.column, 50 * 8) << text->substr(0, 20);
  }
  // 48 levels are fine.
  EXPECT_EQ(Eval(std::string(47, '(') + "7" + std::string(47, ')')), 7);
}

TEST(Expr, UnexpectedByteIsShownInHex) {
  // Was "\\x255" (decimal).
  Compiled c = Compile("1 + \xff");
  EXPECT_FALSE(c.ok);
  EXPECT_EQ(c.error.message, "unexpected character '\\xff' in expression");
  EXPECT_EQ(c.error.column, 5);
}

TEST(Expr, RunTimeErrorColumnsPast65535AreExact) {
  // Columns were stored in 16 bits and clamped.
  std::string text = std::string(70000, ' ') + "1 / x";
  Compiled c = Compile(text, {"x"});
  ASSERT_TRUE(c.ok) << c.error.message;
  RandomStream rng{1, 0, 0, 0, 0};
  double zero = 0, v;
  EvalError e;
  EXPECT_FALSE(c.expr.Eval(&zero, rng, &v, &e));
  EXPECT_EQ(e.column, 70003) << e.message;
}

TEST(Expr, RandomFunctionsStayInRangeAndAreNotFolded) {
  Compiled c = Compile("ran(10)");
  ASSERT_TRUE(c.ok);
  EXPECT_FALSE(c.expr.IsConstant());
  EXPECT_TRUE(c.expr.UsesRandom());
  RandomStream rng{9, 0, 0, 0, 0};
  for (int i = 0; i < 1000; ++i) {
    double v;
    EvalError e;
    ASSERT_TRUE(c.expr.Eval(nullptr, rng, &v, &e));
    ASSERT_GE(v, 0);
    ASSERT_LT(v, 10);
  }
  Compiled u = Compile("uniform(2, 3)");
  RandomStream rng2{9, 0, 0, 0, 0};
  double v;
  EvalError e;
  ASSERT_TRUE(u.expr.Eval(nullptr, rng2, &v, &e));
  EXPECT_GE(v, 2);
  EXPECT_LT(v, 3);
}

}  // namespace
}  // namespace sylva::lsys
