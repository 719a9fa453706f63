// cpfg arrays (`define: { array a[3]; }`, a[i] in expressions and
// assignments) and srand(seed) in the Start: block.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "lsys/parser.h"
#include "lsys_test_util.h"

namespace sylva::lsys {
namespace {

using testing::DeriveText;
using testing::FirstError;
using testing::MustParse;

TEST(CpfgArrays, InitialisedArraysAreReadRowMajor) {
  const std::string text =
      "define: { array a[3] = {10, 20, 30}, m[2][2] = {1, 2, 3, 4}; array z[2]; }\n"
      "axiom: A(0)\n"
      "A(i) : i < 3 --> B(a[i], m[1][0], m[0][1], z[1]) A(i+1)\n";
  EXPECT_EQ(DeriveText(text, 4), "B(10,3,2,0)B(20,3,2,0)B(30,3,2,0)A(3)");
  Grammar g = MustParse(text);
  ASSERT_EQ(g.arrays.size(), 3u);
  EXPECT_EQ(g.arrays[1].dims, (std::vector<uint32_t>{2, 2}));
}

TEST(CpfgArrays, AssignedInStartAndInProductionsInWordOrder) {
  // Start: fills c with squares; the axiom is built after it. Each A(k)
  // adds 1 to c[k] before its successor reads it, left to right.
  const std::string text =
      "define: {\n  array c[4];\n}\n"
      "Start: { i = 0; while (i < 4) { c[i] = i*i; i = i + 1; } }\n"
      "axiom: X(c[3]) A(1) A(1) A(2)\n"
      "A(k) : { c[k] = c[k] + 1; } * --> B(c[k])\n";
  EXPECT_EQ(DeriveText(text, 0), "X(9)A(1)A(1)A(2)");
  EXPECT_EQ(DeriveText(text, 1), "X(9)B(2)B(3)B(5)");
}

// "line:col message" of the array warnings after a derivation.
std::vector<std::string> ArrayWarnings(const Grammar& g) {
  std::vector<std::string> out;
  if (!g.arrayBounds) return out;
  for (const Diagnostic& d : g.arrayBounds->Warnings())
    out.push_back(std::to_string(d.loc.line) + ":" + std::to_string(d.loc.column) + " " +
                  d.message);
  return out;
}

TEST(CpfgArrays, IndexOutOfBoundsUsesTheNearestElementAndWarnsOncePerArray) {
  // vlab's CelticKnot reads turn0[7] of a 7-element array in its
  // homomorphism; cpfg's Eval warns and uses the last element (index 0 for a
  // negative index), for reads and writes alike.
  Grammar g = MustParse(
      "define: { array a[3] = {10, 20, 30}; }\naxiom: A(0)\nA(i) --> B(a[i]) C(a[i-1]) A(i+1)\n");
  DeriveOptions o;
  o.steps = 4;
  auto r = Derive(g, o);
  ASSERT_TRUE(r) << r.error().Format();
  EXPECT_EQ(FormatWord(r->word, g.symbols), "B(10)C(10)B(20)C(10)B(30)C(20)B(30)C(30)A(4)");
  auto w = ArrayWarnings(g);
  ASSERT_EQ(w.size(), 1u) << testing::Joined(w);  // once per array: its first site
  EXPECT_EQ(w[0].rfind("3:12 index 3 of array 'a' is outside 0 to 2: Sylva uses element 2", 0), 0u)
      << w[0];
  // A store at a negative second index writes element [0][0].
  Grammar s = MustParse(
      "define: { array a[2][2]; }\naxiom: A(-1)\nA(i) : { a[0][i] = 7; } * --> B(a[0][0])\n");
  o.steps = 1;
  auto rs = Derive(s, o);
  ASSERT_TRUE(rs) << rs.error().Format();
  EXPECT_EQ(FormatWord(rs->word, s.symbols), "B(7)");
  auto ws = ArrayWarnings(s);
  ASSERT_EQ(ws.size(), 1u) << testing::Joined(ws);
  EXPECT_EQ(ws[0].rfind("3:10 index -1 of array 'a' (its index 2) is outside 0 to 1: Sylva uses "
                        "element 0",
                        0),
            0u)
      << ws[0];
  // Without out-of-bounds indices, no warning.
  Grammar ok = MustParse("define: { array a[3]; }\naxiom: A(0)\nA(i) --> B(a[i])\n");
  ASSERT_TRUE(Derive(ok, o));
  EXPECT_TRUE(ArrayWarnings(ok).empty()) << testing::Joined(ArrayWarnings(ok));
}

TEST(CpfgArrays, DeclarationAndUseErrorsHaveLocations) {
  EXPECT_EQ(FirstError("define: { array a[0]; }\naxiom: A\n"),
            "1:19 an array size must be a whole number from 1 to 1048576");
  EXPECT_EQ(FirstError("define: { array a[2] = {1, 2, 3}; }\naxiom: A\n"),
            "1:31 more values than the 2 elements of 'a'");
  EXPECT_EQ(FirstError("define: { external e; }\naxiom: A\n"),
            "1:11 'external' definitions (cpfg, for environment programs) are not supported");
  EXPECT_EQ(FirstError("define: { array a[2]; }\naxiom: A(a[1][0])\n"),
            "2:14 array 'a' has 1 dimension");
  EXPECT_EQ(FirstError("define: { array a[2]; }\naxiom: A(a)\n"),
            "2:10 array 'a' needs 1 index: a[i]");
  EXPECT_EQ(FirstError("axiom: A\nA : { b[0] = 1; } * --> B\n"),
            "2:7 'b' is not an array (arrays are declared in 'define: { array b[n]; }')");
  EXPECT_EQ(FirstError("define: { array a[2]; }\naxiom: A\nA : { a[0] += 1; } * --> B\n"),
            "3:12 compound assignment to an array element is not supported: write 'a[...] = "
            "a[...] + ...'");
  EXPECT_EQ(FirstError("#define a 2\ndefine: { array a[2]; }\naxiom: A\n"),
            "2:17 'a' is already a constant, variable or array");
}

TEST(CpfgSrand, InStartItSetsTheSeedLikeSeedStatement) {
  const std::string rules = "axiom: A A A A A A A A\nA --> B : 1\nA --> C : 1\n";
  const std::string viaSeed = DeriveText("seed: 42\n" + rules, 1);
  EXPECT_EQ(DeriveText("Start: { srand(40 + 2); }\n" + rules, 1), viaSeed);
  EXPECT_NE(DeriveText("seed: 43\n" + rules, 1), viaSeed);  // the seed matters here
  // A seed given to the derivation wins, as it does over `seed:`.
  DeriveOptions o;
  o.seed = 43;
  EXPECT_EQ(DeriveText("Start: { srand(42); }\n" + rules, 1, o), DeriveText(rules, 1, o));
}

}  // namespace
}  // namespace sylva::lsys
