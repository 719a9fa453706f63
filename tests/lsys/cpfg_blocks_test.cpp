// cpfg's statement blocks (docs/cpfg.md "Statement blocks and variables"):
// blocks around conditions and inside successors with local variables,
// Start:/StartEach:/EndEach:/End: blocks and global variables.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "lsys/parser.h"
#include "lsys_test_util.h"

namespace sylva::lsys {
namespace {

using testing::DeriveText;
using testing::FirstError;
using testing::MustDerive;
using testing::MustParse;

// "line:col message" of the first error.
TEST(CpfgBlocks, PreConditionBlockDefinesLocalsForTheConditionAndSuccessor) {
  const std::string g =
      "derivation length: 2\n"
      "axiom: A(1) A(0)\n"
      "A(x) : {y = x*2; } y > 1 --> B(y) {z = y+1;} C(z)\n"
      "B(x) --> B(x+1)\n";
  EXPECT_EQ(DeriveText(g, 1), "B(2)C(3)A(0)");
  EXPECT_EQ(DeriveText(g, 2), "B(3)C(3)A(0)");
}

TEST(CpfgBlocks, SuccessorBlocksRunInOrderBeforeTheModuleAfterThem) {
  EXPECT_EQ(DeriveText("axiom: A(1)\nA(x) --> B(x) {x = x+1;} C(x) {x = x*10;} D(x) {x = 0;}\n", 1),
            "B(1)C(2)D(20)");
}

TEST(CpfgBlocks, ConditionLeftOutOrStarAfterABlockIsTrue) {
  EXPECT_EQ(DeriveText("axiom: A(2)\nA(x) : {y = x*x;} --> B(y)\n", 1), "B(4)");
  EXPECT_EQ(DeriveText("axiom: A(2)\nA(x) : {y = x*x;} * --> B(y)\n", 1), "B(4)");
  // The post-condition block runs only when the condition holds.
  EXPECT_EQ(DeriveText("axiom: A(2) A(-1)\nA(x) : {y = 1;} x > 0 {y = 5;} --> B(y)\n", 1),
            "B(5)A(-1)");
}

TEST(CpfgBlocks, IfElseWhileDoAndCompoundAssignments) {
  const std::string g =
      "axiom: A(5) A(3)\n"
      "A(n) : {f = 1; i = 1; while (i <= n) { f *= i; i += 1; }\n"
      "        if (f > 100) big = 1; else { big = 0; }\n"
      "        k = 0; do k = k + 2; while (k < 7); } * --> F(f, big, k)\n";
  EXPECT_EQ(DeriveText(g, 1), "F(120,1,8)F(6,0,8)");
}

TEST(CpfgBlocks, LoopAsTheFirstStatementOfABlockLoops) {
  // vlab's phyllotaxis-ridley/spiral.l opens its block with `while`: the
  // loop's jump back to instruction 0 once ended the block after one pass
  // (B(2,0,0.3,0.1)).
  EXPECT_EQ(DeriveText("axiom: A(0, 0)\n"
                       "A(s, a) : s < 1 {while (a < 1 && s < 1) {x = 2; a = a + 0.3; s = s + 0.1;}"
                       " a = a - 1; y = 5;} --> B(x, y, a, s)\n",
                       1),
            "B(2,5,0.2,0.4)");
  EXPECT_EQ(
      DeriveText("axiom: A(0)\nA(k) : {do k = k + 2; while (k < 7); m = 1;} * --> B(k, m)\n", 1),
      "B(8,1)");
}

TEST(CpfgBlocks, LocalsStartAtZeroEachTimeAProductionIsTried) {
  // y is assigned only when x > 1: A(0) must not see the 4 of A(2).
  EXPECT_EQ(DeriveText("axiom: A(2) A(0)\nA(x) : {if (x > 1) y = x*2;} * --> B(y)\n", 1),
            "B(4)B(0)");
}

TEST(CpfgBlocks, GlobalBlocksRunAroundTheDerivation) {
  const std::string g =
      "Lsystem: 1\n"
      "Start: {count = 0; total = 10;}\n"
      "StartEach: { count = count + 1; }\n"
      "EndEach: { total = total + 1; }\n"
      "End: { total = -1; }\n"
      "derivation length: 3\n"
      "axiom: A(count)\n"
      "A(x) : count < 3 --> A(x+1) [B(count, total)]\n"
      "A(x) --> D(total)\n"
      "endlsystem\n";
  EXPECT_EQ(DeriveText(g), "D(12)[B(2,11)][B(1,10)]");
  Grammar gr = MustParse(g);
  auto d = Derivation::Start(gr);
  ASSERT_TRUE(d);
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(d->Step().ok());
  ASSERT_EQ(gr.globals, (std::vector<std::string>{"count", "total"}));
  EXPECT_EQ(d->globals()[0], 3);
  EXPECT_EQ(d->globals()[1], 13);
  ASSERT_TRUE(d->RunEnd().ok());
  EXPECT_EQ(d->globals()[1], -1) << "End: did not run";
}

TEST(CpfgBlocks, ProductionsAssigningGlobalsRunInWordOrderOnAnyThreadCount) {
  // 2^16 modules A become B(1) ... B(65536), numbered left to right.
  const std::string g =
      "Start: {k = 0; s = 0;}\n"
      "StartEach: {s = s + 1;}\n"
      "derivation length: 17\n"
      "axiom: A\n"
      "A : s < 17 --> A A\n"
      "A : {k = k + 1;} * --> B(k)\n";
  Grammar gr = MustParse(g);
  EXPECT_TRUE(gr.productionsWriteGlobals);
  std::string first;
  for (int threads : {1, 4}) {
    DeriveOptions opt;
    opt.threads = threads;
    DeriveResult r = MustDerive(gr, opt);
    ASSERT_EQ(r.word.size(), 65536u) << threads;
    bool ordered = true;
    for (size_t i = 0; i < r.word.size() && ordered; ++i)
      ordered = r.word.params[i] == double(i + 1);
    EXPECT_TRUE(ordered) << "threads " << threads << ": B(k) not numbered in word order";
    const std::string text = FormatWord(r.word, gr.symbols);
    if (first.empty()) first = text;
    EXPECT_EQ(text, first) << "threads " << threads;
  }
}

TEST(CpfgBlocks, LocalsOnlyDeriveInParallelToTheSameWord) {
  // Blocks with local variables (and random draws) keep the parallel
  // derivation: the word is the same on 1 and 4 threads.
  Grammar gr = MustParse(
      "seed: 5\nderivation length: 16\naxiom: A(1)\n"
      "A(x) : {y = x + ran(1); z = y * 0.5;} y > 0 --> A(y) [B(z)] A(z)\n"
      "B(x) : {w = x * 2; if (w > 100) w = 0;} * --> B(w * 0.5)\n");
  EXPECT_FALSE(gr.productionsWriteGlobals);
  std::string first;
  for (int threads : {1, 4}) {
    DeriveOptions opt;
    opt.threads = threads;
    DeriveResult r = MustDerive(gr, opt);
    ASSERT_GT(r.word.size(), 100000u);
    const std::string text = FormatWord(r.word, gr.symbols);
    if (first.empty()) first = text;
    EXPECT_EQ(text, first) << "threads " << threads;
  }
}

TEST(CpfgBlocks, BlocksOverSeveralLinesKeepTheirLineNumbers) {
  const std::string g =
      "Start: {\n"
      "  k = 0;\n"
      "}\n"
      "axiom: A A A\n"
      "A : {\n"
      "  k = k + 1;\n"
      "  if (k > 2) m = 100;\n"
      "  else m = k;\n"
      "} * --> C(m)\n";
  EXPECT_EQ(DeriveText(g, 1), "C(1)C(2)C(100)");
  EXPECT_EQ(FirstError("axiom: A\nA : {\n  k = 1;\n  m = k +;\n} * --> C(m)\n"),
            "4:10 unexpected character ';' in expression");
}

TEST(CpfgBlocks, IndentedBlocksAndArrowContinueTheProduction) {
  const std::string g =
      "Start: {time = 0;}\n"
      "StartEach: {time = time + 1;}\n"
      "derivation length: 3\n"
      "Axiom: A(0)\n"
      "A(t) : t < 5\n"
      "\t{\n"
      "\t\tnt = t + time;\n"
      "\t}\n"
      "\t--> [B(nt)]A(nt)\n"
      "A(t) :\n"
      "\t{ q = 2; } *\n"
      "\t--> C(q)\n";
  // time 1: A(0) -> [B(1)]A(1); time 2: -> [B(3)]A(3); time 3: -> [B(6)]A(6).
  EXPECT_EQ(DeriveText(g), "[B(1)][B(3)][B(6)]A(6)");
  EXPECT_EQ(
      DeriveText(
          "axiom: A(9)\nA(t) : t < 5\n  {nt = 1;}\n  --> B\nA(t) :\n  {q = 2;} *\n  --> C(q)\n", 1),
      "C(2)");
  // vlab's clover and fern-leaf: the condition on the line after the block,
  // the arrow on the line after that.
  EXPECT_EQ(DeriveText("axiom: A(1)A(7)\nA(x) : {y = fabs(x - 5);}\n\t\t(y > 3)\n\t--> B(y)\n", 1),
            "B(4)A(7)");
}

TEST(CpfgBlocks, AWeightAfterABlockWithAConditionalExpression) {
  EXPECT_EQ(DeriveText("axiom: A(1)\nA(x) --> B(x) {z = x > 0 ? 7 : 2;} C(z) : 1\n", 1),
            "B(1)C(7)");
}

TEST(CpfgBlocks, BracesThatAreNotStatementsStayPolygons) {
  EXPECT_EQ(DeriveText("axiom: A\nA --> [{.F.F.}]{F}\n", 1), "[{.F.F.}]{F}");
}

TEST(CpfgBlocks, RunawayLoopIsAnErrorAtTheWhileNeverAHang) {
  Grammar g = MustParse("axiom: A(1)\nA(x) : {y = 1; while (y > 0) y = y + 1; } * --> B(y)\n");
  DeriveOptions opt;
  opt.steps = 1;
  auto r = Derive(g, opt);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().loc.line, 2) << r.error().Format();
  EXPECT_EQ(r.error().loc.column, 16) << r.error().Format();
  EXPECT_NE(r.error().message.find("loop ran more than 1000000 times"), std::string::npos)
      << r.error().message;
}

TEST(CpfgBlocks, MalformedBlocksAreErrorsWithLocations) {
  EXPECT_EQ(FirstError("axiom: A(1)\nA(x) : {y = x*2; z = } y > 1 --> B(y)\n"),
            "2:22 unexpected character '}' in expression");
  EXPECT_EQ(FirstError("axiom: A(1)\nA(x) : {y = x;\n  z = y + 1;\n"),
            "2:8 unclosed '{': the statement block has no '}'");
  EXPECT_EQ(FirstError("axiom: A(1)\nA(x) --> B(x) {z = q + 1;} C(z)\n", "c.lsys"),
            "2:20 unknown name 'q' in expression");
  EXPECT_EQ(FirstError("axiom: A(1)\nA(x) : {y += 1;} * --> B(y)\n"),
            "2:9 'y' has no value before this assignment");
  EXPECT_EQ(FirstError("axiom: A(1)\nA(x) : {y = 1 z = 2;} * --> B(y)\n"),
            "2:15 expected ';' after the statement");
  EXPECT_EQ(FirstError("axiom: A(1)\nA(x) : {if x > 1 y = 2;} * --> B(y)\n"),
            "2:12 expected '(' after 'if'");
  EXPECT_EQ(FirstError("axiom: A(1)\nA(x) : {y = 2;} x > 1 z --> B(y)\n"),
            "2:23 unexpected text after the condition");
  // Arrays: cpfg_arrays_test.cpp; an undeclared one is an error.
  EXPECT_EQ(FirstError("Start: {a[1] = 2;}\naxiom: A\n"),
            "1:9 'a' is not an array (arrays are declared in 'define: { array a[n]; }')");
  EXPECT_EQ(FirstError("Start: x = 1;\naxiom: A\n"), "1:8 expected '{' after 'Start:'");
  EXPECT_EQ(FirstError("axiom: A {x = 1;} B\n"),
            "1:10 a statement block belongs in a production, not here");
  EXPECT_EQ(FirstError("axiom: A(1)\nA(x) : {sin(x);} * --> B(x)\n"),
            "2:9 a call 'sin(...)' as a statement is not supported (cpfg's printf, ...)");
  // A data file that is not there (reading: cpfg_data_files_test.cpp).
  EXPECT_EQ(FirstError("Start: {fp = fopen(\"no_such_data.txt\", \"r\");}\naxiom: A\n"),
            "1:20 cannot read data file 'no_such_data.txt': cannot read file: No such file or "
            "directory");
}

TEST(CpfgBlocks, OutputCallsAreReadAndWarnedOnceEach) {
  // cpfg's canalization-file tutorial: the output goes nowhere, the rest runs.
  const std::string text =
      "Start: {n = 0; fp = fopen(\"out.txt\", \"w\");}\n"
      "EndEach: {n = n + 1; fprintf(fp, \"step %.0f (%s)\\n\", n, \"a;b)\"); fflush(fp);}\n"
      "End: {fclose(fp);}\n"
      "axiom: A(0)\n"
      "A(x) : {printf(\"%f\\n\", x); printf(\"again\");} * --> A(x + n + fp)\n";
  ParseResult r = ParseGrammarText(text, "c.l");
  ASSERT_TRUE(r.grammar) << r.diagnostics.FormatAll();
  std::vector<std::string> warnings;
  for (const auto& d : r.diagnostics.items)
    if (d.severity == Severity::kWarning)
      warnings.push_back(std::to_string(d.loc.line) + ":" + std::to_string(d.loc.column) + " " +
                         d.message.substr(0, d.message.find(':')));
  const std::vector<std::string> expected{
      "1:21 'fopen(...)' opens no file", "2:22 'fprintf(...)' prints nothing",
      "2:66 'fflush(...)' does nothing", "3:7 'fclose(...)' does nothing",
      "5:9 'printf(...)' prints nothing"};
  EXPECT_EQ(warnings, expected) << r.diagnostics.FormatAll();
  // fp is 0; n counts the steps: A(0) -> A(0) -> A(1) -> A(3).
  DeriveOptions opt;
  opt.steps = 3;
  EXPECT_EQ(FormatWord(MustDerive(*r.grammar, opt).word, r.grammar->symbols), "A(3)");
}

}  // namespace
}  // namespace sylva::lsys
