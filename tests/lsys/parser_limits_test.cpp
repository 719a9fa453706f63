// Hostile and huge grammars: long operator chains, deep nesting, megabyte
// lines. Each must parse (or fail with a located error) in time linear in
// its size, never crash.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <new>
#include <string>

#include "lsys/parser.h"
#include "lsys_test_util.h"
#include "scratch_dir.h"

// Bytes allocated by this test program, to check that parsing allocates in
// proportion to its input (not to input x modules).
static std::atomic<size_t> gAllocatedBytes{0};

void* operator new(size_t n) {
  gAllocatedBytes.fetch_add(n, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, size_t) noexcept {
  std::free(p);
}

namespace sylva::lsys {
namespace {

namespace fs = std::filesystem;

fs::path Scratch() {
  return sylva::testing::ScratchDir("sylva_parser_limits_");
}

std::string Write(const std::string& name, const std::string& text) {
  fs::path p = Scratch() / name;
  std::ofstream(p, std::ios::binary) << text;
  return p.string();
}

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
  std::string text =
      "axiom: A\nA --> " + std::string(100000, '[') + "F" + std::string(100000, ']') + "\n";
  Grammar g = testing::MustParse(text);
  DeriveOptions opt;
  opt.steps = 1;
  DeriveResult r = testing::MustDerive(g, opt);
  EXPECT_EQ(r.word.size(), 200001u);
}

TEST(ParserLimits, ParsingALongLineAllocatesInProportionToIt) {
  // Every module used to copy its whole source line (symbolLoc, productions,
  // diagnostics): 320,000 bracket pairs in one successor took half a minute.
  std::string succ;
  for (int i = 0; i < 100000; ++i) succ += "[F~s" + std::to_string(i % 500) + "]";
  std::string text = "axiom: A\nA --> " + succ + " : 1\nA --> " + succ + "\nB --> " + succ + " $\n";
  size_t before = gAllocatedBytes.load();
  ParseResult r = ParseGrammarText(text, "long.lsys");
  size_t used = gAllocatedBytes.load() - before;
  ASSERT_TRUE(r.grammar) << r.diagnostics.items.size();
  EXPECT_FALSE(r.diagnostics.items.empty());  // B can never match
  EXPECT_LT(used, 40 * text.size()) << "bytes allocated for " << text.size() << " bytes of text";
  for (const Diagnostic& d : r.diagnostics.items) {
    EXPECT_LT(d.sourceLine.size(), 1000u) << d.message;
    EXPECT_LT(d.Format().size(), 500u) << d.message;
  }
  // The grammar quotes its lines from the kept text.
  const Production& p = r.grammar->main.productions[1];
  EXPECT_EQ(r.grammar->SourceLine(p.loc), "A --> " + succ);
}

TEST(ParserLimits, MessagesQuotingAHugeTokenStaySmall) {
  // "malformed number '<the whole token>'" used to quote a megabyte.
  for (const std::string& token :
       {std::string(1000000, '7') + "x", "q" + std::string(1000000, 'z')}) {
    ParseResult r = ParseGrammarText("axiom: F(" + token + ")\n", "token.lsys");
    ASSERT_EQ(r.diagnostics.ErrorCount(), 1u);
    const Diagnostic& d = r.diagnostics.items[0];
    EXPECT_LT(d.message.size(), 600u) << d.message.substr(0, 40);
    EXPECT_LT(d.Format().size(), 1000u) << d.message.substr(0, 40);
    EXPECT_NE(d.message.find("..."), std::string::npos) << d.message;
    EXPECT_TRUE(d.message.rfind("'", d.message.size()) > d.message.size() - 20)
        << "keeps the end: " << d.message;
  }
}

TEST(ParserLimits, RunTimeErrorsQuoteTheLineOfTheProduction) {
  Grammar g = testing::MustParse("axiom: A(0)\nA(x) --> F(1 / x)\n");
  DeriveOptions opt;
  opt.steps = 1;
  auto r = Derive(g, opt);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().Format().find("| A(x) --> F(1 / x)\n"), std::string::npos)
      << r.error().Format();
}

TEST(ParserLimits, ErrorsPastTheLimitAreCountedNotKept) {
  std::string text = "axiom: F\n";
  for (int i = 0; i < kMaxErrors + 25; ++i) text += "F --> G(\n";
  ParseResult r = ParseGrammarText(text, "many.lsys");
  ASSERT_FALSE(r.grammar);
  EXPECT_EQ(r.diagnostics.items.size(), size_t(kMaxErrors));
  EXPECT_EQ(r.diagnostics.droppedErrors, 25u);
  EXPECT_EQ(r.diagnostics.ErrorCount(), size_t(kMaxErrors) + 25);
  EXPECT_NE(r.diagnostics.FormatAll(20).find("sylva: note: 55 more errors not shown\n"),
            std::string::npos);
}

TEST(ParserLimits, ByteOrderMarkIsSkippedInMainAndIncludedFiles) {
  std::map<std::string, std::string> files = {
      {"main.lsys", "\xEF\xBB\xBF#include \"c.lsys\"\naxiom: F(n)\n"},
      {"c.lsys", "\xEF\xBB\xBF#define n 3\n"},
  };
  ParseOptions opt;
  opt.readFile = [&](const std::string& p) -> std::optional<std::string> {
    auto it = files.find(p);
    if (it == files.end()) return std::nullopt;
    return it->second;
  };
  ParseResult r = ParseGrammarFile("main.lsys", opt);
  ASSERT_TRUE(r.grammar) << r.diagnostics.FormatAll();
  EXPECT_EQ(FormatWord(testing::MustDerive(*r.grammar).word, r.grammar->symbols), "F(3)");
  // Columns do not count the mark.
  ParseResult bad = ParseGrammarText(
      "\xEF\xBB\xBF"
      "axiom: F(q)\n",
      "bom.lsys");
  ASSERT_FALSE(bad.grammar);
  EXPECT_EQ(bad.diagnostics.items[0].loc.column, 10) << bad.diagnostics.FormatAll();
}

TEST(ParserLimits, IncludeOfADeviceFifoOrDirectoryIsALocatedError) {
  fs::path fifo = Scratch() / "fifo.lsys";
  fs::remove(fifo);
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  fs::create_directories(Scratch() / "dir.lsys");
  Write("inc.lsys", "#define k 2\n");
  fs::remove(Scratch() / "link.lsys");
  fs::create_symlink(Scratch() / "inc.lsys", Scratch() / "link.lsys");
  std::string main = Write("main.lsys",
                           "#include \"/dev/zero\"\n#include \"fifo.lsys\"\n"
                           "#include \"dir.lsys\"\n#include \"link.lsys\"\naxiom: F(k)\n");
  ParseResult r = ParseGrammarFile(main);
  ASSERT_EQ(r.diagnostics.ErrorCount(), 3u) << r.diagnostics.FormatAll();
  const char* why[] = {"is not a regular file", "is not a regular file", "is a directory"};
  for (int i = 0; i < 3; ++i) {
    const Diagnostic& d = r.diagnostics.items[size_t(i)];
    EXPECT_EQ(d.loc.line, i + 1) << d.Format();
    EXPECT_EQ(d.loc.column, 10) << d.Format();
    EXPECT_NE(d.message.find(why[i]), std::string::npos) << d.message;
  }
  // The main file gets the same checks.
  for (const std::string& p :
       {std::string("/dev/zero"), fifo.string(), (Scratch() / "dir.lsys").string()}) {
    ParseResult m = ParseGrammarFile(p);
    ASSERT_EQ(m.diagnostics.ErrorCount(), 1u) << p;
    EXPECT_EQ(m.diagnostics.items[0].loc.file, p);
  }
}

TEST(ParserLimits, IncludeNameWithANulByteIsAnError) {
  ParseResult r = ParseGrammarText(std::string("#include \"a\0b\"\naxiom: F\n", 23), "nul.lsys");
  ASSERT_EQ(r.diagnostics.ErrorCount(), 1u) << r.diagnostics.FormatAll();
  EXPECT_EQ(r.diagnostics.items[0].message, "#include file name contains a NUL byte");
}

TEST(ParserLimits, IncludeFanOutStopsAtTheFileLimit) {
  // Each file includes the next twice, 15 levels: 2^15 reads before.
  int reads = 0;
  ParseOptions opt;
  opt.readFile = [&](const std::string& p) -> std::optional<std::string> {
    ++reads;
    int level = std::stoi(p.substr(1));
    if (level == 15) return std::string("#define x 1\n");
    std::string next = "f" + std::to_string(level + 1);
    return "#include \"" + next + "\"\n#include \"" + next + "\"\n";
  };
  ParseResult r = ParseGrammarText("#include \"f1\"\naxiom: F\n", "fan.lsys", opt);
  EXPECT_EQ(reads, kMaxIncludedFiles);
  ASSERT_FALSE(r.grammar);
  EXPECT_NE(r.diagnostics.FormatAll().find("more than 1000 #include files in one grammar"),
            std::string::npos)
      << r.diagnostics.FormatAll();
}

TEST(ParserLimits, IncludedBytesHaveATotalBudgetAndAPerFileLimit) {
  ParseOptions opt;
  opt.readFile = [&](const std::string& p) -> std::optional<std::string> {
    return p == "big" ? std::string(300, '\n') : std::string(100, '\n');
  };
  opt.maxFileBytes = 150;
  opt.maxTotalBytes = 200;  // the main text counts too
  ParseResult r = ParseGrammarText("#include \"a\"\n#include \"b\"\n#include \"big\"\naxiom: F\n",
                                   "budget.lsys", opt);
  ASSERT_EQ(r.diagnostics.ErrorCount(), 2u) << r.diagnostics.FormatAll();
  EXPECT_EQ(r.diagnostics.items[0].loc.line, 2);
  EXPECT_EQ(r.diagnostics.items[0].message,
            "#include of 'b' goes past the limit of 200 bytes read for one grammar");
  EXPECT_EQ(r.diagnostics.items[1].loc.line, 3);
  EXPECT_EQ(r.diagnostics.items[1].message,
            "cannot read included file 'big': file is larger than the limit of 150 bytes");
}

TEST(ParserLimits, ManyDeclaredModuleNamesLexInTimeLinearInTheWord) {
  // Each module was compared with every declared name: 20,000 names and a
  // million modules took 46 s. The bound only catches that.
  std::string decl = "module:";
  for (int i = 0; i < 50000; ++i) decl += " m" + std::to_string(i);
  std::string word;
  for (int i = 0; i < 400000; ++i) word += "m49999m1m12F";
  auto start = std::chrono::steady_clock::now();
  ParseResult r = ParseGrammarText(decl + "\naxiom: A\nA --> " + word + "\n", "decl.lsys");
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(r.grammar) << r.diagnostics.FormatAll(3);
  EXPECT_LT(seconds, 30.0);
  const Successor& succ = r.grammar->main.productions[0].successor;
  ASSERT_EQ(succ.symbols.size(), 1600000u);
  // Longest declared name first: m12 is one module, not m1 then 2.
  EXPECT_EQ(r.grammar->symbols.name(succ.symbols[0]), "m49999");
  EXPECT_EQ(r.grammar->symbols.name(succ.symbols[1]), "m1");
  EXPECT_EQ(r.grammar->symbols.name(succ.symbols[2]), "m12");
}

TEST(ParserLimits, RightContextNestedDeeperThan64IsAnError) {
  // The matcher gave up past 64 levels without a word: such a production
  // silently never matched.
  auto context = [](int n) {
    return std::string(size_t(n), '[') + "B" + std::string(size_t(n), ']');
  };
  EXPECT_TRUE(ParseGrammarText("axiom: A\nA > " + context(64) + " --> C\n", "ok.lsys").grammar);
  ParseResult r = ParseGrammarText("axiom: A\nA > " + context(65) + " --> C\n", "deep.lsys");
  ASSERT_EQ(r.diagnostics.ErrorCount(), 1u);
  EXPECT_EQ(r.diagnostics.items[0].message, "right context nested deeper than 64 brackets");
  EXPECT_EQ(r.diagnostics.items[0].loc.column, 5 + 64);
}

TEST(ParserLimits, ShadowWarningsNameTheFirstProductionThatAlwaysApplies) {
  std::string text = "axiom: A(1)\nA(x) : x > 0 --> B\nA(x) --> C\n";
  for (int i = 0; i < 1000; ++i) text += "A(x) : x == " + std::to_string(i) + " --> D\n";
  text += "A(x) --> E\n";
  ParseResult r = ParseGrammarText(text, "shadow.lsys");
  ASSERT_TRUE(r.grammar);
  ASSERT_EQ(r.diagnostics.items.size(), 1001u);
  for (const Diagnostic& d : r.diagnostics.items) {
    EXPECT_EQ(d.message,
              "production never applies: the production at line 3 always matches 'A' first")
        << d.loc.line;
  }
  EXPECT_EQ(r.diagnostics.items.back().loc.line, 1004);
}

}  // namespace
}  // namespace sylva::lsys
