// cpfg's #define whose value is text (a piece of a word, say), substituted
// where its name is used, as cpfg's preprocessor does (docs/cpfg.md).
#include <gtest/gtest.h>

#include <string>

#include "lsys/parser.h"
#include "lsys_test_util.h"

namespace sylva::lsys {
namespace {

using testing::DeriveText;

// "line:column message" of the first error.
std::string FirstError(const std::string& text, const ParseOptions& opt = {}) {
  ParseResult r = ParseGrammarText(text, "c.l", opt);
  EXPECT_FALSE(r.grammar) << text;
  for (const auto& d : r.diagnostics.items) {
    if (d.severity == Severity::kError)
      return std::to_string(d.loc.line) + ":" + std::to_string(d.loc.column) + " " + d.message;
  }
  return "<no error>";
}

// A small hand-written file in the manner of vlab's topiary and two-trees:
// a word as a #define's value over two lines, a module renamed, a #define
// with arguments whose body is a piece of a word, one text #define inside
// another (defined after it, as C allows), and a numeric constant inside.
const char* kFile =
    "#define SIZE 2\n"
    "#define BOX [;(5)BORDER F(SIZE) \\\n"
    "\t-(90)F(2*SIZE)]\n"
    "#define BORDER f(SIZE/2)\n"
    "#define Apex A\n"
    "#define STEM(w, n) !(w)F(n)\n"
    "axiom: BOX Apex(1)\n"
    "Apex(n) --> STEM(n * 0.5, SIZE + n) Apex(n + 1)\n";

TEST(CpfgTextDefine, WordValuesAreSubstitutedWhereUsed) {
  EXPECT_EQ(DeriveText(kFile, 0), "[;(5)f(1)F(2)-(90)F(4)]A(1)");
  EXPECT_EQ(DeriveText(kFile, 2), "[;(5)f(1)F(2)-(90)F(4)]!(0.5)F(3)!(1)F(4)A(3)");
}

TEST(CpfgTextDefine, ADefineThatNamesItselfStops) {
  EXPECT_EQ(DeriveText("#define X [X]\naxiom: X\n", 0), "[X]");
}

TEST(CpfgTextDefine, NumbersStayConstantsThatDashDOverrides) {
  ParseOptions opt;
  opt.overrides["SIZE"] = 3;
  ParseResult r = ParseGrammarText(kFile, "c.l", opt);
  ASSERT_TRUE(r.grammar) << r.diagnostics.FormatAll();
  DeriveOptions d;
  d.steps = 0;
  auto w = Derive(*r.grammar, d);
  ASSERT_TRUE(w);
  EXPECT_EQ(FormatWord(w->word, r.grammar->symbols), "[;(5)f(1.5)F(3)-(90)F(6)]A(1)");
  ParseOptions text;
  text.overrides["Apex"] = 1;
  EXPECT_EQ(FirstError(kFile, text),
            "5:9 -D Apex: '#define Apex' is text (a piece of a word), not a number, and cannot "
            "be overridden");
}

TEST(CpfgTextDefine, ErrorsPointAtTheUseAndNameTheDefine) {
  // Inside the substituted text: at the name, with the #define's line.
  EXPECT_EQ(FirstError("#define BAD F(1+)\naxiom: A BAD\n"),
            "2:10 expected an expression before ')' (in the text of '#define BAD' at line 1)");
  // After it on the same line: the column in the file, not in the text.
  EXPECT_EQ(FirstError("#define W [FFFFFFFF]\naxiom: W A(1+)\n"),
            "2:14 expected an expression before ')'");
  EXPECT_EQ(FirstError("#define S(a, b) F(a)F(b)\naxiom: X S(1)\n"),
            "2:10 '#define S' takes 2 arguments, given 1");
  EXPECT_EQ(FirstError("#define S(a) F(a)\naxiom: X S(1\n"),
            "2:10 unclosed '(' in the use of '#define S'");
}

TEST(CpfgTextDefine, RunTimeErrorsPointIntoTheFile) {
  // The production's text is "[FFFF] B(1/n)"; the file's line has W.
  Grammar g = testing::MustParse("#define W [FFFF]\naxiom: A(0)\nA(n) --> W B(1/n)\n");
  DeriveOptions opt;
  opt.steps = 1;
  auto r = Derive(g, opt);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().loc.line, 3) << r.error().Format();
  EXPECT_EQ(r.error().loc.column, 15) << r.error().Format();
}

TEST(CpfgTextDefine, NestedDefinesThatDoubleAreStoppedAtALimit) {
  std::string text = "#define X0 F\n";
  for (int i = 1; i <= 40; ++i)
    text += "#define X" + std::to_string(i) + " X" + std::to_string(i - 1) + " X" +
            std::to_string(i - 1) + "\n";
  text += "axiom: A X40\n";
  EXPECT_EQ(FirstError(text), "42:10 the #defines on this line expand to more than 1 MiB");
}

TEST(CpfgTextDefine, UndefForgetsATextDefineFromThere) {
  EXPECT_EQ(DeriveText("#define P F\naxiom: P\n#undef P\n#define P G\nA --> P\n", 0), "F");
  EXPECT_EQ(DeriveText("#define P F\n#undef P\n#define P G\naxiom: P\n#undef NEVER\n", 0), "G");
  // In a .lsys file a number's #define holds for the whole file; in a cpfg
  // file every #define of a name #undef'd is text (CpfgPreprocessor tests).
  EXPECT_EQ(testing::FirstError("#define N 2\n#undef N\naxiom: A(N)\n", "c.lsys"),
            "2:8 #undef of 'N' is not supported: a #define that is a number or an expression "
            "holds for the whole file");
}

TEST(CpfgTextDefine, TwoBackslashesContinueADefine) {
  // vlab's fern-leaf writes `#define name(x) \\` before the body's line.
  EXPECT_EQ(DeriveText("#define len(x) \\\\\n\t(2 * x)\naxiom: F(len(3))\n", 0), "F(6)");
}

}  // namespace
}  // namespace sylva::lsys
