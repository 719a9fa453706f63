// cpfg's forms of contexts and predecessors that follow its string matcher
// (vlab `cpfg/generate.c`: PredDiff, RconDiff, skipright, LconDiff): `=` in
// a right context, predecessors holding branches, brackets in ignore: and
// consider:. Each case is derived by hand from cpfg's rules.
#include <gtest/gtest.h>

#include "lsys_test_util.h"

namespace sylva::lsys {
namespace {

using testing::DeriveText;
using testing::FirstError;

// --- `=`: the rest of the current branch ---

TEST(CpfgContext, EqualsSkipsTheRestOfANamedBranch) {
  // A's right context is the branch that starts with B, whatever follows B
  // in it, then C after the branch.
  EXPECT_EQ(DeriveText("axiom: A[BDE]C\nA > [B=]C --> X\n", 1), "X[BDE]C");
  // The first module of the branch must be B.
  EXPECT_EQ(DeriveText("axiom: A[DBE]C\nA > [B=]C --> X\n", 1), "A[DBE]C");
  // And C must follow the branch.
  EXPECT_EQ(DeriveText("axiom: A[BDE]DC\nA > [B=]C --> X\n", 1), "A[BDE]DC");
}

TEST(CpfgContext, EqualsBindsTheModulesAroundIt) {
  // cpfg's pipe model (tree-shedding plant.l): the branch's first ! and the
  // ! after the branch.
  EXPECT_EQ(DeriveText("axiom: !(1)[!(2)F!(7)]!(3)\n"
                       "!(a) > [!(b)=]!(c) --> !(a+10*b+100*c)\n"
                       "!(a) --> !(a)\n",
                       1),
            "!(321)[!(2)F!(7)]!(3)");
}

TEST(CpfgContext, EqualsAtTheEndOfTheContextMatchesAnyRest) {
  // topiary-2d: `F(n) > [Signal=] --> Signal F(n)`.
  EXPECT_EQ(DeriveText("axiom: F(1)[JFF]F(2)\nF(n) > [J=] --> J F(n)\n", 1), "JF(1)[JFF]F(2)");
}

TEST(CpfgContext, CloseBracketWithoutItsOpenLeavesTheBranch) {
  // caterpillar: `* < 4 > F=]g --> 5`: F, the rest of the branch, its `]`,
  // then g in the parent.
  EXPECT_EQ(DeriveText("axiom: A[4FFF]g\n4 > F=]g --> 5\n", 1), "A[5FFF]g");
  EXPECT_EQ(DeriveText("axiom: A[4FFF]h\n4 > F=]g --> 5\n", 1), "A[4FFF]h");
  // The main axis has no enclosing `]`: no match.
  EXPECT_EQ(DeriveText("axiom: 4Fg\n4 > F=]g --> 5\n", 1), "4Fg");
}

TEST(CpfgContext, EqualsIsAModuleOutsideARightContext) {
  EXPECT_EQ(DeriveText("axiom: A=B\n= --> C\nA < C --> D\n", 1), "ACB");
  EXPECT_EQ(FirstError("axiom: A\nA > [B=(x)] --> C\n"),
            "2:7 '=' in a right context (the rest of the branch) takes no parameters");
}

// --- predecessors that hold branches ---

TEST(CpfgContext, BracketedPredecessorRewritesAWholeBranch) {
  // self-thinning tree.l: a plant is a branch [f f P ?E]; it is rewritten
  // as a whole, its modules matched one by one.
  const std::string g =
      "axiom: X[f(1)-f(2)P(3,0)]Y[f(4)-f(5)P(6,1)]\n"
      "[f(y)-f(z)P(r,s)] : s==0 --> [f(y)-f(z)P(r*2,s)]\n"
      "[f(y)-f(z)P(r,s)] : s==1 --> *\n";
  EXPECT_EQ(DeriveText(g, 1), "X[f(1)-f(2)P(6,0)]Y");
  // A branch that does not hold exactly those modules is left alone.
  EXPECT_EQ(DeriveText("axiom: [f(1)-f(2)G P(3,0)]\n[f(y)-f(z)P(r,s)] --> *\n", 1),
            "[f(1)-f(2)GP(3,0)]");
}

TEST(CpfgContext, PredecessorBeginningWithOtherModulesHoldsNestedBranches) {
  // sfplant plant.l: `,,[-F[F]] ;; --> Z` matched module for module.
  EXPECT_EQ(DeriveText("axiom: A,,[-F[F]];;B\n,,[-F[F]];; --> Z\n", 1), "AZB");
  EXPECT_EQ(DeriveText("axiom: A,,[-F[F]F];;B\n,,[-F[F]];; --> Z\n", 1), "A,,[-F[F]F];;B");
}

TEST(CpfgContext, PredecessorBracketsMustPair) {
  EXPECT_EQ(FirstError("axiom: A\nA ] --> B\n"),
            "2:3 ']' cannot be rewritten without its '[': a predecessor holds brackets only in "
            "balanced pairs");
  EXPECT_EQ(FirstError("axiom: A\n[ A --> B\n"),
            "2:1 '[' cannot be rewritten without its ']': a predecessor holds brackets only in "
            "balanced pairs");
}

// --- brackets in ignore: and consider: ---

TEST(CpfgContext, IgnoredOpenBracketLetsTheRightContextReadIntoBranches) {
  // caterpillar's `ignore: [+-`: the right context of A reads B inside
  // the branch.
  EXPECT_EQ(DeriveText("ignore: [\naxiom: A[B]C\nA > B --> X\n", 1), "X[B]C");
  // Without it the branch is skipped and C follows A.
  EXPECT_EQ(DeriveText("axiom: A[B]C\nA > B --> X\n", 1), "A[B]C");
  EXPECT_EQ(DeriveText("axiom: A[B]C\nA > C --> X\n", 1), "X[B]C");
  // The `]` is not ignored: it ends the context (cpfg compares it).
  EXPECT_EQ(DeriveText("ignore: [\naxiom: A[B]C\nA > BC --> X\n", 1), "A[B]C");
  // Both ignored: the word reads as if flat.
  EXPECT_EQ(DeriveText("ignore: []\naxiom: A[B]C\nA > BC --> X\n", 1), "X[B]C");
}

TEST(CpfgContext, IgnoredBracketsLeaveTheLeftContextOnTheBranching) {
  // cpfg's LconDiff steps over branches before it looks at ignore:.
  EXPECT_EQ(DeriveText("ignore: []\naxiom: A[B]C\nB < C --> X\n", 1), "A[B]C");
  EXPECT_EQ(DeriveText("ignore: []\naxiom: A[B]C\nA < C --> X\n", 1), "A[B]X");
}

TEST(CpfgContext, ConsiderWithoutBracketsReadsTheRightContextFlat) {
  // cpfg's consider: ignores every module it does not name, brackets too.
  EXPECT_EQ(DeriveText("consider: AB\naxiom: A[xB]C\nA > B --> X\n", 1), "X[xB]C");
  // Named, the brackets keep the branching: B is inside a sibling branch.
  EXPECT_EQ(DeriveText("consider: AB[]\naxiom: A[xB]C\nA > B --> X\n", 1), "A[xB]C");
}

// --- `ring lsystem`: the word is a ring ---

TEST(CpfgRing, LastModuleIsTheFirstOnesLeftNeighbour) {
  // B is first: its left neighbour is the last module, A, only in a ring.
  const std::string g = "axiom: B C D A\nA < B --> X\nA > B --> Y\n";
  EXPECT_EQ(DeriveText(g, 1), "BCDA");
  EXPECT_EQ(DeriveText("ring lsystem\n" + g, 1), "XCDY");
  // Vlab's Ring/ring.l with dir 1: B > A passes A leftwards, round the end.
  const std::string ring = "ring lsystem\naxiom: A B B B\nB > A : 1 --> A\nA --> B\n";
  EXPECT_EQ(DeriveText(ring, 1), "BBBA");
  EXPECT_EQ(DeriveText(ring, 2), "BBAB");
}

TEST(CpfgRing, SecondRingStatementIsAWarning) {
  ParseResult r = ParseGrammarText("ring lsystem\naxiom: A\nRing  lsystem\n", "c.l");
  ASSERT_TRUE(r.grammar) << r.diagnostics.FormatAll();
  EXPECT_TRUE(r.grammar->ring);
  ASSERT_EQ(r.diagnostics.items.size(), 1u) << r.diagnostics.FormatAll();
  const Diagnostic& d = r.diagnostics.items[0];
  EXPECT_EQ(d.severity, Severity::kWarning);
  EXPECT_EQ(std::to_string(d.loc.line) + ":" + std::to_string(d.loc.column) + " " + d.message,
            "3:1 second 'ring lsystem' (the first is at line 1): it changes nothing");
}

TEST(CpfgRing, ContextsWrapOnceAndSkipIgnoredModules) {
  // Ignored modules are passed over across the seam; a context longer than
  // the word reads the ring round again, one module at a time.
  EXPECT_EQ(DeriveText("ring lsystem\nignore: f\naxiom: B f C f\nC < B --> X\n", 1), "XfCf");
  EXPECT_EQ(DeriveText("ring lsystem\naxiom: A\nA < A > A --> Z\n", 1), "Z");
  // A word of ignored modules only: no context, no hang.
  EXPECT_EQ(DeriveText("ring lsystem\nignore: f\naxiom: f f\nA < f --> Z\nf > A --> Z\n", 1), "ff");
  // The right context steps into a branch at the start of the word.
  EXPECT_EQ(DeriveText("ring lsystem\naxiom: [C] B A\nA > [C] --> Y\n", 1), "[C]BY");
}

}  // namespace
}  // namespace sylva::lsys
