// cpfg's generalized-cylinder contours drawn by the turtle: @#(n), @!(s)
// and the frame of the cross-sections (turtle/interpreter.h).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "plant/plant_test_util.h"
#include "turtle/interpreter.h"

namespace sylva::turtle {
namespace {

// An open, nearly flat contour like a leaf's: x from -s to s, y at most
// 0.067 s (the B-spline of a bump of 0.1 s).
mesh::Contour Flat(double s) {
  mesh::Contour c;
  for (int k = 0; k < 3; ++k) c.points.push_back({-s, 0, 0});
  c.points.push_back({0, 0.1 * s, 0});
  for (int k = 0; k < 3; ++k) c.points.push_back({s, 0, 0});
  return c;
}

DrawOptions WithContours(bool twist) {
  auto c = std::make_shared<CylinderContours>();
  c->byId[1] = Flat(1);
  c->byId[2] = Flat(0.5);
  c->twist = twist;
  DrawOptions o;
  o.contours = c;
  return o;
}

mesh::PlantGeometry Draw(const std::string& axiom, const DrawOptions& o) {
  auto p = testing::PlantFromText("axiom: " + axiom + "\n", 0, plant::Stage::kGeometry, o);
  return p ? std::move(p->geometry) : mesh::PlantGeometry();
}

// The extent of ring r of a tube along the unit direction d.
double Extent(const mesh::ContourTube& t, size_t r, const Vec3& d) {
  double lo = 1e300, hi = -1e300;
  for (size_t j = 0; j < t.ringSize; ++j) {
    const double x = t.points[r * t.ringSize + j].dot(d);
    lo = std::min(lo, x);
    hi = std::max(hi, x);
  }
  return hi - lo;
}

TEST(TurtleContour, FlatContourMakesACylinderWideAlongUpAndThinAlongLeft) {
  // Width 2 (radius 1); the turtle starts with H = +y, L = -x, U = -z.
  // cpfg puts the contour's x along U and its y along -L.
  mesh::PlantGeometry g = Draw("#(2)@#(1)@Gs f(1) @Gc(4) f(1) @Ge(4)", WithContours(false));
  ASSERT_EQ(g.tubes.size(), 1u) << "the two pieces make one tube";
  EXPECT_TRUE(g.segments.empty());
  const mesh::ContourTube& t = g.tubes[0];
  EXPECT_EQ(t.ringSize, 9u);  // cpfg's default 8 sides, open: 9 points
  ASSERT_EQ(t.rings(), 9u);
  EXPECT_FALSE(t.closed);
  for (size_t r : {size_t(0), size_t(4), size_t(8)}) {
    const double up = Extent(t, r, Vec3(0, 0, 1)), left = Extent(t, r, Vec3(1, 0, 0));
    EXPECT_NEAR(up, 2.0, 1e-6) << "ring " << r << ": width along U " << up;
    EXPECT_LT(left, 0.07) << "ring " << r << ": thickness along L " << left;
    EXPECT_GT(left, 0.05) << "ring " << r << ": thickness along L " << left;
  }
  EXPECT_NEAR(t.points[8 * 9].y(), 2.0, 1e-12) << "the last ring is at the end of the axis";
  EXPECT_NEAR(g.boundsMax.z() - g.boundsMin.z(), 2.0, 1e-6);
}

TEST(TurtleContour, ContoursAreInterpolatedAlongAPiece) {
  // Contour 1 is 2 wide, contour 2 half as wide: the middle ring (t = 0.5)
  // is between.
  mesh::PlantGeometry g = Draw("#(2)@#(1)@Gs f(1) @#(2)@Ge(2)", WithContours(false));
  ASSERT_EQ(g.tubes.size(), 1u);
  const mesh::ContourTube& t = g.tubes[0];
  ASSERT_EQ(t.rings(), 3u);
  const Vec3 u(0, 0, 1);
  EXPECT_NEAR(Extent(t, 0, u), 2.0, 1e-9) << Extent(t, 0, u);
  EXPECT_NEAR(Extent(t, 1, u), 1.5, 1e-9) << Extent(t, 1, u);
  EXPECT_NEAR(Extent(t, 2, u), 1.0, 1e-9) << Extent(t, 2, u);
}

TEST(TurtleContour, TwistOfCylindersDecidesWhetherARollTurnsTheCrossSection) {
  // /(90) between the control points turns U from -z to +x.
  const std::string axiom = "#(2)@#(1)@Gs f(1) /(90) @Ge(2)";
  mesh::PlantGeometry off = Draw(axiom, WithContours(false));
  mesh::PlantGeometry on = Draw(axiom, WithContours(true));
  ASSERT_EQ(off.tubes.size(), 1u);
  ASSERT_EQ(on.tubes.size(), 1u);
  const Vec3 x(1, 0, 0), z(0, 0, 1);
  // Off (cpfg's default): the up is carried from the first point.
  EXPECT_NEAR(Extent(off.tubes[0], 2, z), 2.0, 1e-9) << Extent(off.tubes[0], 2, z);
  EXPECT_LT(Extent(off.tubes[0], 2, x), 0.07) << Extent(off.tubes[0], 2, x);
  // On: the last ring follows the turtle, the middle one is half way.
  EXPECT_NEAR(Extent(on.tubes[0], 2, x), 2.0, 1e-9) << Extent(on.tubes[0], 2, x);
  EXPECT_LT(Extent(on.tubes[0], 2, z), 0.07) << Extent(on.tubes[0], 2, z);
  const double mid = Extent(on.tubes[0], 1, x);
  EXPECT_NEAR(mid, 2 * std::cos(kPi / 4), 0.01) << "the middle ring turned 45 degrees: " << mid;
}

TEST(TurtleContour, SidesComeFromTheViewFileAndFromTheBang) {
  DrawOptions o = WithContours(false);
  auto c = std::make_shared<CylinderContours>(*o.contours);
  c->sides = 32;
  o.contours = c;
  mesh::PlantGeometry g = Draw("@#(1)@Gs F @Ge [@!(5)@Gs F @Ge] @!(1)@Gs F @Ge", o);
  ASSERT_EQ(g.tubes.size(), 3u);
  EXPECT_EQ(g.tubes[0].ringSize, 33u);
  EXPECT_EQ(g.tubes[1].ringSize, 6u);
  EXPECT_EQ(g.tubes[2].ringSize, 4u) << "@!(1) is 3 sides, as in cpfg";
}

TEST(TurtleContour, UnknownContourWarnsAndDrawsRound) {
  mesh::PlantGeometry g = Draw("@#(7)@Gs f @Ge(2)", WithContours(false));
  EXPECT_TRUE(g.tubes.empty());
  EXPECT_EQ(g.segments.size(), 2u);
  ASSERT_EQ(g.warnings.size(), 1u);
  EXPECT_NE(g.warnings[0].find("selects contour 7, which the view file does not give"),
            std::string::npos)
      << g.warnings[0];
  mesh::PlantGeometry none = Draw("@#(1)@Gs F @Ge(2)", DrawOptions{});
  EXPECT_TRUE(none.tubes.empty());
  ASSERT_EQ(none.warnings.size(), 1u);
  EXPECT_NE(none.warnings[0].find("is not in use"), std::string::npos) << none.warnings[0];
  // @# alone is the circle, without a word.
  mesh::PlantGeometry circle = Draw("@#(1)@#@Gs F @Ge(2)", WithContours(false));
  EXPECT_TRUE(circle.tubes.empty());
  EXPECT_TRUE(circle.warnings.empty());
}

TEST(TurtleContour, ContourTubesTessellateIntoQuadsWithUnitNormals) {
  mesh::PlantGeometry g = Draw("#(2)@#(1)@Gs f(1) @Gc(4) f(1) @Ge(4)", WithContours(false));
  mesh::TriangleMesh m;
  mesh::TessellateOptions opt;
  ASSERT_TRUE(mesh::Tessellate(g, opt, m).ok());
  EXPECT_EQ(m.triangleCount(), 2u * 8 * 8) << "8 spans of 8 quads";
  EXPECT_EQ(m.positions.size(), 81u);
  double worst = 0;
  for (const Vec3f& n : m.normals) worst = std::max(worst, std::abs(double(n.norm()) - 1));
  EXPECT_LT(worst, 1e-5) << "largest |normal| - 1: " << worst;
  const mesh::Box b = mesh::TessellatedBounds(g, nullptr);
  EXPECT_NEAR(b.hi.z() - b.lo.z(), 2.0, 1e-6);
}

TEST(TurtleContour, CylinderLineStyleIsNeverALineFigure) {
  // vlab's GeneralizedCylinder lies in the plane z = 0; cpfg draws it as a
  // cylinder (`line style: cylinder`), not as the lines of a 2D figure.
  const std::string axiom = "@Gs F + F @Gc F @Ge";
  mesh::PlantGeometry plain = Draw(axiom, DrawOptions{});
  EXPECT_TRUE(plant::IsLineFigure(plain));
  DrawOptions o;
  o.cylinderStyle = true;
  mesh::PlantGeometry cylinders = Draw(axiom, o);
  EXPECT_TRUE(cylinders.planar);
  EXPECT_FALSE(plant::IsLineFigure(cylinders));
}

}  // namespace
}  // namespace sylva::turtle
