#include "core/rng.h"

#include <gtest/gtest.h>

#include <cmath>

namespace sylva {

TEST(Rng, SameKeySameDraws) {
  RandomStream a{42, 1, 2, 3, 0}, b{42, 1, 2, 3, 0};
  for (int i = 0; i < 100; ++i) EXPECT_EQ(a.Uniform(), b.Uniform());
}

TEST(Rng, NeighbouringKeysDiffer) {
  RandomStream a{42, 1, 2, 3, 0}, b{42, 1, 2, 4, 0}, c{43, 1, 2, 3, 0};
  double x = a.Uniform();
  EXPECT_NE(x, b.Uniform());
  EXPECT_NE(x, c.Uniform());
}

TEST(Rng, UniformMomentsMatchTheory) {
  // Mean 1/2 and variance 1/12 over 10^6 draws keyed by index: standard
  // error of the mean is 0.00029, so 0.002 is about 7 sigma.
  const int n = 1000000;
  double sum = 0, sum2 = 0, lo = 1, hi = 0;
  for (int i = 0; i < n; ++i) {
    double u = ToUnit(CounterHash(7, 0, 0, uint64_t(i)));
    sum += u;
    sum2 += u * u;
    lo = std::min(lo, u);
    hi = std::max(hi, u);
  }
  double mean = sum / n, var = sum2 / n - mean * mean;
  EXPECT_NEAR(mean, 0.5, 0.002) << "mean " << mean;
  EXPECT_NEAR(var, 1.0 / 12, 0.001) << "variance " << var;
  EXPECT_GE(lo, 0.0);
  EXPECT_LT(hi, 1.0);
}

TEST(Rng, NormalMoments) {
  RandomStream s{3, 0, 0, 0, 0};
  const int n = 200000;
  double sum = 0, sum2 = 0;
  for (int i = 0; i < n; ++i) {
    double x = s.Normal();
    sum += x;
    sum2 += x * x;
  }
  double mean = sum / n, var = sum2 / n - mean * mean;
  EXPECT_NEAR(mean, 0.0, 0.01) << mean;
  EXPECT_NEAR(var, 1.0, 0.02) << var;
}

}  // namespace sylva
