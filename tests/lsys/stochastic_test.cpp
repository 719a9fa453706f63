#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "lsys_test_util.h"

namespace sylva::lsys {
namespace {

using testing::MustDerive;
using testing::MustParse;

// 2^17 independent draws: A(n) doubles until n == 0, then picks B, C or D.
constexpr const char* kChoice = R"(
axiom: A(17)
A(n) : n > 0 --> A(n-1)A(n-1)
A(n) : n == 0 --> B : 1
A(n) : n == 0 --> C : 2
A(n) : n == 0 --> D : 7
)";

std::array<uint64_t, 3> CountBCD(const Grammar& g, const Word& w) {
  std::array<uint64_t, 3> n{};
  for (SymbolId s : w.symbols) {
    const std::string& name = g.symbols.name(s);
    if (name == "B") ++n[0];
    if (name == "C") ++n[1];
    if (name == "D") ++n[2];
  }
  return n;
}

TEST(Stochastic, FrequenciesFollowWeights) {
  Grammar g = MustParse(kChoice);
  DeriveOptions opt;
  opt.steps = 18;
  for (uint64_t seed : {1, 2, 3}) {
    opt.seed = seed;
    auto r = MustDerive(g, opt);
    auto n = CountBCD(g, r.word);
    const double total = double(n[0] + n[1] + n[2]);
    ASSERT_EQ(total, 131072.0);
    const double p[3] = {0.1, 0.2, 0.7};
    double chi2 = 0;
    for (int k = 0; k < 3; ++k) {
      double e = total * p[k];
      chi2 += (n[k] - e) * (n[k] - e) / e;
    }
    // 2 degrees of freedom: P(chi2 > 13.8) = 0.001.
    EXPECT_LT(chi2, 13.8) << "seed " << seed << ": B " << n[0] << " C " << n[1] << " D " << n[2];
  }
}

TEST(Stochastic, OnlyMatchingWeightedProductionsTakePart) {
  Grammar g = MustParse(R"(
axiom: A(12)
A(n) : n > 0 --> A(n-1)A(n-1)
A(n) : n == 0 --> B : 1
A(n) : n == 1 --> C : 1000
A(n) : n == 0 --> D : 1
)");
  DeriveOptions opt;
  opt.steps = 13;
  auto r = MustDerive(g, opt);
  auto n = CountBCD(g, r.word);
  EXPECT_EQ(n[1], 0u) << "C's condition never holds at n == 0";
  EXPECT_NEAR(double(n[0]) / 4096, 0.5, 0.04) << n[0];
}

TEST(Stochastic, WeightsAreExpressionsOfParameters) {
  Grammar g = MustParse(R"(
axiom: A(12,0)
A(n,w) : n > 0 --> A(n-1,w)A(n-1,w)
A(n,w) : n == 0 --> B : w
A(n,w) : n == 0 --> C : 1 - w
)");
  DeriveOptions opt;
  opt.steps = 13;
  auto r = MustDerive(g, opt);
  EXPECT_EQ(CountBCD(g, r.word)[0], 0u) << "weight 0 is never drawn";
}

TEST(Stochastic, SameSeedSameWordOtherSeedOtherWord) {
  Grammar g = MustParse(kChoice);
  DeriveOptions opt;
  opt.steps = 18;
  opt.seed = 5;
  uint64_t a = HashWord(MustDerive(g, opt).word);
  uint64_t b = HashWord(MustDerive(g, opt).word);
  opt.seed = 6;
  uint64_t c = HashWord(MustDerive(g, opt).word);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
}

TEST(Stochastic, RandomParametersAreReproducibleAndInRange) {
  Grammar g = MustParse(
      "axiom: A(10)\nA(n) : n > 0 --> A(n-1)A(n-1)\nA(n) : n == 0 --> F(uniform(1, 2))F(ran(3))\n");
  DeriveOptions opt;
  opt.steps = 11;
  auto r1 = MustDerive(g, opt);
  opt.threads = 1;
  auto r2 = MustDerive(g, opt);
  EXPECT_EQ(HashWord(r1.word), HashWord(r2.word));
  ASSERT_EQ(r1.word.params.size(), 2048u);
  double sum = 0;
  for (size_t i = 0; i < r1.word.params.size(); i += 2) {
    ASSERT_GE(r1.word.params[i], 1);
    ASSERT_LT(r1.word.params[i], 2);
    ASSERT_GE(r1.word.params[i + 1], 0);
    ASSERT_LT(r1.word.params[i + 1], 3);
    sum += r1.word.params[i];
  }
  EXPECT_NEAR(sum / 1024, 1.5, 0.03);
}

}  // namespace
}  // namespace sylva::lsys

namespace sylva::lsys {
namespace {

// 2^17 draws among 100 weighted productions of one predecessor; B(k) says
// which one fired. weights[k - 1] is the weight of B(k).
std::string HundredChoices(const std::vector<int>& weights) {
  std::string g = "axiom: A(17)\nA(n) : n > 0 --> A(n-1)A(n-1)\n";
  for (size_t k = 0; k < weights.size(); ++k) {
    g +=
        "A(n) : n == 0 --> B(" + std::to_string(k + 1) + ") : " + std::to_string(weights[k]) + "\n";
  }
  return g;
}

std::vector<uint64_t> CountB(const Word& w, size_t n) {
  std::vector<uint64_t> count(n + 1, 0);
  for (size_t i = 0; i < w.size(); ++i) {
    auto p = w.ParamsOf(i);
    if (!p.empty()) count[size_t(p[0])]++;
  }
  return count;
}

TEST(Stochastic, HundredCandidatesTheLastCanFire) {
  // Only the first 64 candidates used to be drawn from: B(100) never fired.
  std::vector<int> weights(100, 0);
  weights[99] = 1;
  Grammar g = MustParse(HundredChoices(weights));
  DeriveOptions opt;
  opt.steps = 18;
  auto r = MustDerive(g, opt);
  ASSERT_EQ(r.word.size(), size_t(1) << 17);
  EXPECT_EQ(CountB(r.word, 100)[100], uint64_t(1) << 17);
}

TEST(Stochastic, HundredCandidatesFollowTheirWeightsOnAnyThreadCount) {
  std::vector<int> weights(100, 1);
  weights[99] = 99;  // half of the draws
  Grammar g = MustParse(HundredChoices(weights));
  DeriveOptions opt;
  opt.steps = 18;
  opt.threads = 1;
  auto one = MustDerive(g, opt);
  const double n = double(size_t(1) << 17);
  auto count = CountB(one.word, 100);
  const double sigmaHalf = std::sqrt(n * 0.25);
  EXPECT_NEAR(double(count[100]), n / 2, 5 * sigmaHalf) << "B(100) of " << n;
  const double p = 1.0 / 198, sigma = std::sqrt(n * p * (1 - p));
  for (size_t k = 1; k < 100; ++k) {
    EXPECT_NEAR(double(count[k]), n * p, 6 * sigma) << "B(" << k << ")";
  }
  for (int threads : {2, 4}) {
    opt.threads = threads;
    auto r = MustDerive(g, opt);
    ASSERT_EQ(r.word.params.size(), one.word.params.size()) << threads << " threads";
    EXPECT_TRUE(std::equal(r.word.params.data(), r.word.params.data() + r.word.params.size(),
                           one.word.params.data()))
        << threads << " threads";
  }
}

}  // namespace
}  // namespace sylva::lsys
