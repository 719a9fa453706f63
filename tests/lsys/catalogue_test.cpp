// Golden module counts of the ABOP catalogue in grammars/abop/. The counts
// of the non-parametric figures were cross-checked with the independent
// naive rewriter tests/tools/naive_lsystem.py.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <set>

#include "lsys_test_util.h"

namespace sylva::lsys {
namespace {

using testing::MustDerive;
using testing::SourcePath;

struct Golden {
  const char* file;
  uint64_t modules;  // at the figure's derivation length
};

constexpr Golden kGolden[] = {
    {"fig1_06_koch_island", 3803},
    {"fig1_07a_quadratic_koch_island", 2211},
    {"fig1_07b_quadratic_snowflake", 1250},
    {"fig1_08_islands_and_lakes", 2595},
    {"fig1_09a_koch_curve", 30427},
    {"fig1_09b_koch_curve", 16007},
    {"fig1_09c_koch_curve", 2287},
    {"fig1_09d_koch_curve", 4999},
    {"fig1_09e_koch_curve", 24999},
    {"fig1_09f_koch_curve", 4999},
    {"fig1_10a_dragon_curve", 3070},
    {"fig1_10b_sierpinski_gasket", 1457},
    {"fig1_11a_hexagonal_gosper", 5601},
    {"fig1_11b_quadratic_gosper", 1094},
    {"fig1_19_hilbert_3d", 271},
    {"fig1_24a_bracketed_plant", 7811},
    {"fig1_24b_bracketed_plant", 9373},
    {"fig1_24c_bracketed_plant", 11116},
    {"fig1_24d_bracketed_plant", 13956},
    {"fig1_24e_bracketed_plant", 12863},
    {"fig1_24f_bracketed_plant", 6263},
    {"fig1_25_bush", 77399},
    {"fig1_31a_hogeweg_hesper", 6910},
    {"fig1_31b_hogeweg_hesper", 19199},
    {"fig1_31c_hogeweg_hesper", 2926},
    {"fig1_31d_hogeweg_hesper", 5789},
    {"fig1_31e_hogeweg_hesper", 2428},
    {"fig1_37a_row_of_trees", 9556},
    {"fig1_37b_row_of_trees", 7792},
    {"fig1_39a_branching", 32761},
    {"fig1_39b_branching", 32761},
    {"fig2_06a_monopodial", 7162},
    {"fig2_06b_monopodial", 7162},
    {"fig2_06c_monopodial", 7162},
    {"fig2_06d_monopodial", 7162},
    {"fig2_07a_sympodial", 11253},
    {"fig2_07b_sympodial", 11253},
    {"fig2_07c_sympodial", 11253},
    {"fig2_07d_sympodial", 11253},
    {"fig2_08a_ternary", 6556},
    {"fig2_08b_ternary", 59044},
    {"fig2_08c_ternary", 59044},
    {"fig2_08d_ternary", 6556},
};

Grammar Load(const std::string& name) {
  ParseResult r = ParseGrammarFile(SourcePath("grammars/abop/" + name + ".lsys"));
  EXPECT_TRUE(r.grammar) << r.diagnostics.FormatAll();
  EXPECT_TRUE(r.diagnostics.items.empty()) << name << ":\n" << r.diagnostics.FormatAll();
  return r.grammar ? std::move(*r.grammar) : Grammar{};
}

TEST(Catalogue, ModuleCountsAtEachFiguresDerivationLength) {
  for (const Golden& gold : kGolden) {
    Grammar g = Load(gold.file);
    auto r = MustDerive(g);
    EXPECT_EQ(r.word.size(), gold.modules) << gold.file;
  }
}

TEST(Catalogue, EveryGrammarFileHasAGoldenCount) {
  std::set<std::string> listed;
  for (const Golden& g : kGolden) listed.insert(g.file);
  listed.insert("fig1_27_stochastic_plant");  // checked statistically below
  for (auto& e : std::filesystem::directory_iterator(SourcePath("grammars/abop"))) {
    if (e.path().extension() != ".lsys") continue;
    EXPECT_TRUE(listed.count(e.path().stem().string())) << e.path() << " has no golden count";
  }
}

TEST(Catalogue, KochIslandMatchesClosedForm) {
  // Axiom F-F-F-F, F -> F-F+F+FF-F-F+F (8 F's, 6 turns): 4*8^n F's and
  // 3 + 6*4*(8^n - 1)/7 turns.
  Grammar g = Load("fig1_06_koch_island");
  for (int n = 0; n <= 6; ++n) {
    DeriveOptions opt;
    opt.steps = n;
    auto r = MustDerive(g, opt);
    const uint64_t p = uint64_t(1) << (3 * n);
    EXPECT_EQ(r.word.size(), 4 * p + 3 + 24 * (p - 1) / 7) << "n = " << n;
  }
}

TEST(Catalogue, TwoFormsOfFig139GiveTheSameStructure) {
  // Eq. (1.9) scales the new internodes, eq. (1.10) grows the old ones: the
  // same branching pattern, with lengths in ratio R^n.
  Grammar a = Load("fig1_39a_branching"), b = Load("fig1_39b_branching");
  auto ra = MustDerive(a), rb = MustDerive(b);
  ASSERT_EQ(ra.word.size(), rb.word.size());
  const double R = 1.456;
  const double scale = std::pow(R, 11);
  size_t compared = 0;
  for (size_t i = 0; i < ra.word.size(); ++i) {
    ASSERT_EQ(a.symbols.name(ra.word.symbols[i]), b.symbols.name(rb.word.symbols[i])) << i;
    if (a.symbols.name(ra.word.symbols[i]) == "F") {
      double la = ra.word.ParamsOf(i)[0], lb = rb.word.ParamsOf(i)[0];
      ASSERT_NEAR(la * scale, lb, 1e-9 * lb) << "module " << i;
      ++compared;
    }
  }
  EXPECT_EQ(compared, 4095u);
}

TEST(Catalogue, StochasticPlantIsReproduciblePerSeedAndVariesAcrossSeeds) {
  Grammar g = Load("fig1_27_stochastic_plant");
  std::set<uint64_t> hashes;
  double sumF = 0;
  const int seeds = 400;
  for (int seed = 1; seed <= seeds; ++seed) {
    DeriveOptions opt;
    opt.seed = uint64_t(seed);
    auto r1 = MustDerive(g, opt);
    if (seed <= 5) {
      EXPECT_EQ(HashWord(r1.word), HashWord(MustDerive(g, opt).word)) << seed;
    }
    hashes.insert(HashWord(r1.word));
    for (SymbolId s : r1.word.symbols) sumF += g.symbols.name(s) == "F";
  }
  EXPECT_EQ(hashes.size(), size_t(seeds)) << "distinct individuals";
  // Each F becomes 5 F's (p = 0.33) or 3 (p = 0.67): a branching process
  // with mean 3.66 per step, so E[#F] = 3.66^5 = 654.6 with a standard
  // deviation of 197 per plant, i.e. a standard error of 9.9 over 400.
  const double mean = sumF / seeds;
  EXPECT_NEAR(mean, std::pow(3.66, 5), 40) << "mean number of F";
}

}  // namespace
}  // namespace sylva::lsys
