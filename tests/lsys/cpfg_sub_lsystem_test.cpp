// cpfg's sub-L-systems (several `lsystem:` blocks, `?(id, scale) ... $`) and
// predecessors of several modules (`A B --> C`), against hand-derived words.
#include <gtest/gtest.h>

#include <string>

#include "lsys/parser.h"
#include "lsys_test_util.h"

namespace sylva::lsys {
namespace {

using testing::DeriveText;
using testing::FirstError;
using testing::MustParse;

// Main L-system 1 and sub-L-system 2. `B` is rewritten by the block that
// owns it: outside ?(2, ..) ... $ by L-system 1 (B --> X), inside by 2.
const char* kTwoBlocks =
    "lsystem: 1\n"
    "derivation length: 2\n"
    "axiom: B A\n"
    "A --> F?(2,0.5)B$A\n"
    "B --> X\n"
    "endlsystem\n"
    "\n"
    "lsystem: 2\n"
    "axiom: B\n"
    "derivation length: 7\n"
    "B --> F[+B]B\n"
    "endlsystem\n";

TEST(SubLsystem, EachBlockRewritesOnlyItsOwnModules) {
  Grammar g = MustParse(kTwoBlocks);
  ASSERT_EQ(g.lsystems.size(), 2u);
  EXPECT_EQ(g.lsystems[1].id, 2);
  EXPECT_TRUE(g.subLsystems);
  // Step 1: B --> X (main); A --> F?(2,0.5)B$A.
  EXPECT_EQ(DeriveText(kTwoBlocks, 1), "XF?(2,0.5)B$A");
  // Step 2: the B inside ?(2,0.5)...$ is L-system 2's: F[+B]B; the `?` and
  // `$` themselves have no production; the last A grows again.
  EXPECT_EQ(DeriveText(kTwoBlocks, 2), "XF?(2,0.5)F[+B]B$F?(2,0.5)B$A");
  // The main block's derivation length (2) is the one used.
  EXPECT_EQ(DeriveText(kTwoBlocks), "XF?(2,0.5)F[+B]B$F?(2,0.5)B$A");
}

TEST(SubLsystem, DefinesBetweenBlocksAreRead) {
  // vlab's Sedge #includes each sub-L-system's file, its #defines first:
  // they come after the main block's endlsystem. They were dropped with the
  // rest of the file ("text after 'endlsystem' is ignored") and the
  // derivation then failed on an unknown sub-L-system with no location.
  const std::string text =
      "lsystem: 1\nderivation length: 2\naxiom: A\nA --> ?(2,1)B$\nendlsystem\n"
      "#define WIDTH .05\n#define LENGTH 2\n"
      "lsystem: 2\nderivation length: 2\naxiom: B\nB --> f(WIDTH)F(LENGTH)\nendlsystem\n";
  Grammar g = MustParse(text);
  ASSERT_EQ(g.lsystems.size(), 2u);
  EXPECT_EQ(DeriveText(text, 2), "?(2,1)f(0.05)F(2)$");
}

TEST(SubLsystem, QuestionModuleBelongsToTheOuterBlockAndDollarToTheInner) {
  // cpfg switches L-system after the `?(..)` module is rewritten and after
  // the `$` is: so `?` is rewritten by the enclosing block, `$` by the sub.
  const std::string text =
      "lsystem: 0\naxiom: ?(3,1)$\n"
      "?(i,s) --> M?(i,s)\n$ --> N$\nendlsystem\n"
      "lsystem: 3\naxiom: Q\n$ --> S$\n?(i,s) --> T\nendlsystem\n";
  EXPECT_EQ(DeriveText(text, 1), "M?(3,1)S$");
  EXPECT_EQ(DeriveText(text, 2), "MM?(3,1)SS$");
}

TEST(SubLsystem, NestedSubLsystemsAndContextInTheirOwnBlock) {
  // 1 inside 0, 2 inside 1; each block's `A` rule differs; block 2 has a
  // context rule with its own ignore: list.
  const std::string text =
      "lsystem: 0\naxiom: A?(1)A?(2)C+A$A$A\nA --> a\nendlsystem\n"
      "lsystem: 1\naxiom: A\nA --> b\nendlsystem\n"
      "lsystem: 2\naxiom: A\nignore: +\nC < A --> c\nA --> d\nendlsystem\n";
  EXPECT_EQ(DeriveText(text, 1), "a?(1)b?(2)C+c$b$a");
}

TEST(SubLsystem, UnknownComputedNumberIsARunTimeError) {
  // A constant number is checked where it is written
  // (CpfgSubLsystems.UnknownConstantIdIsAnErrorWhereItIsWritten); one
  // computed while deriving, when the step meets it.
  Grammar g = MustParse(
      "lsystem: 1\naxiom: A(5)\nA(x) --> ?(x,1)F$\nendlsystem\nlsystem: 2\naxiom: F\n"
      "endlsystem\n");
  DeriveOptions o;
  o.steps = 2;
  auto r = Derive(g, o);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().message,
            "step 2: module 0, '?(5, ...)', starts sub-L-system 5, but the file's 'lsystem:' "
            "blocks are numbered 1, 2");
}

TEST(SubLsystem, HeaderErrorsHaveLocations) {
  EXPECT_EQ(FirstError("lsystem: 1\naxiom: F\nlsystem: 2\naxiom: G\nendlsystem\n"),
            "3:1 a second 'lsystem:' inside an L-system: end the first with 'endlsystem' before "
            "a sub-L-system starts");
  EXPECT_EQ(FirstError("lsystem: 1\naxiom: F\nendlsystem\nlsystem: 2\nangle: 30\naxiom: G\n"
                       "endlsystem\n"),
            "5:1 'angle:' belongs to the main L-system (the first 'lsystem:' block), not to a "
            "sub-L-system");
  EXPECT_EQ(FirstError("lsystem: 1\naxiom: F\nendlsystem\nlsystem: 1.5\naxiom: G\nendlsystem\n"),
            "4:1 two L-systems numbered 1 (the other at line 1): ?(id, scale) could not tell "
            "them apart");
  // Found by fuzz_grammar: a label beyond int's range was converted anyway (UB).
  EXPECT_EQ(FirstError("lsystem: 1\naxiom: F\nendlsystem\nlsystem: 1e123\naxiom: G\nendlsystem\n"),
            "4:1 L-system label '1e123' is a number out of range");
  EXPECT_EQ(FirstError("lsystem: 1e123\naxiom: F\nendlsystem\n"),
            "1:1 L-system label '1e123' is a number out of range");
}

TEST(SubLsystem, DefinesOfALaterBlockAreRead) {
  // cpfg runs the C preprocessor over the whole file.
  EXPECT_EQ(DeriveText("#define N 1\nlsystem: 1\naxiom: ?(2)A(N)$\nendlsystem\n"
                       "lsystem: 2\n#define M 3\naxiom: A(0)\nA(x) --> A(x+M)\nendlsystem\n",
                       1),
            "?(2)A(4)$");
}

TEST(SubLsystem, DollarWithParametersWarnsThatItOnlyEnds) {
  // Seen in real files as a start, $(2, s); cpfg's source ends a
  // sub-L-system at any $ and starts one only at ?(id, s).
  ParseResult r = ParseGrammarText(
      "lsystem: 1\naxiom: $(2)C$\nendlsystem\nlsystem: 2\naxiom: C\nendlsystem\n", "c.l");
  ASSERT_TRUE(r.grammar) << r.diagnostics.FormatAll();
  // ('$' is used with 1 parameter and with 0, but no production names '$':
  // no warning about the two counts.)
  ASSERT_EQ(r.diagnostics.items.size(), 1u) << r.diagnostics.FormatAll();
  EXPECT_EQ(r.diagnostics.items[0].loc.line, 2);
  EXPECT_EQ(r.diagnostics.items[0].loc.column, 8);
  EXPECT_EQ(r.diagnostics.items[0].message.rfind(
                "'$' takes no parameters; here it has 1 parameter, ignored", 0),
            0u)
      << r.diagnostics.items[0].message;
}

TEST(SubLsystem, SeedOfASubLsystemWarns) {
  ParseResult r = ParseGrammarText(
      "lsystem: 1\naxiom: F\nendlsystem\nlsystem: 2\nseed: 4\naxiom: G\nendlsystem\n", "c.l");
  ASSERT_TRUE(r.grammar) << r.diagnostics.FormatAll();
  ASSERT_EQ(r.diagnostics.items.size(), 1u) << r.diagnostics.FormatAll();
  EXPECT_EQ(r.diagnostics.items[0].loc.line, 5);
  EXPECT_EQ(r.diagnostics.items[0].severity, Severity::kWarning);
}

// ---------------------------------------------------------------------------
// Predecessors of several modules (cpfg's strict predecessor)

TEST(MultiModulePredecessor, ReplacesConsecutiveModulesLeftToRight) {
  // A B matches at 0 and 3; the B it takes is not rewritten again (B --> Y
  // would apply to a lone B); the scan goes on after the match.
  EXPECT_EQ(DeriveText("axiom: A B C A B B\nA B --> X\nB --> Y\n", 1), "XCXY");
  // Overlap: in A A A, "A A" matches at 0, then the third A alone.
  EXPECT_EQ(DeriveText("axiom: A A A\nA A --> P\nA --> Q\n", 1), "PQ");
  // No skipping: brackets or other modules between break the match.
  EXPECT_EQ(DeriveText("axiom: A[F]B A F B\nA B --> X\n", 1), "A[F]BAFB");
}

TEST(MultiModulePredecessor, BindsEveryParameterAndReadsContextAroundIt) {
  EXPECT_EQ(DeriveText("axiom: A(1)B(2)A(3)B(4)\nA(x) B(y) : x > 2 --> C(x+y)\n", 1),
            "A(1)B(2)C(7)");
  // Left context before the first module, right context after the last.
  EXPECT_EQ(DeriveText("axiom: D(5)A B C(7) A B\nD(d) < A B > C(c) --> E(d*c)\n", 1),
            "D(5)E(35)C(7)AB");
  // cpfg's left context of several modules.
  EXPECT_EQ(DeriveText("axiom: A B C A C\nA B < C --> Z\n", 1), "ABZAC");
}

TEST(MultiModulePredecessor, FileOrderDecidesAgainstASingleModuleRule) {
  EXPECT_EQ(DeriveText("axiom: A B\nA --> Q\nA B --> X\n", 1), "QB");
  EXPECT_EQ(DeriveText("axiom: A B\nA B --> X\nA --> Q\n", 1), "X");
}

TEST(MultiModulePredecessor, SameWordWithAnyThreadCount) {
  std::string axiom;
  for (int i = 0; i < 40000; ++i) axiom += "AB";
  const std::string text = "axiom: " + axiom + "\nA B --> BA\nB A --> C\n";
  DeriveOptions one, four;
  one.threads = 1;
  four.threads = 4;
  // Step 1: every A B --> BA; step 2: every B A --> C.
  const std::string a = DeriveText(text, 1, one), b = DeriveText(text, 1, four);
  EXPECT_EQ(a, b);
  EXPECT_EQ(a.size(), 80000u);
  EXPECT_EQ(a.substr(0, 6), "BABABA");
  EXPECT_EQ(DeriveText(text, 2, four), std::string(40000, 'C'));
}

TEST(MultiModulePredecessor, BracketsCannotBePartOfIt) {
  EXPECT_EQ(FirstError("axiom: A\nA [ --> B\n"),
            "2:3 '[' cannot be rewritten without its ']': a predecessor holds brackets only "
            "in balanced pairs");
  EXPECT_EQ(FirstError("axiom: A\nA * --> B\n"),
            "2:3 '*' cannot be (part of) a predecessor: it stands alone as a context");
}

}  // namespace
}  // namespace sylva::lsys

namespace sylva::lsys {
namespace {

TEST(SubLsystem, ExampleFileDerivesAsWrittenByHand) {
  const std::string path = testing::SourcePath("grammars/cpfg/sub_lsystem.l");
  ParseResult r = ParseGrammarFile(path);
  ASSERT_TRUE(r.grammar) << r.diagnostics.FormatAll();
  EXPECT_TRUE(r.diagnostics.items.empty()) << r.diagnostics.FormatAll();  // --strict clean
  DeriveOptions o;
  o.steps = 2;
  auto w = Derive(*r.grammar, o);
  ASSERT_TRUE(w);
  const std::string bud = "?(2,0.5);(1)!(0.2)";
  EXPECT_EQ(FormatWord(w->word, r.grammar->symbols),
            "!(0.12)F(1.12)[+(50)" + bud + "F(0.6)[+(30)L][-(30)L]S$][-(50)" + bud +
                "F(0.6)[+(30)L][-(30)L]S$]/(137.5)F(1)[+(50)" + bud + "S$][-(50)" + bud +
                "S$]/(137.5)A(2)");
  // Step 3: the main L-system lengthens its F; L-system 2's F(0.6) stays
  // and its L becomes F(0.4).
  o.steps = 3;
  auto w3 = Derive(*r.grammar, o);
  ASSERT_TRUE(w3);
  const std::string s3 = FormatWord(w3->word, r.grammar->symbols);
  EXPECT_EQ(s3.rfind("!(0.12)F(1.2544)[+(50)" + bud + "F(0.6)[+(30)F(0.4)][-(30)F(0.4)]F(0.6)", 0),
            0u)
      << s3;
}

}  // namespace
}  // namespace sylva::lsys
