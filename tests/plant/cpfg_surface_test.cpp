#include "plant/cpfg_surface.h"

#include <gtest/gtest.h>

#include <sstream>

#include "plant/plant.h"
#include "plant/plant_test_util.h"

namespace sylva::plant {
namespace {

// A .s file of one patch whose 16 control points are `point(r, c)`.
template <typename F>
std::string SurfaceText(const std::string& frame, F point, int points = 16) {
  std::ostringstream s;
  s << "0 1 0 1 0 1\n"
    << frame << "flat\nTOP COLOR: 1 DIFFUSE: 0.00 BOTTOM COLOR: 1 DIFFUSE: 0.00\n"
    << "AL: ~ A: ~ AR: ~\nL: ~ R: ~\nBL: ~ B: ~ BR: ~\n";
  for (int k = 0; k < points; ++k) {
    const Vec3 p = point(k / 4, k % 4);
    s << p.x() << " " << p.y() << " " << p.z() << (k % 4 == 3 ? "\n" : "  ");
  }
  return s.str();
}

struct Bounds {
  Vec3 lo{1e30, 1e30, 1e30}, hi{-1e30, -1e30, -1e30};
};
Bounds BoundsOf(const mesh::TriangleMesh& m) {
  Bounds b;
  for (const auto& p : m.positions) {
    b.lo = b.lo.cwiseMin(p.cast<double>());
    b.hi = b.hi.cwiseMax(p.cast<double>());
  }
  return b;
}

// A flat square in the file's x-y plane, 3 by 3, heading +y, up +z.
const std::string kFlatFrame =
    "CONTACT POINT  X: 1.5 Y: 0 Z: 0\nEND POINT  X: 1.5 Y: 3 Z: 0\n"
    "HEADING  X: 0 Y: 1 Z: 0\nUP  X: 0 Y: 0 Z: 1\nSIZE: 3\n";
Vec3 FlatPoint(int r, int c) {
  return Vec3(c, r, 0);
}

TEST(CpfgSurface, PutsTheContactPointAtTheTurtleAndScalesTheSizeToTheViewFiles) {
  // size 6 / SIZE 3: twice as large; the contact point (1.5, 0, 0) at the origin.
  auto m = ParseCpfgSurface(SurfaceText(kFlatFrame, FlatPoint), "flat.s", 6);
  ASSERT_TRUE(m) << m.error().Format();
  EXPECT_EQ(mesh::Validate(*m), "");
  const Bounds b = BoundsOf(*m);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(b.lo[k], Vec3(-3, 0, 0)[k], 1e-5) << "min " << k << ": " << b.lo.transpose();
    EXPECT_NEAR(b.hi[k], Vec3(3, 6, 0)[k], 1e-5) << "max " << k << ": " << b.hi.transpose();
  }
  // One grid of kMinPatchDivisions^2 quads, two triangles a quad, both faces.
  EXPECT_EQ(m->triangleCount(), size_t(4 * kMinPatchDivisions * kMinPatchDivisions));
  for (const auto& n : m->normals) {
    EXPECT_NEAR(std::abs(n.z()), 1.0f, 1e-5f) << n.transpose();
    EXPECT_NEAR(n.x(), 0.0f, 1e-5f) << n.transpose();
    EXPECT_NEAR(n.y(), 0.0f, 1e-5f) << n.transpose();
  }
}

TEST(CpfgSurface, TheFilesHeadingAndUpBecomeTheTurtlesHAndU) {
  // Heading -z, up -y (as vlab's bud.s): left = heading x up = -x. A strip
  // 1 wide running 3 along the heading lands along local +y (H), its width
  // along local -x.
  const std::string frame =
      "PRECISION S: 2 T: 2\nCONTACT POINT  X: 0 Y: 0 Z: 0\nEND POINT  X: 0 Y: 0 Z: -3\n"
      "HEADING  X: 0 Y: 0 Z: -1\nUP  X: 0 Y: -1 Z: 0\nSIZE: 3\n";
  auto m = ParseCpfgSurface(SurfaceText(frame, [](int r, int c) { return Vec3(c / 3.0, 0, -r); }),
                            "strip.s", 3);
  ASSERT_TRUE(m) << m.error().Format();
  const Bounds b = BoundsOf(*m);
  EXPECT_NEAR(b.lo.x(), -1, 1e-5) << b.lo.transpose();
  EXPECT_NEAR(b.hi.x(), 0, 1e-5) << b.hi.transpose();
  EXPECT_NEAR(b.lo.y(), 0, 1e-5) << b.lo.transpose();
  EXPECT_NEAR(b.hi.y(), 3, 1e-5) << b.hi.transpose();
  EXPECT_NEAR(b.lo.z(), 0, 1e-5) << b.lo.transpose();
  EXPECT_NEAR(b.hi.z(), 0, 1e-5) << b.hi.transpose();
}

TEST(CpfgSurface, BadFilesAreErrorsAtTheirLine) {
  // HEADING missing: line 4 holds UP.
  const std::string noHeading =
      "0 1 0 1 0 1\nCONTACT POINT  X: 0 Y: 0 Z: 0\nEND POINT  X: 0 Y: 1 Z: 0\n"
      "UP  X: 0 Y: 0 Z: 1\nSIZE: 3\n";
  auto a = ParseCpfgSurface(noHeading, "a.s", 1);
  ASSERT_FALSE(a);
  EXPECT_EQ(a.error().loc.line, 4) << a.error().Format();
  EXPECT_NE(a.error().message.find("HEADING"), std::string::npos) << a.error().Format();

  auto b = ParseCpfgSurface(SurfaceText(kFlatFrame, FlatPoint, 15), "b.s", 1);
  ASSERT_FALSE(b);
  EXPECT_NE(b.error().message.find("has 15 control points, not 16"), std::string::npos)
      << b.error().Format();
  EXPECT_EQ(b.error().loc.line, 7) << b.error().Format();  // the patch's name line

  std::string nan = SurfaceText(kFlatFrame, FlatPoint);
  nan.replace(nan.rfind("3 3 0"), 5, "3 nan 0");
  auto c = ParseCpfgSurface(nan, "c.s", 1);
  ASSERT_FALSE(c);
  EXPECT_EQ(c.error().loc.line, 15) << c.error().Format();
  EXPECT_NE(c.error().message.find("not finite"), std::string::npos) << c.error().Format();

  std::string zeroSize = SurfaceText(kFlatFrame, FlatPoint);
  zeroSize.replace(zeroSize.find("SIZE: 3"), 7, "SIZE: 0");
  auto d = ParseCpfgSurface(zeroSize, "d.s", 1);
  ASSERT_FALSE(d);
  EXPECT_EQ(d.error().loc.line, 6) << d.error().Format();
}

TEST(CpfgSurface, APlantPlacesTheNamedSurfaceScaledByItsParameter) {
  PlantSpec spec;
  spec.path = "/g/t.l";
  spec.text = "axiom: ~l(2)\n";
  spec.cpfgSurfaces.push_back({"l", "/g/flat.s", 6, 0, 0, "/g/t.v", 3});
  const std::string flat = SurfaceText(kFlatFrame, FlatPoint);
  spec.readFile = [&](const std::string& path) -> std::optional<std::string> {
    if (path == "/g/flat.s") return flat;
    return std::nullopt;
  };
  spec.detail.sides = 8;
  auto plant = testing::BuildOrFail(spec);
  ASSERT_TRUE(plant);
  const Bounds b = BoundsOf(plant->mesh);
  // Scaled 2 * 6/3 = 4: 12 along the heading (the turtle's H is +Y), 12 wide.
  EXPECT_NEAR(b.hi.y() - b.lo.y(), 12, 1e-4) << b.lo.transpose() << " / " << b.hi.transpose();
  EXPECT_NEAR((b.hi - b.lo).maxCoeff(), 12, 1e-4) << b.lo.transpose() << " / " << b.hi.transpose();

  // cpfg's one-letter names: `~lF` is the surface l, then F, when l is a
  // view-file surface (and there is no lF.obj).
  spec.text = "axiom: ~lF\n";
  auto lf = testing::BuildOrFail(spec);
  ASSERT_TRUE(lf);
  EXPECT_EQ(lf->word.size(), 2u);
  EXPECT_EQ(lf->geometry.surfaces.size(), 1u);
  EXPECT_EQ(lf->geometry.segments.size(), 1u);
  spec.text = "axiom: ~l(2)\n";

  // A surface file that cannot be read is an error at the view file's line.
  spec.cpfgSurfaces[0].file = "/g/missing.s";
  PlantResult r = BuildPlant(spec);
  ASSERT_FALSE(r.plant);
  const std::string all = r.diagnostics.FormatAll();
  EXPECT_NE(all.find("/g/t.v:3: error: cannot read the surface file /g/missing.s"),
            std::string::npos)
      << all;
}

}  // namespace
}  // namespace sylva::plant
