// cpfg's srand(seed) outside Start:, stop(v), and blocks over several lines
// (`define: {` ... `}`, `Start: {srand(1);` ... `}`), as vlab's objects
// write them (paintbrush, two-trees, lilac-congo).
#include <gtest/gtest.h>

#include "lsys_test_util.h"

namespace sylva::lsys {
namespace {

using testing::DeriveText;
using testing::FirstError;
using testing::MustParse;

// Eight A's, each B or C at random; S calls srand(7) when rewritten.
const char* kRules = "A --> B : 1\nA --> C : 1\n";

TEST(CpfgSrand, InAProductionReseedsTheModulesAfterIt) {
  const std::string reseed = "S : {srand(7);} * --> S\n";
  const std::string after = DeriveText("axiom: S A A A A A A A A\n" + reseed + kRules, 1);
  // The A's after S are drawn as with `seed: 7` from the start.
  EXPECT_EQ(after, DeriveText("seed: 7\naxiom: S A A A A A A A A\n" + std::string(kRules), 1));
  EXPECT_NE(after, DeriveText("seed: 8\naxiom: S A A A A A A A A\n" + std::string(kRules), 1));
  // The A's before S keep the grammar's seed (1), those after take 7.
  const std::string mixed = DeriveText("axiom: A A A A S A A A A\n" + reseed + kRules, 1);
  const std::string seed1 = DeriveText("axiom: A A A A S A A A A\n" + std::string(kRules), 1);
  const std::string seed7 =
      DeriveText("seed: 7\naxiom: A A A A S A A A A\n" + std::string(kRules), 1);
  ASSERT_EQ(mixed.size(), 9u) << mixed;
  EXPECT_EQ(mixed.substr(0, 4), seed1.substr(0, 4)) << mixed << " " << seed1;
  EXPECT_EQ(mixed.substr(5), seed7.substr(5)) << mixed << " " << seed7;
  EXPECT_NE(seed1.substr(5), seed7.substr(5)) << "the seed must matter here";
}

TEST(CpfgSrand, InTheHomomorphismReseedsTheDrawing) {
  // paintbrush plant.l: `E : 1 {srand(1);} --> *` first in the word makes
  // every drawing take its random numbers from seed 1.
  const std::string rules = "axiom: E A A A\nA --> A\ninterpretation:\n";
  Grammar withSrand = MustParse(rules + "E : 1 {srand(5);} --> *\nA --> F(ran(1))\n");
  Grammar seed5 = MustParse("seed: 5\n" + rules + "E --> *\nA --> F(ran(1))\n");
  Grammar seed1 = MustParse(rules + "E --> *\nA --> F(ran(1))\n");
  auto text = [](const Grammar& g) {
    auto w = Interpret(g, testing::MustDerive(g).word);
    return w ? FormatWord(*w, g.symbols) : std::string("<error>");
  };
  EXPECT_EQ(text(withSrand), text(seed5));
  EXPECT_NE(text(withSrand), text(seed1));
}

TEST(CpfgSrand, InStartEachReseedsTheStep) {
  const std::string rules = "axiom: A A A A A A A A\n" + std::string(kRules);
  EXPECT_EQ(DeriveText("StartEach: {srand(7);}\n" + rules, 1), DeriveText("seed: 7\n" + rules, 1));
}

TEST(CpfgSrand, OnlyAsAStatement) {
  EXPECT_EQ(FirstError("axiom: A\nA --> B(srand(1))\n"),
            "2:9 cpfg function 'srand' is not supported by Sylva");
}

// --- stop(v) ---

const char* kCounter =
    "Start: {n = 0;}\nStartEach: {n = n + 1;}\nderivation length: 10\naxiom: A\nA --> AB\n";

TEST(CpfgStop, EndsTheDerivationAfterTheStep) {
  EXPECT_EQ(DeriveText(std::string(kCounter) + "EndEach: {if (n == 3) {stop(0);}}\n"), "ABBB");
  // A step count asked for does not go past it either.
  EXPECT_EQ(DeriveText(std::string(kCounter) + "EndEach: {if (n == 3) {stop(2);}}\n", 6), "ABBB");
}

TEST(CpfgStop, OneMeansRunOn) {
  // cpfg: stop(1) sets its animation to "run".
  EXPECT_EQ(DeriveText(std::string(kCounter) + "EndEach: {if (n == 3) {stop(1);}}\n"),
            "A" + std::string(10, 'B'));
}

TEST(CpfgStop, InAProductionEndsAtThatStep) {
  // B first appears in step 1 and is rewritten in step 2, which calls stop.
  EXPECT_EQ(DeriveText(std::string(kCounter) + "B : {stop(0);} * --> B\n"), "ABB");
}

TEST(CpfgStop, InStartLeavesTheAxiom) {
  EXPECT_EQ(DeriveText("Start: {stop(0);}\nderivation length: 4\naxiom: A\nA --> AB\n"), "A");
}

// --- blocks over several lines ---

TEST(CpfgBlocks, DefineBlockClosedOnALaterLine) {
  // lilac-congo plant.l: `Define: { array a[N], b[M];` / `\t}`.
  EXPECT_EQ(DeriveText("#define N 2\nDefine: { array a[N],\n\tb[3];\n\t}\n"
                       "Start: {a[1] = 5; b[2] = 7;}\naxiom: A(a[1] + b[2])\n",
                       0),
            "A(12)");
}

TEST(CpfgBlocks, StartBlockOpenedByACall) {
  // paintbrush.field plant.l: `Start: {srand(1);` with an assignment over
  // two lines and the `}` alone on the last.
  EXPECT_EQ(DeriveText("Start: {srand(1);\n\tdx0 =\n\t2 * 3;\n}\naxiom: A(dx0)\n", 0), "A(6)");
}

// --- decompositions thousands deep, text parameters ---

TEST(CpfgDecomposition, ThousandsOfPassesDeep) {
  // self-thinning tree.l: `maximum depth: 15000`, one plant made a pass.
  Grammar g = MustParse(
      "axiom: X(3000)\nderivation length: 1\ndecomposition:\nmaximum depth: 15000\n"
      "X(n) : n > 0 --> [P] X(n-1)\n");
  EXPECT_EQ(g.decomposition.maxDepth, 15000);
  const Word w = testing::MustDerive(g).word;
  EXPECT_EQ(w.size(), 3u * 3000 + 1) << "3000 branches [P] and X(0)";
  EXPECT_EQ(FirstError("axiom: A\ndecomposition:\nmaximum depth: 100001\n"),
            "3:16 maximum depth must be a whole number from 1 to 100000");
}

TEST(CpfgText, TextParameterIsTheNumberOfTheText) {
  // simple-alpha, equilibrium: `@L("%.0f", n)` labels.
  ParseResult r = ParseGrammarText("axiom: @L(\"a\") @L(\"b\", 2) @L(\"a\") A(\"b\")\n", "c.l", {});
  ASSERT_TRUE(r.grammar) << r.diagnostics.FormatAll();
  EXPECT_EQ(FormatWord(testing::MustDerive(*r.grammar).word, r.grammar->symbols),
            "@L(0)@L(1,2)@L(0)A(1)");
  EXPECT_EQ(r.grammar->strings, (std::vector<std::string>{"a", "b"}));
  // @L is drawn (by the turtle and `sylva render`), no warning; A warns
  // that its text is a number.
  const std::string all = r.diagnostics.FormatAll();
  EXPECT_EQ(all.find("'@L'"), std::string::npos) << all;
  EXPECT_NE(all.find("c.l:1:37: warning: a text parameter of 'A' is read as the number of the "
                     "text (1), as cpfg does"),
            std::string::npos)
      << all;
  EXPECT_EQ(FirstError("axiom: @L(\"a)\n"), "1:11 unclosed '\"' in parameters of '@L'");
}

}  // namespace
}  // namespace sylva::lsys
