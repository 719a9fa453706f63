#include "mesh/contour.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace sylva::mesh {
namespace {

std::string Messages(const DiagnosticList& list) {
  std::string s;
  for (const Diagnostic& d : list.items) s += d.Format();
  return s;
}

TEST(Contour, ReadsThePointsOfTheOldFormat) {
  // vlab's thatcheria: `N DIMENSION open|closed`, the points free-form.
  auto c = ParseContour("5 3 open\n0 0 0\n1 0 0  2 0.5 0\n3 0 0\n4 0 0.25\n", "c.con");
  ASSERT_TRUE(c) << c.error().Format();
  EXPECT_FALSE(c->closed);
  ASSERT_EQ(c->points.size(), 5u);
  EXPECT_EQ(c->points[2], Vec3(2, 0.5, 0));
  EXPECT_EQ(c->points[4], Vec3(4, 0, 0.25));
  auto two = ParseContour("3 2 closed\n1 0\n0 1\n-1 0\n", "c.con");
  ASSERT_TRUE(two) << two.error().Format();
  EXPECT_TRUE(two->closed);
  EXPECT_EQ(two->points[1], Vec3(0, 1, 0));
}

TEST(Contour, ExpandsTheMultiplicitiesOfTheCverFormat) {
  // vlab's Tropisms stripe.con (cver 1 3), and a 1.2 file with a closed type.
  auto c = ParseContour(
      "cver 1 3\nname: noname\npoints: 4 8\ntype: or\nsamples: 8\n"
      "-0.018 -5.99 0 3\n-0.041 -1.34 0 1\n0.014 1.64 0 1\n0.018 5.95 0 3\n",
      "stripe.con");
  ASSERT_TRUE(c) << c.error().Format();
  EXPECT_FALSE(c->closed);
  ASSERT_EQ(c->points.size(), 8u);
  EXPECT_EQ(c->points[2], Vec3(-0.018, -5.99, 0));
  EXPECT_EQ(c->points[3], Vec3(-0.041, -1.34, 0));
  EXPECT_EQ(c->points[7], Vec3(0.018, 5.95, 0));
  auto closed = ParseContour(
      "cver 1 2\nname: x\npoints: 3 3\ntype: cr\n1 0 0 1\n0 1 0 1\n-1 -1 0 1\n", "x.con");
  ASSERT_TRUE(closed) << closed.error().Format();
  EXPECT_TRUE(closed->closed);
}

TEST(Contour, BadFilesAreErrorsAtTheirLineAndColumn) {
  auto at = [](const std::string& text) {
    auto c = ParseContour(text, "bad.con");
    if (c) return std::string("no error");
    return std::to_string(c.error().loc.line) + ":" + std::to_string(c.error().loc.column) + " " +
           c.error().message;
  };
  EXPECT_EQ(
      at("5 3 open\n1 2 3\n4 x 6\n").rfind("3:3 expected a number (coordinate 2 of point 2)", 0),
      0u)
      << at("5 3 open\n1 2 3\n4 x 6\n");
  EXPECT_EQ(at("4 3 opne\n").rfind("1:5 expected 'open' or 'closed', not 'opne'", 0), 0u)
      << at("4 3 opne\n");
  EXPECT_EQ(at("4 3 open\n1 2 3\n").rfind("2:6 the file ends before point 2 of 4", 0), 0u)
      << at("4 3 open\n1 2 3\n");
  const std::string sum = "cver 1 1\nname: a\npoints: 2 5\ntype: open\n0 0 0 3\n1 0 0 1\n";
  EXPECT_EQ(at(sum).rfind("3:11 the multiplicities add up to 4 points, not 5", 0), 0u) << at(sum);
  EXPECT_EQ(at("cver 2 0\n").rfind("1:6 contour format 2.0 is not one cpfg reads", 0), 0u)
      << at("cver 2 0\n");
  EXPECT_EQ(at("3 2 open\n0 0\n1 0\n2 0\n").rfind("1:1 an open contour needs at least 4", 0), 0u)
      << at("3 2 open\n0 0\n1 0\n2 0\n");
  EXPECT_EQ(at("4 2 open\n1 1\n1 1\n1 1\n1 1\n").rfind("1:1 every point of the contour", 0), 0u);
  EXPECT_EQ(at("version: 1.4\n").rfind("1:1 this is a cpfg curve file", 0), 0u);
  EXPECT_EQ(at("").rfind("1:1 an empty contour file", 0), 0u);
}

TEST(Contour, WarnsAboutEndPointTypeAndTrailingText) {
  DiagnosticList w;
  auto c = ParseContour("cver 1 2\nname: a\npoints: 2 4\ntype: oe\n0 0 0 2\n1 0 0 2\nmore\n",
                        "a.con", &w);
  ASSERT_TRUE(c) << c.error().Format();
  ASSERT_EQ(w.items.size(), 2u) << Messages(w);
  EXPECT_EQ(w.items[0].loc.line, 4);
  EXPECT_NE(w.items[0].message.find("drawn as a regular one"), std::string::npos);
  EXPECT_EQ(w.items[1].loc.line, 7);
}

TEST(Contour, OpenContourSamplesRunEvenlyFromEndToEnd) {
  // A straight B-spline whose end points are tripled runs from the first
  // point to the last; its samples are spaced evenly by length.
  Contour c;
  c.points = {{-1, 0, 0}, {-1, 0, 0}, {-1, 0, 0}, {0.7, 0, 0}, {1, 0, 0}, {1, 0, 0}, {1, 0, 0}};
  const std::vector<Vec3> s = SampleContour(c, 8);
  ASSERT_EQ(s.size(), 9u);
  double worst = 0;
  for (int i = 0; i <= 8; ++i) worst = std::max(worst, std::abs(s[size_t(i)].x() - (-1 + i / 4.0)));
  EXPECT_LT(worst, 1e-3) << "largest distance of a sample from its even place: " << worst;
}

TEST(Contour, ClosedContourIsTurnedToStartOnPlusXAndCloses) {
  // A square of control points, its first at (0, 1): turned a quarter.
  Contour c;
  c.closed = true;
  c.points = {{0, 1, 0}, {-1, 0, 0}, {0, -1, 0}, {1, 0, 0}};
  const std::vector<Vec3> s = SampleContour(c, 16);
  ASSERT_EQ(s.size(), 17u);
  EXPECT_GT(s[0].x(), 0.5) << s[0].transpose();
  EXPECT_NEAR(s[0].y(), 0, 1e-12) << s[0].transpose();
  EXPECT_EQ(s[16], s[0]);
  // Evenly spaced: consecutive chords within 5% of each other.
  double lo = 1e9, hi = 0;
  for (int i = 0; i < 16; ++i) {
    const double d = (s[size_t(i) + 1] - s[size_t(i)]).norm();
    lo = std::min(lo, d);
    hi = std::max(hi, d);
  }
  EXPECT_LT(hi / lo, 1.05) << "chords from " << lo << " to " << hi;
  const std::vector<Vec3> circle = CircleContour(4);
  EXPECT_EQ(circle.size(), 5u);
  EXPECT_NEAR((circle[1] - Vec3(0, 1, 0)).norm(), 0, 1e-12);
}

TEST(Contour, TinyAndHugeContoursAreMeasuredAtUnitScale) {
  // A contour of 1e-300 units: its squared lengths underflow to 0, and it
  // was rejected as "every point at the same (x, y)". It is read, and
  // sampled as the same shape at unit size, scaled.
  const std::string unit = "4 3 closed\n1 0 0\n0 1 0\n-1 0 0\n0 -1 0\n";
  auto a = ParseContour(unit, "u.con");
  ASSERT_TRUE(a) << a.error().Format();
  const std::vector<Vec3> ref = SampleContour(*a, 8);
  for (double scale : {1e-300, 1e300}) {
    Contour c = *a;
    for (Vec3& p : c.points) p *= scale;
    char text[256];
    std::snprintf(text, sizeof text, "4 3 closed\n%g 0 0\n0 %g 0\n%g 0 0\n0 %g 0\n", scale, scale,
                  -scale, -scale);
    auto parsed = ParseContour(text, "s.con");
    ASSERT_TRUE(parsed) << "scale " << scale << ": " << parsed.error().Format();
    const std::vector<Vec3> got = SampleContour(c, 8);
    ASSERT_EQ(got.size(), ref.size());
    for (size_t i = 0; i < got.size(); ++i)
      EXPECT_LT((got[i] / scale - ref[i]).norm(), 1e-12)
          << "scale " << scale << " point " << i << ": " << got[i].transpose() / scale;
  }
}

}  // namespace
}  // namespace sylva::mesh
