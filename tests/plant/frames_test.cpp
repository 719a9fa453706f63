// cpfg's overlaid animation frames (plant/frames.h).
#include "plant/frames.h"

#include <gtest/gtest.h>

#include <set>

namespace sylva::plant {
namespace {

PlantSpec SpecOf(const std::string& text) {
  PlantSpec spec;
  spec.text = text;
  spec.path = "frames.l";
  return spec;
}

TEST(Frames, UnionOfEveryFrameWithDisjointBranchesPastTheDerivationLength) {
  // F doubles each step: frames 0..3 draw 1 + 2 + 4 + 8 segments, although
  // the grammar's own derivation length is 1 (cpfg's animation goes on).
  DiagnosticList d;
  auto g = DrawFrames(SpecOf("derivation length: 1\naxiom: F\nF --> F F\n"), {0, 3, 1}, d);
  ASSERT_TRUE(g.ok()) << d.FormatAll();
  EXPECT_EQ(g->segments.size(), 15u);
  EXPECT_NEAR(g->boundsMax.y(), 8.0, 1e-12);
  // Each frame's segments are a branch of their own: frame k's one chain
  // never joins another frame's.
  std::set<uint32_t> branches;
  for (const mesh::Segment& s : g->segments) branches.insert(s.branch);
  EXPECT_EQ(branches.size(), 4u);
  // Every second frame from 1: frames 1 and 3.
  auto odd = DrawFrames(SpecOf("axiom: F\nF --> F F\n"), {1, 3, 2}, d);
  ASSERT_TRUE(odd.ok());
  EXPECT_EQ(odd->segments.size(), 10u);
  // A negative last frame is the derivation length (cpfg's `last frame: -1`).
  auto toEnd = DrawFrames(SpecOf("derivation length: 2\naxiom: F\nF --> F F\n"), {0, -1, 1}, d);
  ASSERT_TRUE(toEnd.ok());
  EXPECT_EQ(toEnd->segments.size(), 7u);
}

TEST(Frames, BadRangesAndTooMuchAreErrors) {
  DiagnosticList d;
  auto bad = DrawFrames(SpecOf("axiom: F\n"), {3, 2, 1}, d);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("expected 0 <= first <= last"), std::string::npos)
      << bad.error().message;
  EXPECT_FALSE(DrawFrames(SpecOf("axiom: F\n"), {0, 2, 0}, d).ok());
  PlantSpec big = SpecOf("axiom: F\nF --> F F\n");
  big.limits.maxTriangles = 4 * 20;  // 20 primitives
  auto over = DrawFrames(big, {0, 4, 1}, d);
  ASSERT_FALSE(over.ok());
  EXPECT_NE(over.error().message.find("draw more than 20 primitives"), std::string::npos)
      << over.error().message;
}

}  // namespace
}  // namespace sylva::plant
