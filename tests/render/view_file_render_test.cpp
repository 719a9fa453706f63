// sylva render with a cpfg view file: the view direction it gives, and
// --camera over it (app/view_file.h).
#include <gtest/gtest.h>
#include <stb_image.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "app/graphics.h"
#include "app/plant_view.h"
#include "render/camera.h"
#include "scratch_dir.h"

namespace sylva::app {
namespace {

std::filesystem::path Scratch() {
  return sylva::testing::ScratchDir("sylva_view_render_");
}

std::string WriteFile(const std::string& name, const std::string& text) {
  auto p = Scratch() / name;
  std::ofstream(p, std::ios::binary) << text;
  return p.string();
}

// Width over height of the box of the drawn (dark) pixels of a PNG.
double DrawnAspect(const std::string& png) {
  int w = 0, h = 0, n = 0;
  unsigned char* px = stbi_load(png.c_str(), &w, &h, &n, 4);
  if (!px) return -1;
  int x0 = w, x1 = -1, y0 = h, y1 = -1;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const unsigned char* p = px + 4 * (size_t(y) * size_t(w) + size_t(x));
      if (p[0] + p[1] + p[2] < 3 * 160) {
        x0 = std::min(x0, x);
        x1 = std::max(x1, x);
        y0 = std::min(y0, y);
        y1 = std::max(y1, y);
      }
    }
  }
  stbi_image_free(px);
  if (x1 < 0) return -1;
  return double(x1 - x0 + 1) / double(y1 - y0 + 1);
}

// The pixels of a PNG (RGBA), with its size; empty when it cannot be read.
struct Png {
  int w = 0, h = 0;
  std::vector<unsigned char> px;
  const unsigned char* At(int x, int y) const {
    return &px[4 * (size_t(y) * size_t(w) + size_t(x))];
  }
};
Png Load(const std::string& png) {
  Png p;
  int n = 0;
  unsigned char* data = stbi_load(png.c_str(), &p.w, &p.h, &n, 4);
  if (!data) return p;
  p.px.assign(data, data + size_t(p.w) * size_t(p.h) * 4);
  stbi_image_free(data);
  return p;
}

int Render(const std::string& grammar, const std::string& png, const std::string& size,
           std::string* errors) {
  std::ostringstream out, err;
  const int code = RunCliWithGraphics({"render", grammar, "-o", png, "--size", size}, out, err);
  *errors = err.str();
  return code;
}

TEST(ViewFile, PixelWidthsAreThatManyPixelsOnScreen) {
  // A vertical line of cpfg's `5 pixels` (a 2D figure: ribbons on white):
  // the middle row crosses 5 drawn pixels, give or take the edges' blend.
  const std::string grammar = WriteFile("px.l", "axiom: F(10)\n");
  WriteFile("px.v", "initial line width: 5 pixels\n");
  const std::string png = (Scratch() / "px.png").string();
  std::string err;
  ASSERT_EQ(Render(grammar, png, "120x120", &err), 0) << err;
  const Png p = Load(png);
  ASSERT_GT(p.w, 0);
  double covered = 0;  // darkness summed across the row, in pixels
  for (int x = 0; x < p.w; ++x) {
    const unsigned char* c = p.At(x, p.h / 2);
    covered += 1.0 - (c[0] + c[1] + c[2]) / (3.0 * 255.0);
  }
  // The line's colour is not black: its darkness over a pixel is below 1.
  int dark = 0;
  for (int x = 0; x < p.w; ++x) {
    const unsigned char* c = p.At(x, p.h / 2);
    if (c[0] + c[1] + c[2] < 3 * 200) ++dark;
  }
  EXPECT_GE(dark, 4) << "pixels of the line in the middle row (darkness " << covered << ")";
  EXPECT_LE(dark, 6) << "pixels of the line in the middle row (darkness " << covered << ")";
  std::filesystem::remove(Scratch() / "px.v");
}

TEST(ViewFile, ACameraBelowThePlantSeesItWithoutTheGround) {
  // terminalia's view: from under the crown looking up. With the default
  // ground in between, the picture was the ground's dark underside.
  // A trunk 15 to the side of a flat whorl, as terminalia's tree.l draws
  // (main at 8ca261c: 0 background pixels of 19,200; without the ground
  // 19,008).
  const std::string grammar =
      WriteFile("below.l",
                "axiom: [-(90)f(15)+(90)f(-2)F(4)] F(1) [&(90) F(3)] [^(90) F(3)] [+(90) F(3)] "
                "[-(90) F(3)]\n");
  WriteFile("below.v",
            "initial line width: 0.1\nviewpoint: 1.1,-60,0\nview reference point: 1.1,0,0\n"
            "projection: perspective\n");
  const std::string png = (Scratch() / "below.png").string();
  std::string err;
  ASSERT_EQ(Render(grammar, png, "160x120", &err), 0) << err;
  const Png p = Load(png);
  ASSERT_GT(p.w, 0);
  int dark = 0, background = 0;
  for (int y = 0; y < p.h; ++y) {
    for (int x = 0; x < p.w; ++x) {
      const unsigned char* c = p.At(x, y);
      const int sum = c[0] + c[1] + c[2];
      if (sum < 3 * 90) ++dark;
      if (sum > 3 * 225) ++background;
    }
  }
  const int all = p.w * p.h;
  EXPECT_GT(background, all / 2) << "light background pixels of " << all;
  EXPECT_GT(dark + (all - background), 10) << "the plant draws something";
  std::filesystem::remove(Scratch() / "below.v");
}

TEST(ViewFile, ACpfgObjectIsDrawnWithoutTheDefaultGround) {
  // cpfg draws no ground. lilac-congo's view (viewpoint 4,-5,30, parallel)
  // on a plant with a branch hanging below its base: with Sylva's default
  // ground the lower part of the picture was a grey plane (main at c6acb62:
  // 11,389 light background pixels of 19,200; without the ground 18,570).
  const std::string grammar =
      WriteFile("noground.l", "axiom: &(30) F(10) [+(60) F(6)] [-(60) F(6)] ^(200) F(9)\n");
  WriteFile("noground.v",
            "initial line width: 0.3\nviewpoint: 4,-5,30\nview reference point: 0,0,0\n"
            "projection: parallel\nscale factor: 0.95\n");
  const std::string png = (Scratch() / "noground.png").string();
  std::string err;
  ASSERT_EQ(Render(grammar, png, "160x120", &err), 0) << err;
  const Png p = Load(png);
  ASSERT_GT(p.w, 0);
  int background = 0;
  for (int y = 0; y < p.h; ++y)
    for (int x = 0; x < p.w; ++x) {
      const unsigned char* c = p.At(x, y);
      if (c[0] + c[1] + c[2] > 3 * 225) ++background;
    }
  const int all = p.w * p.h;
  EXPECT_GT(background, all * 9 / 10) << "light background pixels of " << all;
  EXPECT_LT(background, all * 99 / 100) << "the plant is drawn";
  std::filesystem::remove(Scratch() / "noground.v");
}

TEST(ViewFile, RenderLooksFromTheViewpointUnlessCameraIsGiven) {
  // An L in the z = 0 plane: as wide as tall from +Z (cpfg's default
  // viewpoint), a vertical line from +X.
  const std::string grammar = WriteFile("vr.l", "axiom: F -(90) F\n");
  const std::string front = WriteFile("front.v", "viewpoint: 0,0,1\n");
  const std::string side = WriteFile("side.v", "viewpoint: 1,0,0\nview reference point: 0,0,0\n");
  const std::string png = (Scratch() / "vr.png").string();
  auto aspect = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = {"render", grammar, "-o", png, "--size", "200x200"};
    args.insert(args.end(), extra.begin(), extra.end());
    std::ostringstream out, err;
    const int code = RunCliWithGraphics(args, out, err);
    EXPECT_EQ(code, 0) << err.str();
    return DrawnAspect(png);
  };
  const double fromFront = aspect({"--view", front});
  const double fromSide = aspect({"--view", side});
  const double cameraWins = aspect({"--view", side, "--camera", "0,0,0"});
  EXPECT_GT(fromFront, 0.7) << "from +Z";
  EXPECT_LT(fromSide, 0.2) << "from +X";
  EXPECT_GT(cameraWins, 0.7) << "--camera over the view file";
}

// A view file's text as LoadViewFiles reads it.
ViewFile ViewOf(const std::string& text) {
  ViewFile v = ParseViewFile(text, "p.v");
  v.path = "p.v";
  return v;
}

mesh::PlantGeometry Tube3D() {
  mesh::PlantGeometry g;
  g.planar = false;
  mesh::Segment s;
  s.start = Vec3(0, 0, 0);
  s.end = Vec3(0, 1, 1);
  s.left = Vec3(1, 0, 0);
  s.radiusStart = s.radiusEnd = 0.1f;
  g.segments.push_back(s);
  return g;
}

TEST(PlantView, ParallelViewFileGivesAnOrthographicCameraFromItsViewpoint) {
  const ViewFile v = ViewOf(
      "viewpoint: 0,10,10\nview reference point: 0,0,0\nprojection: parallel\n"
      "scale factor: 2\nlight direction: 1,0,0\n");
  const mesh::PlantGeometry g = Tube3D();
  const PlantView view = ChoosePlantView("p.l", &v, &g);
  EXPECT_EQ(view.look, PlantLook::kMesh);
  EXPECT_TRUE(view.orthographic);
  EXPECT_TRUE(view.cpfgObject) << "a cpfg object stands on no ground";
  EXPECT_NEAR(view.azimuth, 0, 1e-9);
  EXPECT_NEAR(view.elevation, 45, 1e-9);
  EXPECT_NEAR((view.keyToward - Vec3(1, 0, 0)).norm(), 0, 1e-9)
      << view.keyToward.transpose() << ": the key light comes from the view file's";
  const mesh::Box box{Vec3(-1, 0, -1), Vec3(1, 2, 1)};
  const render::Camera framed = FramePlant(view, box, 1.0);
  const render::Camera unscaled = render::Camera::Frame(box.lo, box.hi, 1.0, 0, 45, true);
  EXPECT_TRUE(framed.orthographic);
  EXPECT_NEAR(framed.orthoHeight, unscaled.orthoHeight / 2, 1e-9)
      << "scale factor 2 shows half the extent";
}

TEST(PlantView, ALFileWithoutAViewFileIsSeenAsCpfgSeesIt) {
  const mesh::PlantGeometry g = Tube3D();
  const PlantView cpfg = ChoosePlantView("plant.l", nullptr, &g);
  EXPECT_TRUE(cpfg.orthographic);
  EXPECT_TRUE(cpfg.cpfgObject);
  EXPECT_EQ(cpfg.azimuth, 0);
  EXPECT_EQ(cpfg.elevation, 0);
  const PlantView sylva = ChoosePlantView("plant.lsys", nullptr, &g);
  EXPECT_FALSE(sylva.orthographic);
  EXPECT_FALSE(sylva.cpfgObject);
  EXPECT_EQ(sylva.azimuth, 30);
  EXPECT_EQ(sylva.elevation, 12);
  const double camera[3] = {90, 10, 7};
  const PlantView flag = ChoosePlantView("plant.l", nullptr, &g, camera);
  EXPECT_EQ(flag.azimuth, 90) << "--camera wins";
  EXPECT_EQ(flag.distance, 7);
}

TEST(PlantView, PixelWidthsWiderThanAPixelMakeA2DFigureRibbons) {
  mesh::PlantGeometry g;
  g.planar = true;
  g.widthInPixels = true;
  mesh::Segment s;
  s.start = Vec3(0, 0, 0);
  s.end = Vec3(0, 1, 0);
  s.left = Vec3(1, 0, 0);
  s.radiusStart = s.radiusEnd = 0.5f;  // one pixel wide
  g.segments.push_back(s);
  EXPECT_EQ(ChoosePlantView("f.l", nullptr, &g).look, PlantLook::kLines);
  g.segments[0].radiusEnd = 2.5f;  // 5 pixels
  const PlantView view = ChoosePlantView("f.l", nullptr, &g);
  EXPECT_EQ(view.look, PlantLook::kRibbons);
  EXPECT_TRUE(view.orthographic);
  const render::Camera camera = FramePlant(view, mesh::Box{Vec3(0, 0, 0), Vec3(0, 1, 0)}, 1.0);
  const mesh::ScreenView screen =
      ScreenViewFor(view, camera, 100, 100, 0.5, mesh::Box{Vec3(0, 0, 0), Vec3(0, 1, 0)}, 1, g);
  EXPECT_GE(screen.eps, 1.0) << "5-pixel ribbons must stay ribbons (under 3 eps of radius)";
  EXPECT_EQ(screen.shadowTexelsPerUnit, 0) << "ribbons cast no shadow";
}

TEST(PlantView, FrameAllKeepsTheProjectionAndShowsTheWholeBox) {
  const ViewFile v = ViewOf("viewpoint: 0,0,10\nprojection: parallel\nscale factor: 4\n");
  const mesh::PlantGeometry g = Tube3D();
  const PlantView view = ChoosePlantView("p.l", &v, &g);
  const mesh::Box box{Vec3(-1, 0, -2), Vec3(3, 5, 1)};
  for (double azimuth : {0.0, 70.0, 200.0}) {
    const render::Camera c = FrameAll(view, box, 16.0 / 9, azimuth, 25);
    EXPECT_TRUE(c.orthographic) << "frame all in a parallel view stays parallel";
    EXPECT_EQ(c.azimuth, azimuth);
    EXPECT_EQ(c.elevation, 25);
    const Mat4 vp = c.ViewProjection(16.0 / 9);
    for (int k = 0; k < 8; ++k) {
      const Vec3 p((k & 1) ? box.hi.x() : box.lo.x(), (k & 2) ? box.hi.y() : box.lo.y(),
                   (k & 4) ? box.hi.z() : box.lo.z());
      const Vec2 q = render::ToPixel(vp, p, 320, 180);
      EXPECT_TRUE(q.x() >= 0 && q.x() <= 320 && q.y() >= 0 && q.y() <= 180)
          << "corner " << p.transpose() << " at pixel " << q.transpose() << ", azimuth " << azimuth
          << " (the scale factor zooms render's view, not frame all)";
    }
  }
  const ViewFile persp = ViewOf("viewpoint: 0,0,10\nprojection: perspective\nviewing angle: 20\n");
  const render::Camera c = FrameAll(ChoosePlantView("p.l", &persp, &g), box, 1.0, 10, 10);
  EXPECT_FALSE(c.orthographic);
  EXPECT_EQ(c.fovY, 20) << "frame all keeps the view file's viewing angle";
}

// Rows of a PNG with drawn (dark) pixels, and whether the top or bottom
// row has any (the drawing runs out of the frame).
struct DrawnRows {
  int rows = 0;
  bool touchesEdge = false;
};
DrawnRows Rows(const std::string& png) {
  const Png p = Load(png);
  DrawnRows r;
  for (int y = 0; y < p.h; ++y) {
    bool any = false;
    for (int x = 0; x < p.w && !any; ++x) {
      const unsigned char* c = p.At(x, y);
      any = c[0] + c[1] + c[2] < 3 * 160;
    }
    if (any) {
      ++r.rows;
      r.touchesEdge |= y == 0 || y == p.h - 1;
    }
  }
  return r;
}

TEST(ViewFile, PerspectiveIsCpfgsCameraNotAFramedBox) {
  // cpfg (control.c, SetView) frames nothing in perspective: the eye is at
  // vrp + (viewpoint - vrp) / scale looking at vrp, with a 45 degree field
  // of view. vlab's lamps say `scale factor: 2.0`; Sylva framed the lamp
  // and then halved the distance, cutting it at the frame's edges. Here a
  // 2-unit stem centred on vrp seen from 5 units: 2 / (2 * 5 * tan(22.5))
  // = 48 % of the picture's height (the framed, halved camera drew it past
  // both edges).
  const std::string grammar = WriteFile("persp.l", "axiom: !(0.05) F(2) [&(90) F(0.1)]\n");
  WriteFile("persp.v",
            "viewpoint: 0,1,10\nview reference point: 0,1,0\nprojection: perspective\n"
            "scale factor: 2.0\nline style: cylinder\n");
  const std::string png = (Scratch() / "persp.png").string();
  std::string err;
  ASSERT_EQ(Render(grammar, png, "160x120", &err), 0) << err;
  const DrawnRows r = Rows(png);
  EXPECT_FALSE(r.touchesEdge) << r.rows << " rows of 120 drawn";
  EXPECT_NEAR(r.rows / 120.0, 0.483, 0.04) << r.rows << " rows of 120 drawn";
  std::filesystem::remove(Scratch() / "persp.v");
}

TEST(ViewFile, PerspectiveFarPlaneReachesAPlantBeyondFourDistances) {
  // cpfg clips at its `back distance:` (100000 by default); Sylva's far
  // plane was 4 distances + 1 from the eye, so a stem 70 units away from an
  // eye 10 units from the view reference point was cut off (corpus3's
  // forest, 3000 units wide seen from 200, drew only the nearest ground).
  // Seen now: a 20-unit stem at 70 units in a 45 degree field fills about
  // 20 / (2 * 70 * tan(22.5)) = 34 % of the picture's height.
  const std::string grammar = WriteFile("far.l", "axiom: @M(0,-9,-60) !(0.5) F(20)\n");
  WriteFile("far.v",
            "viewpoint: 0,1,10\nview reference point: 0,1,0\nprojection: perspective\n"
            "line style: cylinder\n");
  const std::string png = (Scratch() / "far.png").string();
  std::string err;
  ASSERT_EQ(Render(grammar, png, "160x120", &err), 0) << err;
  const DrawnRows r = Rows(png);
  EXPECT_NEAR(r.rows / 120.0, 0.345, 0.05) << r.rows << " rows of 120 drawn";
  EXPECT_EQ(err.find("sees none"), std::string::npos) << err;
  std::filesystem::remove(Scratch() / "far.v");
}

TEST(ViewFile, ACameraThatSeesNoneOfThePlantIsWarnedAtItsViewpoint) {
  // cpfg's perspective camera looks from the viewpoint toward the view
  // reference point whatever the plant: here away from it (corpus3's
  // tree.l looks toward -z from z = 0 and its forest stands at z > 0). The
  // picture is empty, as cpfg's would be; Sylva says so at the viewpoint
  // line, and --strict makes it an error.
  const std::string grammar = WriteFile("away.l", "axiom: !(0.5) F(2)\n");
  WriteFile("away.v",
            "projection: perspective\nview reference point: 0,1,-20\nviewpoint: 0,1,-10\n"
            "line style: cylinder\n");
  const std::string png = (Scratch() / "away.png").string();
  std::string err;
  ASSERT_EQ(Render(grammar, png, "160x120", &err), 0) << err;
  EXPECT_EQ(Rows(png).rows, 0) << "the stem is behind the eye";
  EXPECT_NE(err.find("away.v:3:1: warning: the view file's camera sees none of the plant"),
            std::string::npos)
      << err;
  std::ostringstream out, strictErr;
  EXPECT_EQ(RunCliWithGraphics({"render", grammar, "-o", png, "--size", "160x120", "--strict"}, out,
                               strictErr),
            2)
      << strictErr.str();
  // A parallel view's `box:` is framed instead of the plant: one that holds
  // none of it is said the same way, at the box line.
  WriteFile("away.v", "line style: cylinder\nbox: x: 10,20 y: 10,20 z: -1,1\n");
  ASSERT_EQ(Render(grammar, png, "160x120", &err), 0) << err;
  EXPECT_NE(err.find("away.v:2:1: warning: the view file's 'box:' holds none of the plant"),
            std::string::npos)
      << err;
  // A plant that draws nothing is not said to be out of view (vlab's
  // 07-canalization-output draws nothing until its environment answers).
  const std::string empty = WriteFile("nothing.l", "axiom: f(2)\n");
  WriteFile("nothing.v", "line style: cylinder\nbox: x: 10,20 y: 10,20 z: -1,1\n");
  ASSERT_EQ(Render(empty, png, "160x120", &err), 0) << err;
  EXPECT_EQ(err.find("holds none"), std::string::npos) << err;
  std::filesystem::remove(Scratch() / "nothing.v");
  // Turned toward the stem, no warning.
  WriteFile("away.v",
            "projection: perspective\nview reference point: 0,1,0\nviewpoint: 0,1,-10\n"
            "line style: cylinder\n");
  ASSERT_EQ(Render(grammar, png, "160x120", &err), 0) << err;
  EXPECT_EQ(err.find("sees none"), std::string::npos) << err;
  EXPECT_GT(Rows(png).rows, 0);
  std::filesystem::remove(Scratch() / "away.v");
}

TEST(CpfgLabel, RenderWritesTheLabelRightOfWhereTheTurtleWas) {
  // cpfg draws @L's text as bitmap text whose baseline starts at the
  // turtle's position on the screen (irisGL.c iGlLabel, glRasterPos). A
  // vertical line with a label at its middle: the text's pixels lie right
  // of the line, around the middle row; without the label none are there.
  const std::string with = WriteFile("label.l", "axiom: F(1) @L(\"HHHH %.0f\", 42) F(1)\n");
  const std::string without = WriteFile("nolabel.l", "axiom: F(1) F(1)\n");
  const std::string a = (Scratch() / "label.png").string(),
                    b = (Scratch() / "nolabel.png").string();
  std::string err;
  ASSERT_EQ(Render(with, a, "160x120", &err), 0) << err;
  EXPECT_EQ(err.find("'@L'"), std::string::npos) << err;
  ASSERT_EQ(Render(without, b, "160x120", &err), 0) << err;
  const Png pa = Load(a), pb = Load(b);
  ASSERT_EQ(pa.px.size(), pb.px.size());
  int changed = 0, outside = 0;
  for (int y = 0; y < pa.h; ++y) {
    for (int x = 0; x < pa.w; ++x) {
      const unsigned char *p = pa.At(x, y), *q = pb.At(x, y);
      if (p[0] == q[0] && p[1] == q[1] && p[2] == q[2]) continue;
      ++changed;
      // 7 pixels of text above the baseline at the middle row, right of x 80.
      if (x < 80 || y < 60 - 9 || y > 60 + 3) ++outside;
    }
  }
  EXPECT_GT(changed, 40) << "pixels of 'HHHH 42'";
  EXPECT_EQ(outside, 0) << outside << " of " << changed << " changed pixels away from the label";
}

}  // namespace
}  // namespace sylva::app
