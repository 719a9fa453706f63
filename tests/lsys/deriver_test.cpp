#include <gtest/gtest.h>

#include "lsys_test_util.h"

namespace sylva::lsys {
namespace {

using testing::DeriveText;
using testing::MustDerive;
using testing::MustParse;
using testing::SourcePath;

TEST(Deriver, RewritesInParallelFromTheOldWord) {
  EXPECT_EQ(DeriveText("axiom: AB\nA --> B\nB --> A\n", 1), "BA");
}

TEST(Deriver, AlgaeLengthsAreFibonacci) {
  Grammar g = MustParse("axiom: A\nA --> AB\nB --> A\n");
  DeriveOptions opt;
  opt.steps = 20;
  auto r = MustDerive(g, opt);
  uint64_t a = 1, b = 2;
  for (const auto& s : r.steps) {
    EXPECT_EQ(s.modules, a) << "step " << s.step;
    uint64_t c = a + b;
    a = b;
    b = c;
  }
}

TEST(Deriver, FirstMatchingProductionInFileOrderApplies) {
  const char* g = "axiom: A(0)\nA(x) : x < 3 --> A(x+1)\nA(x) --> B(x)\n";
  EXPECT_EQ(DeriveText(g, 2), "A(2)");
  EXPECT_EQ(DeriveText(g, 4), "B(3)");
}

TEST(Deriver, MonopodialFirstStepByHand) {
  // A(1,10) with r1=0.9, r2=0.6, a0=45, d=137.5, wr=0.707 (ABOP Fig. 2.6a).
  Grammar g = MustParse(*ReadFile(SourcePath("grammars/abop/fig2_06a_monopodial.lsys")));
  DeriveOptions opt;
  opt.steps = 1;
  EXPECT_EQ(FormatWord(MustDerive(g, opt).word, g.symbols),
            "!(10)F(1)[&(45)B(0.6,7.07)]/(137.5)A(0.9,7.07)");
}

TEST(Deriver, DecompositionRunsToItsMaximumDepthAfterEachStep) {
  const char* base = "axiom: A\nA --> B\ndecomposition:\nmaximum depth: %d\nB --> CC\nC --> DD\n";
  char text[256];
  std::snprintf(text, sizeof text, base, 1);
  EXPECT_EQ(DeriveText(text, 1), "CC");
  std::snprintf(text, sizeof text, base, 2);
  EXPECT_EQ(DeriveText(text, 1), "DDDD");
  std::snprintf(text, sizeof text, base, 5);  // stops when nothing changes
  EXPECT_EQ(DeriveText(text, 1), "DDDD");
}

TEST(Deriver, RecursiveDecompositionIsBoundedByDepth) {
  EXPECT_EQ(DeriveText("axiom: A\nA --> B\ndecomposition:\nmaximum depth: 3\nB --> BB\n", 1),
            "BBBBBBBB");
}

TEST(Deriver, InterpretationLeavesTheDerivedWordAlone) {
  Grammar g =
      MustParse("axiom: A\nA --> AB\ninterpretation:\nmaximum depth: 2\nB --> [G]\nG --> F(2)\n");
  DeriveOptions opt;
  opt.steps = 2;
  auto r = MustDerive(g, opt);
  EXPECT_EQ(FormatWord(r.word, g.symbols), "ABB");
  auto w = Interpret(g, r.word);
  ASSERT_TRUE(w.ok());
  EXPECT_EQ(FormatWord(*w, g.symbols), "A[F(2)][F(2)]");
}

TEST(Deriver, CutRemovesTheRestOfItsBranch) {
  EXPECT_EQ(DeriveText("axiom: F[A%BC[E]G]D\nF --> F\n", 1), "F[A]D");
  EXPECT_EQ(DeriveText("axiom: AB%C[D]E\nA --> A\n", 1), "AB");
  EXPECT_EQ(DeriveText("axiom: F[AB]C[A(1)]\nA --> %\nA(x) --> %X\n", 1), "F[]C[]");
}

TEST(Deriver, MaxModulesStopsWithStepAndSize) {
  Grammar g = MustParse(*ReadFile(SourcePath("grammars/abop/fig1_06_koch_island.lsys")));
  DeriveOptions opt;
  opt.maxModules = 1000;
  auto r = Derive(g, opt);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().kind, ErrorKind::kRuntime);
  EXPECT_EQ(r.error().message,
            "derivation step 3 would make the word 3803 modules long, more than the limit of "
            "1000 (--max-modules)");
}

TEST(Deriver, ExponentialGrammarStopsAtTheDefaultLimitWithoutExhaustingMemory) {
  Grammar g = MustParse("axiom: A\nA --> AAAAAAAAAAAAAAAA\n");
  DeriveOptions opt;
  opt.steps = 40;  // 16^40 modules if unchecked
  auto r = Derive(g, opt);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("derivation step 8 would make the word 4294967296"),
            std::string::npos)
      << r.error().message;
}

TEST(Deriver, RuntimeDivisionByZeroPointsIntoTheProduction) {
  Grammar g = MustParse("axiom: A(1)\nA(x) --> A(x-1)B(1/x)\n");
  DeriveOptions opt;
  opt.steps = 3;
  auto r = Derive(g, opt);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().loc.line, 2);
  EXPECT_EQ(r.error().loc.column, 19);  // the '/'
  EXPECT_EQ(r.error().message, "division by zero (module 1 of the word, step 2)");
}

TEST(Deriver, SameWordForAnyThreadCount) {
  for (const char* file :
       {"grammars/abop/fig2_06a_monopodial.lsys", "grammars/abop/fig1_27_stochastic_plant.lsys",
        "grammars/abop/fig1_31b_hogeweg_hesper.lsys",
        "grammars/abop/fig1_24d_bracketed_plant.lsys"}) {
    Grammar g = MustParse(*ReadFile(SourcePath(file)));
    uint64_t reference = 0;
    size_t size = 0;
    for (int threads : {1, 2, 3, 8}) {
      DeriveOptions opt;
      opt.threads = threads;
      opt.steps = g.derivationLength + (g.usesContext ? 12 : 3);
      auto r = MustDerive(g, opt);
      uint64_t h = HashWord(r.word);
      if (threads == 1) {
        reference = h;
        size = r.word.size();
        EXPECT_GT(size, 40000u) << file << ": too small to be split into chunks";
      } else {
        EXPECT_EQ(h, reference) << file << " with " << threads << " threads";
        EXPECT_EQ(r.word.size(), size) << file;
      }
    }
  }
}

TEST(Deriver, ZeroStepsGivesTheAxiom) {
  EXPECT_EQ(DeriveText("axiom: A(2*3)B\nA(x) --> B\n", 0), "A(6)B");
}

TEST(Deriver, LongDerivationOfAFixedPointFinishes) {
  // B --> B applies at each step but changes nothing: the steps after the
  // first are skipped (one StepStats entry for the last).
  Grammar g = MustParse("derivation length: 100000\naxiom: AB\nB --> B\n");
  auto r = MustDerive(g);
  EXPECT_EQ(r.word.size(), 2u);
  ASSERT_EQ(r.steps.size(), 3u);
  EXPECT_EQ(r.steps.back().step, 100000);
}

TEST(Deriver, DerivationLengthOfCpfgsIntRangeEndsWhenTheWordSettles) {
  // cpfg files write `derivation length: 1000000` (corpus3's tree.l) and
  // more for "until it stops".
  Grammar g = MustParse("derivation length: 2147483647\naxiom: A(0)\nA(n) : n < 5 --> A(n+1)\n");
  EXPECT_EQ(g.derivationLength, 2147483647);
  auto r = MustDerive(g);
  EXPECT_EQ(FormatWord(r.word, g.symbols), "A(5)");
  EXPECT_EQ(r.steps.back().step, 2147483647);
  EXPECT_LE(r.steps.size(), 9u) << "the unchanging steps are skipped";
  // Global variables that change keep it going; stop(0) ends it.
  Grammar h = MustParse(
      "Start: {n = 0;}\nEndEach: {n = n + 1; if (n == 40) {stop(0);}}\n"
      "derivation length: 1000000\naxiom: A\nA --> A\n");
  auto rh = MustDerive(h);
  EXPECT_EQ(rh.steps.back().step, 40);
}

TEST(Deriver, StepsThatChangeTheWordHaveALimit) {
  Grammar g = MustParse("derivation length: 1000\naxiom: A(0)\nA(n) --> A(n+1)\n");
  DeriveOptions opt;
  opt.maxChangingSteps = 100;
  auto r = Derive(g, opt);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().message,
            "step 101: the word still changes after 100 steps, the most Sylva takes (steps that "
            "change nothing are free)");
  EXPECT_EQ(r.error().kind, ErrorKind::kRuntime);
  // Random draws make every step new: no skipping, the limit holds.
  Grammar s = MustParse("derivation length: 1000\naxiom: A\nA --> A : 1\nA --> A : 1\n");
  auto rs = Derive(s, opt);
  ASSERT_FALSE(rs);
}

}  // namespace
}  // namespace sylva::lsys

namespace sylva::lsys {
namespace {

// Golden hashes: the same word in every run, build and thread count. The
// parametric ones use only + - * / on doubles, which IEEE 754 makes exact
// everywhere (the build uses -ffp-contract=off, so no fused multiply-adds).
TEST(Determinism, GoldenHashesAcrossRunsAndThreadCounts) {
  struct Golden {
    const char* file;
    int steps;
    size_t size;
    uint64_t hash;
  } golden[] = {
      {"grammars/abop/fig2_06a_monopodial.lsys", 14, 114682, 0x2230fa77d61d3ad4ULL},
      {"grammars/abop/fig1_27_stochastic_plant.lsys", 8, 74656, 0x24dfd731230a49edULL},
      {"grammars/abop/fig1_31a_hogeweg_hesper.lsys", 40, 75931, 0x059466fc578d792dULL},
      {"grammars/abop/fig2_08c_ternary.lsys", 9, 177142, 0xb101ae8e86b34eb5ULL},
  };
  for (const Golden& g : golden) {
    Grammar grammar = testing::MustParse(*ReadFile(testing::SourcePath(g.file)));
    for (int threads : {1, 2, 4}) {
      DeriveOptions opt;
      opt.steps = g.steps;
      opt.threads = threads;
      auto r = testing::MustDerive(grammar, opt);
      EXPECT_EQ(r.word.size(), g.size) << g.file << " threads " << threads;
      EXPECT_EQ(HashWord(r.word), g.hash)
          << g.file << " threads " << threads << ": hash 0x" << std::hex << HashWord(r.word);
    }
  }
}

}  // namespace
}  // namespace sylva::lsys
