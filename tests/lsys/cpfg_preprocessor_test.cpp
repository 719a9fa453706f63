// The preprocessor's conditionals in cpfg files: #if, #ifdef, #ifndef,
// #elif, #else, #endif (docs/cpfg.md).
#include <gtest/gtest.h>

#include <string>

#include "lsys/parser.h"
#include "lsys_test_util.h"

namespace sylva::lsys {
namespace {

using testing::FirstError;

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
