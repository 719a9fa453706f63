// cpfg's pixel line widths (mesh/pixel_widths.h): a segment whose width is
// N pixels is N pixels wide on screen, near or far.
#include "mesh/pixel_widths.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "mesh/tessellator.h"
#include "view_test_util.h"

namespace sylva::mesh {
namespace {

Vec2 Pixel(const ScreenView& v, const Vec3& p) {
  const Vec4 c = v.viewProjection * Vec4(p.x(), p.y(), p.z(), 1);
  return Vec2((c.x() / c.w() + 1) * 0.5 * v.width, (c.y() / c.w() + 1) * 0.5 * v.height);
}

// Distance in pixels from q to the line through a and b.
double ToLine(const Vec2& q, const Vec2& a, const Vec2& b) {
  const Vec2 d = (b - a).normalized();
  const Vec2 r = q - a;
  return std::abs(r.x() * d.y() - r.y() * d.x());
}

Segment Horizontal(const Vec3& start, double length, float radiusPx, uint32_t branch) {
  Segment s;
  s.start = start;
  s.end = start + Vec3(length, 0, 0);
  s.left = Vec3(0, 1, 0);
  s.radiusStart = s.radiusEnd = radiusPx;
  s.branch = s.parent = branch;
  return s;
}

// A width under one pixel is drawn one pixel wide, as cpfg's GL lines are
// (L-studio's cloud_I(line): 0.05 pixels, drawn before as faint coverage).
TEST(PixelWidths, AWidthUnderOnePixelIsOnePixelWide) {
  PlantGeometry g;
  g.segments.push_back(Horizontal(Vec3(-1, 0, 0), 2, 0.025f, 0));  // 0.05 px wide
  g.segments.push_back(Horizontal(Vec3(-1, 1, 0), 2, 1.5f, 1));    // 3 px: unchanged
  g.widthInPixels = true;
  g.boundsMin = Vec3(-1, 0, 0);
  g.boundsMax = Vec3(1, 1, 0);
  ScreenView view;
  view.width = 400;
  view.height = 300;
  view.viewProjection = testing::LookAtPerspective(Vec3(0, 0, 5), Vec3(0, 0, 0), 35, 4.0 / 3.0);
  const PlantGeometry out = ResolvePixelWidths(g, &view);
  ASSERT_EQ(out.segments.size(), 2u);
  // Pixels per world unit near the segments (z = 0; within 3 % across them).
  const double ppu = (Pixel(view, Vec3(0, 1, 0)) - Pixel(view, Vec3(0, 0, 0))).norm();
  EXPECT_NEAR(2 * out.segments[0].radiusStart * ppu, 1.0, 0.03)
      << "a 0.05 px line drawn " << 2 * out.segments[0].radiusStart * ppu << " px wide";
  EXPECT_NEAR(2 * out.segments[1].radiusStart * ppu, 3.0, 0.09)
      << 2 * out.segments[1].radiusStart * ppu;
}

TEST(PixelWidths, SegmentsAreTheirWidthInPixelsNearAndFar) {
  // Two segments 2 px wide (radius 1 px), one 5 units from the eye and one
  // 45: drawn as world units they would differ ninefold on screen.
  PlantGeometry g;
  g.segments.push_back(Horizontal(Vec3(-1, 0.5, 0), 2, 1.0f, 0));
  g.segments.push_back(Horizontal(Vec3(-8, -3, -40), 16, 1.0f, 1));
  g.widthInPixels = true;
  g.boundsMin = Vec3(-8, -3, -40);
  g.boundsMax = Vec3(8, 0.5, 0);
  ScreenView view;
  view.width = 400;
  view.height = 300;
  view.viewProjection = testing::LookAtPerspective(Vec3(0, 0, 5), Vec3(0, 0, 0), 35, 4.0 / 3.0);
  TessellateOptions o;
  o.view = view;
  o.cull = false;
  TriangleMesh m;
  TessellateStats stats;
  ASSERT_TRUE(Tessellate(g, o, m, &stats).ok());
  EXPECT_TRUE(stats.warnings.empty());
  ASSERT_GT(m.positions.size(), 0u);
  const Vec2 a0 = Pixel(view, g.segments[0].start), a1 = Pixel(view, g.segments[0].end);
  const Vec2 b0 = Pixel(view, g.segments[1].start), b1 = Pixel(view, g.segments[1].end);
  double halfA = 0, halfB = 0;
  for (const Vec3f& p : m.positions) {
    const Vec2 q = Pixel(view, p.cast<double>());
    const double da = ToLine(q, a0, a1), db = ToLine(q, b0, b1);
    if (da < db)
      halfA = std::max(halfA, da);
    else
      halfB = std::max(halfB, db);
  }
  EXPECT_NEAR(halfA, 1.0, 0.02) << "near segment: half its drawn width in pixels";
  EXPECT_NEAR(halfB, 1.0, 0.02) << "far segment: half its drawn width in pixels";
}

TEST(PixelWidths, ResolvedRadiiScaleWithDistanceAndBoundsIgnoreThem) {
  PlantGeometry g;
  g.segments.push_back(Horizontal(Vec3(0, 0, 0), 1, 3.0f, 0));
  g.segments.push_back(Horizontal(Vec3(0, 0, -45), 1, 3.0f, 1));
  g.widthInPixels = true;
  g.boundsMin = Vec3(0, 0, -45);
  g.boundsMax = Vec3(1, 0, 0);
  ScreenView view;
  view.viewProjection = testing::LookAtPerspective(Vec3(0, 0, 5), Vec3(0, 0, 0), 35, 16.0 / 9);
  const PlantGeometry r = ResolvePixelWidths(g, &view);
  EXPECT_FALSE(r.widthInPixels);
  // 3 px at the eye's distance 5 and 50: about ten times as wide in the world.
  const double ratio = r.segments[1].radiusStart / r.segments[0].radiusStart;
  EXPECT_NEAR(ratio, 10.0, 0.5) << "far over near world radius";
  EXPECT_NEAR(
      r.segments[0].radiusStart * PixelOffset(view, g.segments[0].start, Vec3(0, 1, 0)).norm(), 3.0,
      1e-4);
  // Without a view: a pixel is 1/kNominalPixels of the largest extent (45).
  const PlantGeometry n = ResolvePixelWidths(g, nullptr);
  EXPECT_NEAR(n.segments[0].radiusStart, 3.0 * 45 / kNominalPixels, 1e-6);
  // The box framing a camera holds the axes only (the pixels are nothing in world units).
  const Box b = TessellatedBounds(g, nullptr);
  EXPECT_NEAR(b.hi.y(), 0.0, 1e-12) << "a 3-unit radius would reach y = 3";
  EXPECT_NEAR(b.lo.z(), -45.0, 1e-12);
}

TEST(PixelWidths, WithoutAViewTheTessellatorWarns) {
  PlantGeometry g;
  g.segments.push_back(Horizontal(Vec3(0, 0, 0), 10, 1.0f, 0));
  g.widthInPixels = true;
  g.boundsMax = Vec3(10, 0, 0);
  TriangleMesh m;
  TessellateStats stats;
  ASSERT_TRUE(Tessellate(g, TessellateOptions{}, m, &stats).ok());
  ASSERT_EQ(stats.warnings.size(), 1u);
  EXPECT_NE(stats.warnings[0].find("the widths are pixels"), std::string::npos)
      << stats.warnings[0];
  float widest = 0;
  for (const Vec3f& p : m.positions) widest = std::max(widest, std::abs(p.y()));
  EXPECT_NEAR(widest, 10.0f / kNominalPixels, 1e-5f);
}

}  // namespace
}  // namespace sylva::mesh
