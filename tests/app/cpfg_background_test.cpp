// cpfg background scenes (app/cpfg_background.h; vlab cpfg/background.c):
// the primitives, placed by the matrix stack, and their colours.
#include "app/cpfg_background.h"

#include <gtest/gtest.h>

#include <string>

namespace sylva::app {
namespace {

BackgroundScene MustParse(const std::string& text) {
  DiagnosticList warnings;
  auto s = ParseBackgroundScene(text, "bg.dat", warnings);
  EXPECT_TRUE(s) << (s ? "" : s.error().Format());
  return s ? *s : BackgroundScene{};
}

std::string FirstError(const std::string& text) {
  DiagnosticList warnings;
  auto s = ParseBackgroundScene(text, "bg.dat", warnings);
  if (s) return "<no error>";
  return std::to_string(s.error().loc.line) + ":" + std::to_string(s.error().loc.column) + " " +
         s.error().message;
}

TEST(CpfgBackground, BoxIsPlacedByTheMatrixStack) {
  const BackgroundScene s = MustParse(
      "#define W 2 /* width */\n"
      "pushmatrix\n translate 1 2 3\n box W 1 1 // a box\npopmatrix\n"
      "prism 1 1 1\n");
  ASSERT_EQ(s.polygons.size(), 12u);  // two boxes of six faces
  Vec3 lo = Vec3::Constant(1e9), hi = Vec3::Constant(-1e9);
  for (size_t i = 0; i < 6; ++i)
    for (const Vec3& v : s.polygons[i].vertices) {
      lo = lo.cwiseMin(v);
      hi = hi.cwiseMax(v);
    }
  EXPECT_TRUE(lo.isApprox(Vec3(1, 2, 3))) << lo.transpose();
  EXPECT_TRUE(hi.isApprox(Vec3(3, 3, 4))) << hi.transpose();
  // After popmatrix: at the origin again.
  for (const Vec3& v : s.polygons[6].vertices) EXPECT_LE(v.maxCoeff(), 1.0) << v.transpose();
}

TEST(CpfgBackground, RotateScaleAndMultmatrixFollowOpenGL) {
  // rotate 90 about z takes x to y; scale moves the sphere, not its radius.
  BackgroundScene s = MustParse("rotate 90 0 0 1\nscale 3 3 3\ntranslate 1 0 0\nsphere 0.5\n");
  ASSERT_EQ(s.spheres.size(), 1u);
  EXPECT_NEAR((s.spheres[0].center - Vec3(0, 3, 0)).norm(), 0, 1e-12)
      << s.spheres[0].center.transpose();
  EXPECT_EQ(s.spheres[0].radius, 0.5);
  // multmatrix column by column: the translation is m12 m13 m14.
  s = MustParse("multmatrix\n0 1 0 0\n-1 0 0 0\n0 0 1 0\n1 3 0 1\nsphere 1\n");
  ASSERT_EQ(s.spheres.size(), 1u);
  EXPECT_TRUE(s.spheres[0].center.isApprox(Vec3(1, 3, 0))) << s.spheres[0].center.transpose();
  s = MustParse("multmatrix 0 1 0 0 -1 0 0 0 0 0 1 0 0 0 0 1\npolygon 1 0 0 0 0 0 0 1 0\n");
  ASSERT_EQ(s.polygons.size(), 1u);
  EXPECT_TRUE(s.polygons[0].vertices[0].isApprox(Vec3(0, 1, 0)))
      << s.polygons[0].vertices[0].transpose();
}

TEST(CpfgBackground, CylinderRunsAlongYAndMaterialsColourWhatFollows) {
  DiagnosticList warnings;
  auto s = ParseBackgroundScene(
      "cylinder 0.3 2\nmaterial\n0 0 0 1\n0.5 0.2 0.1 0.4\n0 0 0 1\n0 0 0 1\n9\ncone 1 0 2\n",
      "bg.dat", warnings);
  ASSERT_TRUE(s) << s.error().Format();
  // 24 sides and two caps each; the cone's top (radius 0) has no cap.
  ASSERT_EQ(s->polygons.size(), 26u + 25u);
  double top = -1, radius = 0;
  for (const Vec3& v : s->polygons[0].vertices) {
    top = std::max(top, v.y());
    radius = std::max(radius, std::hypot(v.x(), v.z()));
  }
  EXPECT_NEAR(top, 2, 1e-12) << top;
  EXPECT_NEAR(radius, 0.3, 1e-12) << radius;
  EXPECT_EQ(s->polygons[0].color, 0);   // before any material
  EXPECT_EQ(s->polygons[26].color, 1);  // the first material
  ASSERT_EQ(s->colors.size(), 1u);
  EXPECT_FLOAT_EQ(s->colors[0][0], 0.5f);
  ASSERT_EQ(warnings.items.size(), 1u);  // alpha 0.4: drawn opaque
  EXPECT_EQ(warnings.items[0].loc.line, 2) << warnings.items[0].Format();

  // Added to a plant: its colours after a palette padded to 256.
  mesh::PlantGeometry g;
  mesh::Palette palette(8, Vec3f(1, 1, 1));
  AddBackgroundScene(*s, g, palette);
  ASSERT_EQ(palette.size(), 257u);
  EXPECT_EQ(g.polygons.back().color, 256);
  EXPECT_FALSE(g.planar);
  EXPECT_NEAR(g.boundsMax.y(), 2, 1e-12) << g.boundsMax.transpose();
}

TEST(CpfgBackground, ErrorsAreLocated) {
  EXPECT_EQ(FirstError("box 1 1 1\n  teapot 2\n"), "2:3 unknown background scene keyword 'teapot'");
  EXPECT_EQ(FirstError("popmatrix\n"), "1:1 'popmatrix' without its 'pushmatrix'");
  EXPECT_EQ(FirstError("\nsphere\n"), "2:1 'sphere' needs 1 numbers (radius), given 0");
  // Negative radii were drawn (inside-out frustums, spheres of radius -1).
  EXPECT_EQ(FirstError("sphere -1\n"),
            "1:1 'sphere' has a negative radius (-1): a radius is 0 or more");
  EXPECT_EQ(FirstError("box 1 1 1\n cylinder -0.5 2\n"),
            "2:2 'cylinder' has a negative radius (-0.5): a radius is 0 or more");
  EXPECT_EQ(FirstError("cone 1 -2 3\n"),
            "1:1 'cone' has a negative radius (-2): a radius is 0 or more");
  EXPECT_EQ(FirstError("#include \"x.dat\"\n"),
            "1:1 preprocessor line '#include' is not supported in a background scene (#define "
            "and #undef are)");
  // Was read as a scene with nothing after the '/*' (the box not drawn).
  EXPECT_EQ(FirstError("sphere 1\n  /* never closed\nbox 1 1 1\n"),
            "2:3 a '/*' comment that is never closed with '*/'");
}

// Hostile scenes end in a located error, not in memory exhaustion or a
// mesh whose points are not finite (unlocated "vertex 0 is not finite").
TEST(CpfgBackground, HugeScenesAreLocatedErrors) {
  // A #define of 1,000 words used 9,000 times: 9M words (was accepted,
  // ~0.4 GB; 200,000 uses took 1.3 GB and ran out of memory, unlocated).
  std::string bomb = "#define A";
  for (int i = 0; i < 1000; ++i) bomb += " 1";
  bomb += "\nsphere A\n";
  for (int i = 0; i < 9000; ++i) bomb += "A ";
  const std::string words = FirstError(bomb);
  EXPECT_EQ(words.rfind("3:", 0), 0u) << words;
  EXPECT_NE(words.find("more than 8388608 words"), std::string::npos) << words;
  // 30,000 cylinders: 144 vertices each, 4.32M in all (1.2M cylinders took
  // over 4 GB before).
  std::string cylinders;
  for (int i = 0; i < 30000; ++i) cylinders += "cylinder 1 1\n";
  const std::string many = FirstError(cylinders);
  EXPECT_EQ(many.rfind("29128:1 the background scene has more than 4194304 vertices", 0), 0u)
      << many;
}

TEST(CpfgBackground, PointsBeyondTheTurtlesRangeAreLocatedErrors) {
  EXPECT_EQ(FirstError("scale 1e300 1e300 1e300\nscale 1e300 1 1\nbox 1 1 1\n"),
            "3:1 'box' places a point that is not a finite number within +-1e+15 units (the "
            "matrix or the numbers are too large)");
  EXPECT_EQ(FirstError("box 1 1 1\n  polygon 0 0 0 1 0 0 0 1e16 0\n"),
            "2:3 'polygon' places a point that is not a finite number within +-1e+15 units (the "
            "matrix or the numbers are too large)");
  EXPECT_EQ(FirstError("sphere 1e308\n"),
            "1:1 'sphere' has a centre or radius that is not a finite number within +-1e+15 "
            "units");
  std::string materials;
  for (int i = 0; i <= 32768; ++i) materials += "material 0 0 0 1 1 1 1 1\n";
  EXPECT_EQ(FirstError(materials), "32769:1 more than 32768 materials in a background scene");
}

}  // namespace
}  // namespace sylva::app
