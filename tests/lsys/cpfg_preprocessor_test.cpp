// The preprocessor's conditionals in cpfg files: #if, #ifdef, #ifndef,
// #elif, #else, #endif (docs/cpfg.md).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "lsys/parser.h"
#include "lsys_test_util.h"

namespace sylva::lsys {
namespace {

using testing::FirstError;
using testing::Joined;

using testing::DeriveText;

const char* kFile =
    "#define TWO\n"
    "#define N 3\n"
    "#ifdef TWO\n"
    "#define K 2\n"
    "#else\n"
    "#define K 1\n"
    "#endif\n"
    "#ifndef TWO\n"
    "axiom: X\n"
    "#elif N > 2 && defined(TWO)\n"
    "axiom: A(K, N)\n"
    "#else\n"
    "axiom: Y(K)\n"
    "#endif\n"
    "#if 0\n"
    "  #if 1\n"
    "  this line is not read\n"
    "  #endif\n"
    "#endif\n";

TEST(CpfgPreprocessor, TakesTheBranchesThatHold) {
  EXPECT_EQ(DeriveText(kFile, 0), "A(2,3)");
}

TEST(CpfgPreprocessor, ConditionsSeeCommandLineOverrides) {
  ParseOptions opt;
  opt.overrides["N"] = 1;
  ParseResult r = ParseGrammarText(kFile, "c.l", opt);
  ASSERT_TRUE(r.grammar) << r.diagnostics.FormatAll();
  DeriveOptions d;
  d.steps = 0;
  auto w = Derive(*r.grammar, d);
  ASSERT_TRUE(w);
  EXPECT_EQ(FormatWord(w->word, r.grammar->symbols), "Y(2)");
}

TEST(CpfgPreprocessor, DefinesAfterEndlsystemAreNotRead) {
  // Text after `endlsystem` that is not another `lsystem:` block is not
  // read (it is warned about), its #defines included.
  ParseResult r =
      ParseGrammarText("#define N 1\naxiom: A(N)\nendlsystem\n#define N 2\nB --> C\n", "c.l");
  ASSERT_TRUE(r.grammar) << r.diagnostics.FormatAll();
  DeriveOptions d;
  d.steps = 0;
  auto w = Derive(*r.grammar, d);
  ASSERT_TRUE(w);
  EXPECT_EQ(FormatWord(w->word, r.grammar->symbols), "A(1)");
}

// A parse of a cpfg file that must succeed; its warnings as "line:col message".
std::vector<std::string> Warnings(const std::string& text, const ParseOptions& opt = {}) {
  ParseResult r = ParseGrammarText(text, "c.l", opt);
  EXPECT_TRUE(r.grammar) << r.diagnostics.FormatAll();
  std::vector<std::string> w;
  for (const auto& d : r.diagnostics.items)
    if (d.severity == Severity::kWarning)
      w.push_back(std::to_string(d.loc.line) + ":" + std::to_string(d.loc.column) + " " +
                  d.message);
  return w;
}

std::string DeriveCpfg(const std::string& text, int steps, const ParseOptions& opt = {}) {
  ParseResult r = ParseGrammarText(text, "c.l", opt);
  if (!r.grammar) return r.diagnostics.FormatAll();
  DeriveOptions d;
  d.steps = steps;
  auto w = Derive(*r.grammar, d);
  if (!w) return w.error().Format();
  return FormatWord(w->word, r.grammar->symbols);
}

TEST(CpfgPreprocessor, RedefinedNameHoldsFromItsLaterDefinitionWithAWarning) {
  // C's preprocessor (cpfg's): a line between the two #defines reads the
  // first, a line after them the second (corpus3's cloud_I(C2) defines
  // ang2 twice).
  const char* text =
      "#define N 1\n"
      "axiom: A(N)\n"
      "#define N  2\n"
      "A(x) --> B(x, N)\n";
  EXPECT_EQ(DeriveCpfg(text, 1), "B(1,2)");
  const auto w = Warnings(text);
  ASSERT_FALSE(w.empty());
  EXPECT_EQ(w[0],
            "3:9 'N' redefined: this definition holds from here on, as cpfg's C preprocessor has "
            "it (the first is at c.l:1:9)")
      << Joined(w);
}

TEST(CpfgPreprocessor, SameRedefinitionIsNoWarning) {
  // As in C: the same text again (blanks aside) is no redefinition.
  const auto w = Warnings("#define N 1 +  2\n#define N 1 + 2\naxiom: A(N)\n");
  EXPECT_TRUE(w.empty()) << Joined(w);
  EXPECT_EQ(DeriveCpfg("#define N 1 +  2\n#define N 1 + 2\naxiom: A(N)\n", 0), "A(3)");
}

TEST(CpfgPreprocessor, RedefinedNamesReachConditionsMacrosAndOverrides) {
  // #if sees the definition above it; a #define naming a redefined one reads
  // it where it is used; so does a function-like #define redefined.
  EXPECT_EQ(
      DeriveCpfg("#define N 1\n#define N 3\n#if N > 2\naxiom: A\n#else\naxiom: B\n#endif\n", 0),
      "A");
  EXPECT_EQ(
      DeriveCpfg("#define N 1\n#define M (N * 10)\naxiom: A(M)\n#define N 2\nA(x) --> B(M)\n", 1),
      "B(20)");
  EXPECT_EQ(DeriveCpfg("#define f(x) (x + 1)\naxiom: A(f(1))\n#define f(x) (x * 10)\n"
                       "A(y) --> B(y, f(y))\n",
                       1),
            "B(2,20)");
  // -D replaces the value of each #define of the name.
  ParseOptions opt;
  opt.overrides["N"] = 7;
  EXPECT_EQ(DeriveCpfg("#define N 1\naxiom: A(N)\n#define N 2\nA(x) --> B(x, N)\n", 1, opt),
            "B(7,7)");
  // The same file as .lsys: an error at the second #define.
  EXPECT_EQ(FirstError("#define N 1\naxiom: A(N)\n#define N 2\n", "c.lsys"),
            "3:9 redefinition of 'N' (first defined at line 1)");
}

TEST(CpfgPreprocessor, UndefOfANumberHoldsFromThere) {
  EXPECT_EQ(DeriveCpfg("#define N 2\naxiom: A(N)\n#undef N\n#define N 3\nA(x) --> B(x, N)\n", 1),
            "B(2,3)");
}

TEST(CpfgBrackets, UnbalancedSuccessorIsOneWarningInACpfgFile) {
  // corpus3's dynamic4: `... SYM(...)]]]` with one `]` too many. cpfg reads
  // it (its turtle ignores the `]`); a .lsys file keeps the error.
  const char* text = "axiom: A B C\nA --> F]F\nB --> [F\nC --> G]\n";
  const auto w = Warnings(text);
  ASSERT_EQ(w.size(), 1u) << Joined(w);
  EXPECT_EQ(w[0],
            "2:8 unbalanced ']' in word (cpfg reads it: its turtle ignores a ']' with no '[' open, "
            "and so does Sylva's; said once)");
  EXPECT_EQ(DeriveCpfg(text, 1), "F]F[FG]");
  EXPECT_EQ(FirstError(text, "c.lsys"), "2:8 unbalanced ']' in word");
}

TEST(CpfgPreprocessor, UnbalancedDirectivesAreErrorsWithLocations) {
  EXPECT_EQ(FirstError("#if 1\naxiom: A\n"), "1:1 #if without #endif");
  EXPECT_EQ(FirstError("axiom: A\n#endif\n"), "2:1 #endif without #if");
  EXPECT_EQ(FirstError("#if 1\n#else\n#else\n#endif\naxiom: A\n"), "3:1 #else after #else");
  EXPECT_EQ(FirstError("#if Q\n#endif\naxiom: A\n"), "1:5 unknown name 'Q' in expression");
  EXPECT_EQ(FirstError("#ifdef\n#endif\naxiom: A\n"), "1:7 expected a name after #ifdef");
  EXPECT_EQ(FirstError("#if defined(Q\n#endif\naxiom: A\n"), "1:14 expected ')' after 'defined(Q'");
}

}  // namespace
}  // namespace sylva::lsys
