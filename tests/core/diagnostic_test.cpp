#include "core/diagnostic.h"

#include <gtest/gtest.h>

#include "core/status.h"

namespace sylva {

TEST(Diagnostic, FormatsGccStyleWithExcerptAndCaret) {
  Diagnostic d = MakeError(SourceLoc{"grammars/tree.lsys", 14, 31}, "unknown name 'r3' in expression",
                           2, "A(l,w) --> !(w)F(l)[&(a0)B(l*r3,w*wr)]");
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
  Diagnostic d = MakeError(SourceLoc{"f", 1, 2}, "bad", 1, std::string("a\x01" "b", 3));
  EXPECT_NE(d.Format().find("a b"), std::string::npos) << d.Format();
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
