// Hostile and huge grammars: long operator chains, deep nesting, megabyte
// lines. Each must parse (or fail with a located error) in time linear in
// its size, never crash.
#include <gtest/gtest.h>

#include <string>

#include "lsys/parser.h"
#include "lsys_test_util.h"

namespace sylva::lsys {
namespace {

std::string Chain(const std::string& term, const std::string& op, int n) {
  std::string s = term;
  s.reserve(n * (term.size() + op.size()));
  for (int i = 1; i < n; ++i) s += op + term;
  return s;
}

TEST(ParserLimits, OperatorChainsOf50000TermsInEveryExpressionPlace) {
  std::string sum = Chain("1", "+", 50000);
  std::string text = "#define N " + sum + "\naxiom: A(1)\nA(x) : " + Chain("x", "+", 50000) +
                     " > 0 --> F(" + Chain("x", "+", 50000) + ", N)\n";
  EXPECT_EQ(testing::DeriveText(text, 1), "F(50000,50000)");
}

TEST(ParserLimits, DefinesReferringToDefinesInALongChain) {
  std::string text = "#define c0 1\n";
  for (int i = 1; i < 20000; ++i) {
    text += "#define c" + std::to_string(i) + " c" + std::to_string(i - 1) + " + 1\n";
  }
  text += "axiom: F(c19999)\n";
  EXPECT_EQ(testing::DeriveText(text, 0), "F(20000)");
}

TEST(ParserLimits, DeepParenthesesAreALocatedError) {
  ParseResult r = ParseGrammarText(
      "axiom: A\nA --> F(" + std::string(100000, '(') + "1" + std::string(100000, ')') + ")\n",
      "deep.lsys");
  ASSERT_FALSE(r.grammar);
  ASSERT_EQ(r.diagnostics.ErrorCount(), 1u) << r.diagnostics.items.size();
  const Diagnostic& d = r.diagnostics.items[0];
  EXPECT_EQ(d.message, "expression nested deeper than 48");
  EXPECT_EQ(d.loc.line, 2);
  EXPECT_EQ(d.loc.column, 9 + 49) << d.message;
}

TEST(ParserLimits, BracketsNested100000DeepDerive) {
  std::string text = "axiom: A\nA --> " + std::string(100000, '[') + "F" +
                     std::string(100000, ']') + "\n";
  Grammar g = testing::MustParse(text);
  DeriveOptions opt;
  opt.steps = 1;
  DeriveResult r = testing::MustDerive(g, opt);
  EXPECT_EQ(r.word.size(), 200001u);
}

}  // namespace
}  // namespace sylva::lsys
