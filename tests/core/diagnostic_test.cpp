#include "core/diagnostic.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "core/status.h"

namespace sylva {

TEST(Diagnostic, FormatsGccStyleWithExcerptAndCaret) {
  Diagnostic d =
      MakeError(SourceLoc{"grammars/tree.lsys", 14, 31}, "unknown name 'r3' in expression", 2,
                "A(l,w) --> !(w)F(l)[&(a0)B(l*r3,w*wr)]");
  std::string s = d.Format();
  EXPECT_EQ(s,
            "grammars/tree.lsys:14:31: error: unknown name 'r3' in expression\n"
            "   14 | A(l,w) --> !(w)F(l)[&(a0)B(l*r3,w*wr)]\n"
            "      |                               ^~\n")
      << s;
}

TEST(Diagnostic, WarningAndNoLocation) {
  Diagnostic d;
  d.severity = Severity::kWarning;
  d.message = "something";
  EXPECT_EQ(d.Format(), "sylva: warning: something\n");
}

TEST(Diagnostic, ControlBytesInExcerptBecomeSpaces) {
  Diagnostic d = MakeError(SourceLoc{"f", 1, 2}, "bad", 1,
                           std::string("a\x01"
                                       "b",
                                       3));
  EXPECT_NE(d.Format().find("a b"), std::string::npos) << d.Format();
}

// The two excerpt lines of a formatted diagnostic, without their gutters.
std::pair<std::string, std::string> Excerpt(const Diagnostic& d) {
  std::string s = d.Format();
  size_t a = s.find('\n'), b = s.find('\n', a + 1), c = s.find('\n', b + 1);
  std::string text = s.substr(a + 1, b - a - 1), caret = s.substr(b + 1, c - b - 1);
  return {text.substr(text.find(" | ") + 3), caret.substr(caret.find(" |") + 3)};
}

TEST(Diagnostic, LongLineShowsABoundedWindowAroundTheColumn) {
  // A 20 MB line used to be printed whole with every diagnostic.
  std::string line(20'000'000, 'a');
  line.replace(10'000'000, 3, "XYZ");
  Diagnostic d = MakeError(SourceLoc{"big", 1, 10'000'001}, "here", 3, line);
  EXPECT_LT(d.sourceLine.size(), 1000u) << "kept bytes";
  std::string s = d.Format();
  EXPECT_LT(s.size(), 300u) << s;
  auto [text, caret] = Excerpt(d);
  EXPECT_EQ(text.substr(0, 3), "...") << text;
  EXPECT_EQ(text.substr(text.size() - 3), "...") << text;
  EXPECT_LE(text.size(), 106u) << text;
  size_t at = caret.find('^');
  ASSERT_NE(at, std::string::npos) << caret;
  EXPECT_EQ(text.substr(at, 3), "XYZ") << text << "\n" << caret;
  EXPECT_EQ(caret.substr(at), "^~~") << caret;
  // Near the start: no left mark.
  Diagnostic e = MakeError(SourceLoc{"big", 1, 5}, "here", 1, line);
  EXPECT_EQ(Excerpt(e).first.substr(0, 4), "aaaa");
  EXPECT_EQ(Excerpt(e).second, "    ^");
}

TEST(Diagnostic, InvalidUtf8IsEscapedAndTheCaretStaysAligned) {
  // "é" (2 bytes, 1 column), then a stray \xff byte, then the error at 'Q'.
  std::string line = "A\xc3\xa9\xff Q";
  Diagnostic d = MakeError(SourceLoc{"u", 1, 6}, "bad", 1, line);
  auto [text, caret] = Excerpt(d);
  EXPECT_EQ(text, "A\xc3\xa9\\xff Q");
  EXPECT_EQ(caret, std::string(7, ' ') + "^") << text << "\n" << caret;
  // A caret on the bad byte underlines its escape.
  Diagnostic e = MakeError(SourceLoc{"u", 1, 4}, "bad", 1, line);
  EXPECT_EQ(Excerpt(e).second, "  ^~~~");
  // Messages and file names are escaped too.
  Diagnostic f = MakeError(SourceLoc{"x\xfe", 0, 0}, std::string("name '\x01\xff'"));
  EXPECT_EQ(f.Format(), "x\\xfe: error: name '\\x01\\xff'\n");
}

TEST(DiagnosticList, FormatAllStopsAfterMaxErrors) {
  DiagnosticList list;
  for (int i = 0; i < 50; ++i)
    list.Add(MakeError(SourceLoc{"f", i + 1, 1}, std::string("e").append(std::to_string(i))));
  std::string s = list.FormatAll(20);
  size_t lines = size_t(std::count(s.begin(), s.end(), '\n'));
  EXPECT_EQ(lines, 21u) << s;
  EXPECT_NE(s.find("f:20:1: error: e19\n"), std::string::npos) << s;
  EXPECT_EQ(s.find("e20"), std::string::npos) << s;
  EXPECT_NE(s.find("sylva: note: 30 more errors not shown\n"), std::string::npos) << s;
  std::string all = list.FormatAll();
  EXPECT_EQ(std::count(all.begin(), all.end(), '\n'), 50) << "no limit";
}

TEST(Expected, CarriesValueOrError) {
  Expected<int> ok = 5;
  ASSERT_TRUE(ok.ok());
  EXPECT_EQ(*ok, 5);
  Expected<int> bad = MakeError(SourceLoc{"x", 1, 1}, "nope");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().message, "nope");
}

}  // namespace sylva
