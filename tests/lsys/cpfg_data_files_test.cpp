// cpfg's data files in statement blocks (docs/cpfg.md, "Data files"):
// `fp = fopen(NAME, "r");`, `fscanf(fp, FORMAT, &x, &a[i]);`, `fclose(fp);`
// with C's scanf rules, NAME relative to the grammar file.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include "../scratch_dir.h"
#include "lsys/cpfg_data_files.h"
#include "lsys/parser.h"
#include "lsys_test_util.h"

namespace sylva::lsys {
namespace {

using testing::MustDerive;

// Parses `text` as /obj/plant.l with these files readable.
ParseResult ParseWith(const std::string& text, std::map<std::string, std::string> files) {
  ParseOptions opt;
  opt.readFile = [files](const std::string& path) -> std::optional<std::string> {
    auto it = files.find(path);
    if (it == files.end()) return std::nullopt;
    return it->second;
  };
  return ParseGrammarText(text, "/obj/plant.l", opt);
}

std::string Word(const ParseResult& r, int steps = -1) {
  if (!r.grammar) return "<no grammar> " + r.diagnostics.FormatAll();
  DeriveOptions opt;
  opt.steps = steps;
  return FormatWord(MustDerive(*r.grammar, opt).word, r.grammar->symbols);
}

std::string FirstError(const ParseResult& r) {
  for (const Diagnostic& d : r.diagnostics.items)
    if (d.severity == Severity::kError)
      return std::to_string(d.loc.line) + ":" + std::to_string(d.loc.column) + " " + d.message;
  return "<no error>";
}

TEST(CpfgDataFiles, FscanfReadsNumbersTextAndArraysAsCscanf) {
  // soil3d's form: literal text, %lf after it, a loop filling an array,
  // blanks in the format matching any blanks (line breaks too).
  const std::string g =
      "define: { array w[3], m[2][2]; }\n"
      "Start: {\n"
      "  fp = fopen(\"roots.spec\", \"r\");\n"
      "  fscanf(fp, \"Time step: %lf\\n\", &step);\n"
      "  fscanf(fp, \"Width:\"); i = 0;\n"
      "  while (i < 3) { fscanf(fp, \"%lf\", &w[i]); i = i + 1; }\n"
      "  n = fscanf(fp, \"\\nPairs: %d %*s %lf\", &m[1][0], &m[0][1]);\n"
      "  fclose(fp);\n"
      "}\n"
      "axiom: A(step, w[0], w[1], w[2], m[1][0], m[0][1], n)\n";
  ParseResult r = ParseWith(g, {{"/obj/roots.spec",
                                 "Time step: 4\nWidth:   0.10  0.035\n\t2e-2\n"
                                 "Pairs: 7 skipped -1.5\n"}});
  EXPECT_EQ(Word(r), "A(4,0.1,0.035,0.02,7,-1.5,2)");
}

TEST(CpfgDataFiles, AtTheEndOfTheFileVariablesKeepTheirValuesAndAWarningSaysSo) {
  // C: fscanf returns EOF (-1) and assigns nothing when the input ends
  // before its first conversion; a mismatch stops it with its count.
  const std::string g =
      "Start: { fp = fopen(\"p.dat\", \"r\"); a = 5; b = 6; c = 7;\n"
      "  fscanf(fp, \"%lf\", &a); r1 = fscanf(fp, \"%lf %lf\", &b, &c);\n"
      "  r2 = fscanf(fp, \"%lf\", &c); }\n"
      "axiom: A(a, b, c, r1, r2)\n";
  ParseResult r = ParseWith(g, {{"/obj/p.dat", "1.5 2.5\n"}});
  EXPECT_EQ(Word(r), "A(1.5,2.5,7,1,-1)");
  ASSERT_TRUE(r.grammar);
  auto warnings = r.grammar->dataFiles->ShortReads();
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0].loc.file, "/obj/p.dat");
  EXPECT_EQ(warnings[0].message,
            "fscanf stopped before the end of its format 2 times reading this file (first at the "
            "end of the file): the variables it did not read kept their values");
  // Text that does not match: stopped there, with the line.
  ParseResult m = ParseWith(
      "Start: { fp = fopen(\"q.dat\", \"r\"); y = 9;\n"
      "  fscanf(fp, \"Width: %lf\", &x); fscanf(fp, \"\\nWidth: %lf\", &y); }\n"
      "axiom: A(x, y)\n",
      {{"/obj/q.dat", "Width: 1\nHeight: 3\n"}});
  EXPECT_EQ(Word(m), "A(1,9)");
  ASSERT_TRUE(m.grammar);
  auto mw = m.grammar->dataFiles->ShortReads();
  ASSERT_EQ(mw.size(), 1u);
  EXPECT_NE(mw[0].message.find("first at line 2: the format expects 'W', the file has 'H'"),
            std::string::npos)
      << mw[0].message;
}

TEST(CpfgDataFiles, ProductionsReadInWordOrderAndEachDerivationStartsAgain) {
  // A production that reads makes the derivation run left to right on one
  // thread (as cpfg), so the A's take 1, 2, 3 in order; deriving again
  // opens the file again.
  const std::string g =
      "Start: { fp = fopen(\"n.dat\", \"r\"); }\n"
      "derivation length: 1\n"
      "axiom: A A A\n"
      "A : {fscanf(fp, \"%lf\", &x);} * --> B(x)\n";
  ParseResult r = ParseWith(g, {{"/obj/n.dat", "1 2 3 4"}});
  ASSERT_TRUE(r.grammar) << r.diagnostics.FormatAll();
  EXPECT_TRUE(r.grammar->productionsWriteGlobals);
  EXPECT_EQ(Word(r), "B(1)B(2)B(3)");
  EXPECT_EQ(Word(r), "B(1)B(2)B(3)");
  EXPECT_TRUE(r.grammar->dataFiles->ShortReads().empty());
}

TEST(CpfgDataFiles, ReadingAClosedOrUnopenedFileIsARunTimeError) {
  ParseResult r = ParseWith(
      "Start: { fp = fopen(\"n.dat\", \"r\"); fclose(fp); fscanf(fp, \"%lf\", &x); }\naxiom: A\n",
      {{"/obj/n.dat", "1"}});
  ASSERT_TRUE(r.grammar) << r.diagnostics.FormatAll();
  auto w = Derive(*r.grammar, DeriveOptions{});
  ASSERT_FALSE(w);
  EXPECT_NE(w.error().message.find("fscanf: the file pointer 1 is not a file open for reading"),
            std::string::npos)
      << w.error().message;
  // A number that is not finite.
  ParseResult nan = ParseWith(
      "Start: { fp = fopen(\"n.dat\", \"r\"); fscanf(fp, \"%lf\", &x); }\n"
      "axiom: A\n",
      {{"/obj/n.dat", "\n nan"}});
  ASSERT_TRUE(nan.grammar);
  auto wn = Derive(*nan.grammar, DeriveOptions{});
  ASSERT_FALSE(wn);
  EXPECT_NE(wn.error().message.find("fscanf read a number that is not finite ('nan') at line 2"),
            std::string::npos)
      << wn.error().message;
}

TEST(CpfgDataFiles, FormatsAndAddressesAreCheckedWhenParsed) {
  std::map<std::string, std::string> files{{"/obj/n.dat", "1"}};
  auto err = [&](const std::string& block) {
    return FirstError(
        ParseWith("Start: { fp = fopen(\"n.dat\", \"r\"); " + block + " }\naxiom: A\n", files));
  };
  EXPECT_EQ(err("fscanf(fp, \"%lf %lf\", &x);"),
            "1:47 fscanf: the format assigns 2 values and 1 address follows");
  EXPECT_EQ(err("fscanf(fp, \"%s\", &x);"),
            "1:47 fscanf: '%s' reads text, and cpfg's variables are numbers (write '%*s' to skip "
            "it)");
  EXPECT_EQ(err("fscanf(fp, \"%lf\", x);"),
            "1:54 fscanf reads into variables: write '&name' or '&a[i]'");
  EXPECT_EQ(err("fscanf(fp, \"%lf\", &a[0]);"),
            "1:55 'a' is not an array (arrays are declared in 'define: { array a[n]; }')");
  EXPECT_EQ(err("if (fscanf(fp, \"%lf\", &y) == 1) x = 2;"),
            "1:40 'fscanf(...)' is read in a statement block as a statement ('fscanf(...);') or an "
            "assignment ('x = fscanf(...);'), not inside an expression");
  // A file that is not there: an error at its name, which says where it looked.
  EXPECT_EQ(FirstError(ParseWith("Start: { fp = fopen(\"gone.dat\", \"r\"); }\naxiom: A\n", files)),
            "1:21 cannot read data file '/obj/gone.dat': cannot read file");
  // Writing stays a warning: Sylva writes no files.
  ParseResult w = ParseWith("Start: { fp = fopen(\"out.dat\", \"w\"); }\naxiom: A\n", files);
  ASSERT_TRUE(w.grammar) << w.diagnostics.FormatAll();
  EXPECT_NE(w.diagnostics.FormatAll().find("'fopen(...)' opens no file"), std::string::npos)
      << w.diagnostics.FormatAll();
}

TEST(CpfgDataFiles, NamesAreRelativeToTheGrammarAndHostileFilesAreClearErrors) {
  const std::filesystem::path dir = sylva::testing::ScratchDir("sylva_data_files_");
  std::filesystem::create_directories(dir / "obj" / "sub");
  std::ofstream(dir / "obj" / "sub" / "d.dat") << "42\n";
  const std::string grammar = (dir / "obj" / "plant.l").string();
  std::ofstream(grammar)
      << "Start: { fp = fopen(\"sub/d.dat\", \"r\"); fscanf(fp, \"%lf\", &x); }\n"
         "axiom: A(x)\n";
  // Wherever the process runs, the name is found beside the grammar.
  ParseResult r = ParseGrammarFile(grammar);
  EXPECT_EQ(Word(r), "A(42)");

  auto errorFor = [&](const std::string& name) {
    std::ofstream(grammar) << "Start: { fp = fopen(\"" + name + "\", \"r\"); }\naxiom: A\n";
    return FirstError(ParseGrammarFile(grammar));
  };
  EXPECT_NE(errorFor("sub").find("is a directory, not a file"), std::string::npos)
      << errorFor("sub");
  EXPECT_NE(errorFor("/dev/zero").find("is not a regular file"), std::string::npos)
      << errorFor("/dev/zero");
  const std::string fifo = (dir / "obj" / "pipe").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_NE(errorFor("pipe").find("is not a regular file"), std::string::npos)  // never blocks
      << errorFor("pipe");
  {
    const std::string big = (dir / "obj" / "big.dat").string();
    const int fd = ::open(big.c_str(), O_CREAT | O_WRONLY, 0600);
    ASSERT_GE(fd, 0);
    ASSERT_EQ(::ftruncate(fd, off_t(kMaxDataFileBytes) + 1), 0);  // sparse: no disk used
    ::close(fd);
  }
  EXPECT_NE(errorFor("big.dat").find("larger than the limit of 16 MiB"), std::string::npos)
      << errorFor("big.dat");
}

TEST(CpfgDataFiles, BlocksThatStartWithFscanfOrSrandGoOnOverLines) {
  // vlab's paintbrush.field: `Start: {srand(1);` / `\tdx0 =` / `\tfunc(...);` / `}`.
  EXPECT_EQ(Word(ParseWith("Start: {srand(3);\n\tx =\n\t2;\n}\naxiom: A(x)\n", {})), "A(2)");
  EXPECT_EQ(Word(ParseWith("Start: {fp = fopen(\"n.dat\", \"r\");}\naxiom: A\n"
                           "A : {fscanf(fp, \"%lf\",\n   &x);} * --> B(x)\n",
                           {{"/obj/n.dat", "7"}}),
                 1),
            "B(7)");
}

TEST(CpfgDataFiles, ScanAgreesWithTheCLibrarysScanf) {
  // Differential: the C library's sscanf on the same text and format gives
  // the same count and values (fscanf differs from sscanf only at EOF,
  // where both return -1 before the first conversion).
  const char* formats[] = {"%lf",      "%lf %lf",  "x=%lf",  "%*s %lf", "%3lf%lf",
                           " %lf,%lf", "%lf\n%lf", "%*c%lf", "a %lf",   "%2lf %*3c%lf"};
  const char* inputs[] = {"1 2",     "x=3.5",     "abc 4",  "12345 6", "  -1e3,7",
                          "",        "   ",       "1,\n 2", "x= 2",    "a\t9",
                          "0x1p3 4", ".5e1 -.25", "1e",     "+7 x",    "12 34"};
  int compared = 0;
  for (const char* f : formats) {
    ScanFormat fmt;
    std::string why;
    ASSERT_TRUE(ParseScanFormat(f, &fmt, &why)) << f << ": " << why;
    ASSERT_LE(fmt.assignments, 2);
    for (const char* in : inputs) {
      CpfgDataFiles files(
          "", [in](const std::string&) -> Expected<std::string> { return std::string(in); });
      uint32_t id = 0;
      ASSERT_TRUE(files.Add("d", &id, &why)) << why;
      CpfgDataFiles::Call call;
      call.format = fmt;
      call.element.assign(size_t(fmt.assignments), 0);
      const uint32_t c = files.AddCall(call);
      double mine[2] = {-7, -7}, theirs[2] = {-7, -7};
      int count = 0;
      ASSERT_TRUE(files.Scan(files.Open(id), c, mine, &count, &why))
          << f << " on " << in << ": " << why;
      const int expected = std::sscanf(in, f, &theirs[0], &theirs[1]);
      EXPECT_EQ(count, expected) << "format '" << f << "' on '" << in << "'";
      for (int k = 0; k < fmt.assignments; ++k)
        EXPECT_EQ(mine[k], theirs[k]) << "format '" << f << "' on '" << in << "', value " << k;
      ++compared;
    }
  }
  EXPECT_EQ(compared, 150);
}

}  // namespace
}  // namespace sylva::lsys
