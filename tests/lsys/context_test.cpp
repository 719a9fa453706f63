// Context matching on the branching structure (ABOP section 1.8).
#include <gtest/gtest.h>

#include "lsys_test_util.h"

namespace sylva::lsys {
namespace {

using testing::DeriveText;

std::string Step(const std::string& axiom, const std::string& productions) {
  return DeriveText("axiom: " + axiom + "\n" + productions + "\n", 1);
}

TEST(Context, LeftContextSkipsCompleteSiblingBranches) {
  EXPECT_EQ(Step("A[B][D]C", "A < C --> X"), "A[B][D]X");
}

TEST(Context, LeftContextStepsOutOfTheEnclosingBranch) {
  EXPECT_EQ(Step("A[B[C]]", "A < C --> X\nA < B --> Y"), "A[Y[C]]");
  EXPECT_EQ(Step("A[B[C]]", "B < C --> X"), "A[B[X]]");
}

TEST(Context, LeftContextDoesNotLookInsideSiblingBranches) {
  EXPECT_EQ(Step("A[B]C", "B < C --> X"), "A[B]C");
}

TEST(Context, RightContextSkipsSiblingBranchesItDoesNotName) {
  EXPECT_EQ(Step("A[B][D]C", "A > C --> X"), "X[B][D]C");
}

TEST(Context, RightContextDescendsIntoBranchesItNames) {
  EXPECT_EQ(Step("A[B]C", "A > [B]C --> X"), "X[B]C");
  EXPECT_EQ(Step("A[B]C", "A > [B]D --> X"), "A[B]C");
  EXPECT_EQ(Step("A[BE]C", "A > [B]C --> X"), "X[BE]C");  // `]` skips the rest of the branch
}

TEST(Context, RightContextNeverLeavesTheCurrentBranch) {
  EXPECT_EQ(Step("[A]B", "A > B --> X"), "[A]B");
}

TEST(Context, IgnoredSymbolsAreSkippedBothWays) {
  EXPECT_EQ(DeriveText("ignore: +-F\naxiom: 0F+F1\n0 > 1 --> X\n1 --> 1\n", 1), "XF+F1");
  EXPECT_EQ(DeriveText("ignore: +-F\naxiom: 0F-[+F1]\n0 < 1 --> X\n", 1), "0F-[+FX]");
}

TEST(Context, ConsiderListsTheOnlySymbolsSeen) {
  EXPECT_EQ(DeriveText("consider: AB\naxiom: AxyzB\nA > B --> X\nB --> B\n", 1), "XxyzB");
  EXPECT_EQ(DeriveText("consider: AB\naxiom: AxyzC\nA > C --> X\n", 1), "AxyzC");
}

TEST(Context, ContextModulesBindTheirParameters) {
  EXPECT_EQ(Step("A(1)B(2)C(3)", "A(a) < B(b) > C(c) --> B(a+b*10+c*100)"), "A(1)B(321)C(3)");
}

TEST(Context, MultiModuleContexts) {
  EXPECT_EQ(Step("ABCDE", "AB < C > DE --> X"), "ABXDE");
  EXPECT_EQ(Step("ABCDE", "BB < C --> X"), "ABCDE");
}

TEST(Context, StarMeansNoContext) {
  EXPECT_EQ(Step("+A-", "* < + > * --> -\n* < - > * --> +"), "-A+");
}

TEST(Context, NoContextAtTheWordsEnds) {
  EXPECT_EQ(Step("A", "B < A --> X\nA > B --> Y"), "A");
}

TEST(Context, SignalTravelsOneModulePerStepAcrossBranches) {
  // An acropetal signal (ABOP eq. 1.8 style): S moves from parent to child.
  const char* g = "ignore: F+-\naxiom: SA[+A]A\nS < A --> S\nS --> A\nderivation length: 1\n";
  EXPECT_EQ(DeriveText(g, 1), "AS[+A]A");
  EXPECT_EQ(DeriveText(g, 2), "AA[+S]S");
  EXPECT_EQ(DeriveText(g, 3), "AA[+A]A");
}

}  // namespace
}  // namespace sylva::lsys

namespace sylva::lsys {
namespace {

TEST(BracketMatch, ParallelMatchEqualsSequentialOnDeepWords) {
  // A word deep enough that brackets span many chunks: a context-sensitive
  // grammar on it must give the same word with 1 and 4 threads.
  Grammar g = testing::MustParse(R"(
axiom: A
A --> [BA]
B < B --> C
B > [C] --> E
C --> B
)");
  DeriveOptions opt;
  opt.steps = 12000;
  opt.threads = 1;
  auto a = testing::MustDerive(g, opt);
  opt.threads = 4;
  auto b = testing::MustDerive(g, opt);
  EXPECT_EQ(a.word.size(), 3u * 12000 + 1);
  EXPECT_EQ(HashWord(a.word), HashWord(b.word));
}

}  // namespace
}  // namespace sylva::lsys
