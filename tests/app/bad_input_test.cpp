// Malformed grammars: each must give exit status 2 and its first diagnostic
// at the right line and column, through the real `sylva derive` command.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>

#include "cli_test_util.h"

namespace sylva::app {
namespace {

using testing::RunSylva;
using testing::WriteFile;

struct BadCase {
  const char* name;
  std::string text;     // "%SELF%" is replaced by the file's own name
  const char* where;    // "line:col" (or "line" when the whole file is at fault)
  const char* message;  // part of the first error message
};

std::string Many(char c, int n) {
  return std::string(size_t(n), c);
}

std::vector<BadCase> Cases() {
  std::string ones = "1";
  for (int i = 0; i < 64; ++i) ones += ",1";
  return {
      {"unbalanced_close", "axiom: F]F\n", "1:9", "unbalanced ']'"},
      {"unbalanced_open", "axiom: F\nF --> F[+F\n", "2:8", "unbalanced '['"},
      {"unknown_name", "axiom: A(1)\nA(x) --> A(y)\n", "2:12", "unknown name 'y'"},
      // Not an expression of constants: text (cpfg), found wrong where used.
      {"unknown_constant", "#define a b+1\naxiom: F(a)\n", "2:10", "unknown name 'b'"},
      {"function_arity", "axiom: F(min(1))\n", "1:10", "takes 2 arguments, given 1"},
      {"bad_number", "axiom: F(1.2.3)\n", "1:10", "malformed number '1.2.3'"},
      {"bad_exponent", "axiom: F(1e)\n", "1:10", "exponent has no digits"},
      {"unterminated_comment", "axiom: F /* never closed\nF --> FF\n", "1:10",
       "unterminated comment"},
      {"empty_axiom", "axiom:   \n", "1:1", "'axiom:' needs a value"},
      {"missing_axiom", "F --> FF\n", "1", "no 'axiom:'"},
      {"constant_division_by_zero", "#define a 1/0\naxiom: F(a)\n", "1:12", "division by zero"},
      {"runtime_division_by_zero", "axiom: A(0)\nA(x) --> B(1/x)\nderivation length: 1\n", "2:13",
       "division by zero"},
      {"runtime_sqrt_negative", "axiom: A(-1)\nA(x) --> B(sqrt(x))\nderivation length: 1\n", "2:12",
       "sqrt of a negative number"},
      {"include_recursion", "#include \"%SELF%\"\naxiom: F\n", "1:10", "#include recursion"},
      {"include_missing", "#include \"nothere.lsys\"\naxiom: F\n", "1:10",
       "cannot read included file"},
      {"binary_garbage", "axiom: F\n\x01\x02\xff\xfe --> \x80\n", "2:1",
       "unexpected character '\\x01'"},
      {"nul_byte", std::string("axiom: F\0F\n", 11), "1:9", "unexpected character '\\x00'"},
      {"bracket_in_predecessor", "axiom: F\nA [ --> C\n", "2:3", "'[' cannot be rewritten"},
      {"no_predecessor", "axiom: F\n --> C\n", "2:2", "no predecessor"},
      {"empty_successor", "axiom: F\nF -->\n", "2:3", "empty successor"},
      {"duplicate_formal", "axiom: A(1,2)\nA(x,x) --> A(x,x)\n", "2:1", "appears twice"},
      {"formal_not_a_name", "axiom: A(1)\nA(1) --> B\n", "2:3", "expected a formal parameter name"},
      {"unclosed_parameters", "axiom: F\nF --> F(1\n", "2:8", "unclosed '('"},
      {"misspelt_statement", "axiom: F\nderivation lenght: 3\n", "2:1",
       "unknown statement 'derivation lenght:'"},
      {"fractional_length", "derivation length: 2.5\naxiom: F\n", "1:20", "whole number"},
      {"negative_length", "derivation length: -1\naxiom: F\n", "1:20", "whole number"},
      {"huge_length", "derivation length: 3e9\naxiom: F\n", "1:20", "whole number"},
      {"unknown_directive", "#pragma X\naxiom: F\n", "1:1", "unknown directive '#pragma'"},
      {"if_without_endif", "#ifdef X\naxiom: F\n", "1:1", "#if without #endif"},
      {"unclosed_statement_block", "axiom: A(1)\nA(x) : {y = x;\n", "2:8",
       "unclosed '{': the statement block has no '}'"},
      {"redefinition", "#define a 1\n#define a 2\naxiom: F(a)\n", "2:9", "redefinition of 'a'"},
      {"bracket_in_left_context", "axiom: F\n[ < F --> G\n", "2:1",
       "not allowed in a left context"},
      {"rewriting_a_bracket", "axiom: F\n] --> F\n", "2:1", "cannot be rewritten"},
      // (An unbalanced right context is cpfg's: `A > [B` and `A > B]C` read.)
      {"star_inside_right_context", "axiom: AB\nA > B * --> C\n", "2:7", "'*' stands alone"},
      {"second_axiom", "axiom: F\naxiom: G\n", "2:1", "second axiom"},
      {"short_tropism", "tropism: 0 1 0\naxiom: F\n", "1:10", "four numbers"},
      {"negative_weight", "axiom: F\nF --> G : -1\n", "2:11", "negative probability weight"},
      {"condition_unknown_name", "axiom: A(1)\nA(x) : y > 1 --> B\n", "2:8", "unknown name 'y'"},
      {"parameters_without_comma", "axiom: F(1 2)\n", "1:12", "expected ',' or ')'"},
      {"parameters_without_module", "axiom: (1)\n", "1:8", "no module name"},
      {"at_without_letter", "axiom: @1\n", "1:8", "after '@'"},
      {"tilde_without_name", "axiom: ~(2)\n", "1:8", "surface name after '~'"},
      {"too_many_parameters", "axiom: F(" + ones + ")\n", "1:8", "more than 64 parameters"},
      {"empty_condition", "axiom: F\nF : --> G\n", "2:3", "empty condition"},
      {"depth_in_main_section", "maximum depth: 2\naxiom: F\n", "1:1",
       "decomposition or interpretation"},
      {"negative_seed", "seed: -4\naxiom: F\n", "1:7", "whole number"},
      {"deep_parentheses", "axiom: F(" + Many('(', 200) + "1" + Many(')', 200) + ")\n",
       "1:", "nested deeper than 48"},
      {"stray_close_paren", "axiom: F)\n", "1:9", "unbalanced ')'"},
      {"zero_tropism", "tropism: 0 0 0 1\naxiom: F\n", "1:10", "tropism vector is zero"},
      {"override_unknown_in_condition", "axiom: A\nA : q --> B\n", "2:5", "unknown name 'q'"},
  };
}

TEST(BadInput, EachMalformedGrammarIsExitTwoWithItsLocation) {
  auto cases = Cases();
  ASSERT_GE(cases.size(), 30u);
  for (const BadCase& c : cases) {
    std::string name = std::string("bad_") + c.name + ".lsys";
    std::string text = c.text;
    if (auto p = text.find("%SELF%"); p != std::string::npos) text.replace(p, 6, name);
    std::string path = WriteFile(name, text);
    auto r = RunSylva({"derive", path});
    EXPECT_EQ(r.code, 2) << c.name << "\n" << r.err;
    std::string prefix = path + ":" + c.where;
    EXPECT_EQ(r.err.rfind(prefix, 0), 0u)
        << c.name << ": expected the first diagnostic at " << c.where << ", got:\n"
        << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.name << ":\n" << r.err;
    EXPECT_NE(r.err.find("error:"), std::string::npos) << c.name;
    EXPECT_EQ(r.out, "") << c.name;
  }
}

TEST(BadInput, DiagnosticShowsTheLineAndACaret) {
  std::string path =
      WriteFile("caret.lsys", "axiom: A(1,10)\nA(l,w) --> !(w)F(l)[&(45)B(l*r3,w)]\n");
  auto r = RunSylva({"check", path});
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, path +
                       ":2:30: error: unknown name 'r3' in expression\n"
                       "    2 | A(l,w) --> !(w)F(l)[&(45)B(l*r3,w)]\n"
                       "      |                              ^~\n");
}

TEST(BadInput, MaxErrorsCapsThePrintedErrorsAndCountsTheRest) {
  std::string text = "axiom: F\n";
  for (int i = 0; i < 30; ++i) text += "F --> G(\n";
  std::string path = WriteFile("many_errors.lsys", text);
  for (const char* cmd : {"derive", "check", "mesh", "render"}) {
#ifndef SYLVA_TESTS_WITH_GRAPHICS
    if (std::string(cmd) == "render") continue;  // built without the renderer
#endif
    std::vector<std::string> args = {cmd, path};
    if (std::string(cmd) == "mesh")
      args.insert(args.end(), {"-o", (testing::Scratch() / "unused.obj").string()});
    if (std::string(cmd) == "render")
      args.insert(args.end(), {"-o", (testing::Scratch() / "unused.png").string()});
    auto r = RunSylva(args);
    EXPECT_EQ(r.code, 2) << cmd;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 20 * 3 + 1) << cmd << "\n" << r.err;
    EXPECT_NE(r.err.find("sylva: note: 10 more errors not shown\n"), std::string::npos) << cmd;
  }
  auto five = RunSylva({"check", "--max-errors", "5", path});
  EXPECT_EQ(five.code, 2);
  EXPECT_NE(five.err.find("sylva: note: 25 more errors not shown\n"), std::string::npos)
      << five.err;
  auto all = RunSylva({"derive", "--max-errors", "0", path});
  EXPECT_EQ(all.code, 2);
  EXPECT_EQ(std::count(all.err.begin(), all.err.end(), '\n'), 30 * 3) << all.err;
}

TEST(BadInput, GrammarThatIsADeviceFifoOrDirectoryIsExitTwo) {
  std::string fifo = (testing::Scratch() / "grammar.fifo").string();
  std::filesystem::remove(fifo);
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  std::string dir = testing::Scratch().string();
  for (const std::string& p : {std::string("/dev/zero"), fifo, dir}) {
    auto r = RunSylva({"derive", p});
    EXPECT_EQ(r.code, 2) << p << "\n" << r.err;
    EXPECT_EQ(r.err.rfind(p + ": error: is ", 0), 0u) << r.err;
  }
}

}  // namespace
}  // namespace sylva::app
