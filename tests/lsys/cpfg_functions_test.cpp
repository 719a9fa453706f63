// cpfg's random functions beyond ran and nran (docs/cpfg.md): bran (beta)
// and biran (binomial), drawn from the seeded generator.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

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
  for (const char* text : {"bran(0, 1)", "bran(1, -2)", "biran(2.5, 0.5)", "biran(3, 1.5)"}) {
    Expr e = MustCompile(std::string("1 + ") + text);
    RandomStream rng{1, 0, 0, 0, 0};
    double v = 0;
    EvalError err;
    EXPECT_FALSE(e.Eval(nullptr, rng, &v, &err)) << text << " gave " << v;
    EXPECT_EQ(err.column, 5) << text << ": " << err.message;
  }
}

}  // namespace
}  // namespace sylva::lsys
