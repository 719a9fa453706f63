// Headless rendering through EGL on Mesa's llvmpipe. These checks do not
// depend on Mesa's exact pixels: an empty scene is the background colour,
// and a plant's silhouette matches the projection of its mesh's bounds.
#include <gtest/gtest.h>
#include <stb_image.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/graphics.h"
#include "core/atomic_file.h"
#include "mesh/tessellator.h"
#include "plant/plant_test_util.h"
#include "render/camera.h"
#include "render/headless_context.h"
#include "render/render_fixture.h"
#include "render/renderer.h"

namespace sylva::render {
namespace {

namespace fs = std::filesystem;

TEST(Camera, DefaultViewLooksFromPlusZAndFramesTheCentre) {
  Camera c = Camera::Frame(Vec3(-1, 0, -1), Vec3(1, 4, 1), 16.0 / 9, 0, 0, false);
  EXPECT_LT((c.target - Vec3(0, 2, 0)).norm(), 1e-12);
  EXPECT_NEAR(c.Eye().x(), 0, 1e-12);
  EXPECT_GT(c.Eye().z(), 0);
  Vec2 px = ToPixel(c.ViewProjection(16.0 / 9), c.target, 160, 90);
  EXPECT_NEAR(px.x(), 80, 1e-9);
  EXPECT_NEAR(px.y(), 45, 1e-9);
  // Up in the world is up in the image.
  EXPECT_LT(ToPixel(c.ViewProjection(16.0 / 9), Vec3(0, 4, 0), 160, 90).y(), 45);
}

TEST(Camera, ZoomGrowsTheImageInBothProjections) {
  // A point beside the target, in the plane facing the camera: its offset
  // from the image centre grows by 1 / 0.8 after Zoom(0.8), in perspective
  // (the eye nearer) as in an orthographic view (a smaller extent; moving
  // the eye there changes nothing on screen).
  for (bool ortho : {false, true}) {
    Camera c = Camera::Frame(Vec3(-1, 0, -1), Vec3(1, 4, 1), 1.0, 0, 0, ortho);
    const Vec3 side = c.target + Vec3(0.5, 0, 0);
    const double before = ToPixel(c.ViewProjection(1), side, 200, 200).x() - 100;
    c.Zoom(0.8);
    const double after = ToPixel(c.ViewProjection(1), side, 200, 200).x() - 100;
    EXPECT_GT(before, 1) << "ortho " << ortho;
    EXPECT_NEAR(after / before, 1 / 0.8, 1e-9)
        << "ortho " << ortho << ": " << before << " px, " << after << " px after zooming";
  }
}

TEST(Camera, FramedBoxStaysInsideTheImage) {
  for (bool ortho : {false, true}) {
    Vec3 lo(-3, 0, -2), hi(2, 9, 1);
    Camera c = Camera::Frame(lo, hi, 4.0 / 3, 30, 20, ortho);
    Mat4 vp = c.ViewProjection(4.0 / 3);
    for (int k = 0; k < 8; ++k) {
      Vec3 p((k & 1) ? hi.x() : lo.x(), (k & 2) ? hi.y() : lo.y(), (k & 4) ? hi.z() : lo.z());
      Vec2 q = ToPixel(vp, p, 400, 300);
      EXPECT_GE(q.x(), 0) << ortho;
      EXPECT_LE(q.x(), 400) << ortho;
      EXPECT_GE(q.y(), 0) << ortho;
      EXPECT_LE(q.y(), 300) << ortho;
    }
  }
}

class Render : public testing::RenderFixture {};

bool IsBackground(const uint8_t* p, const uint8_t* bg) {
  return std::abs(p[0] - bg[0]) <= 2 && std::abs(p[1] - bg[1]) <= 2 && std::abs(p[2] - bg[2]) <= 2;
}

// Bounding box of the pixels that differ from the background: {x0, y0, x1, y1}.
std::array<int, 4> Silhouette(const Image& img, const uint8_t* bg) {
  std::array<int, 4> b = {img.width, img.height, -1, -1};
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x) {
      if (IsBackground(img.Pixel(x, y), bg)) continue;
      b[0] = std::min(b[0], x);
      b[1] = std::min(b[1], y);
      b[2] = std::max(b[2], x);
      b[3] = std::max(b[3], y);
    }
  }
  return b;
}

mesh::PlantGeometry Draw(const std::string& file, int steps) {
  auto p = sylva::testing::PlantFromFile(file, steps);
  return p ? std::move(p->geometry) : mesh::PlantGeometry{};
}

TEST_F(Render, EmptySceneIsTheBackgroundColour) {
  ASSERT_TRUE(renderer_->Resize(64, 48).ok());
  renderer_->SetBackground(mesh::Srgb(0.2f, 0.4f, 0.6f));
  renderer_->Draw(Camera{});
  Image img = renderer_->ReadPixels();
  ASSERT_EQ(img.rgba.size(), size_t(64 * 48 * 4));
  const uint8_t want[4] = {51, 102, 153, 255};
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x)
      for (int k = 0; k < 4; ++k)
        ASSERT_EQ(img.Pixel(x, y)[k], want[k]) << "pixel " << x << "," << y << " channel " << k;
}

TEST_F(Render, PlantSilhouetteMatchesItsProjectedBounds) {
  auto p =
      sylva::testing::PlantFromFile("abop/fig2_06a_monopodial.lsys", 6, plant::Stage::kMesh, 16);
  ASSERT_TRUE(p);
  const mesh::TriangleMesh& m = p->mesh;
  Vec3 lo = m.positions[0].cast<double>(), hi = lo;
  for (const auto& p : m.positions) {
    lo = lo.cwiseMin(p.cast<double>());
    hi = hi.cwiseMax(p.cast<double>());
  }
  const int W = 320, H = 240;
  Camera cam = Camera::Frame(lo, hi, double(W) / H, 30, 12, false);
  ASSERT_TRUE(renderer_->Resize(W, H).ok());
  renderer_->SetMesh(m, mesh::DefaultPalette());
  renderer_->Draw(cam);
  Image img = renderer_->ReadPixels();
  const uint8_t bg[3] = {uint8_t(0.94f * 255 + 0.5f), uint8_t(0.95f * 255 + 0.5f),
                         uint8_t(0.96f * 255 + 0.5f)};
  auto s = Silhouette(img, bg);
  ASSERT_GE(s[2], 0) << "nothing drawn";
  const Mat4 vp = cam.ViewProjection(double(W) / H);
  double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
  for (const auto& p : m.positions) {
    Vec2 q = ToPixel(vp, p.cast<double>(), W, H);
    x0 = std::min(x0, q.x());
    y0 = std::min(y0, q.y());
    x1 = std::max(x1, q.x());
    y1 = std::max(y1, q.y());
  }
  EXPECT_NEAR(s[0], x0, 2) << "left";
  EXPECT_NEAR(s[1], y0, 2) << "top";
  EXPECT_NEAR(s[2] + 1, x1, 2) << "right";
  EXPECT_NEAR(s[3] + 1, y1, 2) << "bottom";
}

TEST_F(Render, TwoDimensionalCurvesDrawAsLinesWithinTheirBounds) {
  mesh::PlantGeometry g = Draw("abop/fig1_06_koch_island.lsys", 2);
  LineBatch lines;
  for (const auto& s : g.segments) {
    lines.points.push_back(s.start.cast<float>());
    lines.points.push_back(s.end.cast<float>());
    lines.colors.push_back(mesh::Vec3f(0, 0, 0));
    lines.colors.push_back(mesh::Vec3f(0, 0, 0));
  }
  const int W = 200, H = 200;
  Camera cam = Camera::Frame(g.boundsMin, g.boundsMax, 1.0, 0, 0, true);
  ASSERT_TRUE(renderer_->Resize(W, H).ok());
  renderer_->SetBackground(mesh::Vec3f(1, 1, 1));
  ASSERT_TRUE(renderer_->SetLines(lines).ok());
  renderer_->Draw(cam);
  Image img = renderer_->ReadPixels();
  const uint8_t white[3] = {255, 255, 255};
  auto s = Silhouette(img, white);
  const Mat4 vp = cam.ViewProjection(1.0);
  Vec2 a = ToPixel(vp, g.boundsMin, W, H), b = ToPixel(vp, g.boundsMax, W, H);
  EXPECT_NEAR(s[0], std::min(a.x(), b.x()), 2);
  EXPECT_NEAR(s[2] + 1, std::max(a.x(), b.x()), 2);
  EXPECT_NEAR(s[1], std::min(a.y(), b.y()), 2);
  EXPECT_NEAR(s[3] + 1, std::max(a.y(), b.y()), 2);
}

TEST(RenderShaders, MissingOrBrokenShaderNamesTheFile) {
  auto c = HeadlessContext::Create();
  ASSERT_TRUE(c.ok()) << c.error().Format();
  auto missing = Renderer::Create("/nonexistent-shaders");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().loc.file, "/nonexistent-shaders/mesh.vert");
  fs::path dir = fs::temp_directory_path() / ("sylva_bad_shaders_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  for (const char* f : {"mesh.vert", "line.vert", "line.frag"})
    fs::copy_file(fs::path(SYLVA_SOURCE_DIR) / "shaders" / f, dir / f,
                  fs::copy_options::overwrite_existing);
  std::ofstream(dir / "mesh.frag")
      << "#version 450 core\nout vec4 c;\nvoid main() { c = vec4(undefined_name); }\n";
  auto broken = Renderer::Create(dir.string());
  ASSERT_FALSE(broken.ok());
  EXPECT_EQ(broken.error().loc.file, (dir / "mesh.frag").string());
  EXPECT_NE(broken.error().message.find("GLSL compilation failed"), std::string::npos)
      << broken.error().message;
  EXPECT_NE(broken.error().message.find("undefined_name"), std::string::npos)
      << broken.error().message;
}

int RunCli(std::vector<std::string> args, std::string* err) {
  std::ostringstream o, e;
  int code = app::RunCliWithGraphics(args, o, e);
  *err = e.str();
  return code;
}

TEST(RenderCli, WritesAPngOfTheRequestedSize) {
  std::string out =
      (fs::temp_directory_path() / ("sylva_render_" + std::to_string(::getpid()) + ".png"))
          .string();
  std::string err;
  ASSERT_EQ(RunCli({"render",
                    std::string(SYLVA_SOURCE_DIR) + "/grammars/abop/fig1_24a_bracketed_plant.lsys",
                    "-n", "3", "--size", "120x80", "-o", out},
                   &err),
            0)
      << err;
  auto png = ReadFile(out);
  ASSERT_TRUE(png.ok());
  ASSERT_GT(png->size(), 24u);
  EXPECT_EQ(png->substr(1, 3), "PNG");
  auto be32 = [&](size_t at) {
    return (uint32_t(uint8_t((*png)[at])) << 24) | (uint32_t(uint8_t((*png)[at + 1])) << 16) |
           (uint32_t(uint8_t((*png)[at + 2])) << 8) | uint32_t(uint8_t((*png)[at + 3]));
  };
  EXPECT_EQ(be32(16), 120u);
  EXPECT_EQ(be32(20), 80u);
  fs::remove(out);
}

TEST(RenderCli, BadInputIsExitTwoWithAClearMessage) {
  const std::string grammar = std::string(SYLVA_SOURCE_DIR) + "/grammars/abop/fig1_25_bush.lsys";
  const std::string out = (fs::temp_directory_path() / "sylva_never.png").string();
  std::string err;
  EXPECT_EQ(RunCli({"render", grammar, "--size", "0x0", "-o", out}, &err), 2);
  EXPECT_NE(err.find("--size '0x0'"), std::string::npos) << err;
  EXPECT_EQ(RunCli({"render", grammar, "--camera", "nan,0,5", "-o", out}, &err), 2);
  EXPECT_NE(err.find("--camera 'nan,0,5'"), std::string::npos) << err;
  EXPECT_EQ(RunCli({"render", "/no/such.lsys", "-o", out}, &err), 2);
  EXPECT_NE(err.find("/no/such.lsys: error: cannot read file"), std::string::npos) << err;
  setenv("SYLVA_SHADER_DIR", "/nonexistent-shaders", 1);
  EXPECT_EQ(RunCli({"render", grammar, "-o", out}, &err), 2);
  unsetenv("SYLVA_SHADER_DIR");
  EXPECT_NE(err.find("/nonexistent-shaders/mesh.vert: error: cannot read shader"),
            std::string::npos)
      << err;
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace sylva::render

namespace sylva::render {
namespace {

TEST_F(Render, PointBatchOfUnequalLengthsIsADiagnosticNotAnOverRead) {
  PointBatch pts;
  pts.positions = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  pts.sizes = {1.0f};  // before: glBufferData read 12 bytes from a 4-byte array
  pts.colors = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const Status st = renderer_->SetPoints(pts);
  ASSERT_FALSE(st.ok()) << "3 positions, 1 size accepted";
  EXPECT_NE(st.error().message.find("3 positions but 1 sizes and 3 colors"), std::string::npos)
      << st.error().message;
  pts.sizes = {1.0f, 1.0f, 1.0f};
  pts.colors.pop_back();
  EXPECT_FALSE(renderer_->SetPoints(pts).ok()) << "3 positions, 2 colours accepted";
}

TEST_F(Render, LineBatchWithFewerColoursIsADiagnosticNotAnOverRead) {
  LineBatch lines;
  lines.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
  lines.colors = {{1, 0, 0}};  // before: glBufferData read 48 bytes from a 12-byte array
  const Status st = renderer_->SetLines(lines);
  ASSERT_FALSE(st.ok()) << "4 points, 1 colour accepted";
  EXPECT_NE(st.error().message.find("4 points but 1 colors"), std::string::npos)
      << st.error().message;
  lines.colors.assign(4, {1, 0, 0});
  EXPECT_TRUE(renderer_->SetLines(lines).ok());
}

TEST_F(Render, PointBatchDrawsRoundSpritesOfTheirWorldSize) {
  PointBatch pts;
  pts.positions = {{-2, 0, 0}, {2, 0, 0}};
  pts.sizes = {1.0f, 0.5f};
  pts.colors = {{1, 0, 0}, {0, 0, 1}};
  const int W = 200, H = 100;
  Camera cam;
  cam.orthographic = true;
  cam.orthoHeight = 4;  // 25 pixels per unit
  cam.azimuth = 0;
  cam.elevation = 0;
  cam.distance = 10;
  ASSERT_TRUE(renderer_->Resize(W, H).ok());
  renderer_->SetBackground(mesh::Vec3f(1, 1, 1));
  ASSERT_TRUE(renderer_->SetPoints(pts).ok());
  renderer_->Draw(cam);
  Image img = renderer_->ReadPixels();
  // Red sprite centred at x = 50: about 25 px across; blue at x = 150: about 12 px.
  auto redWidth = 0, blueWidth = 0;
  for (int x = 0; x < W; ++x) {
    const uint8_t* p = img.Pixel(x, H / 2);
    if (p[0] > 150 && p[2] < 80) ++redWidth;
    if (p[2] > 150 && p[0] < 80) ++blueWidth;
  }
  EXPECT_NEAR(redWidth, 25, 2);
  EXPECT_NEAR(blueWidth, 12.5, 2);
  EXPECT_GT(img.Pixel(50, 50)[0], 150);
  EXPECT_EQ(img.Pixel(100, 50)[0], 255);  // between them: background
}

}  // namespace
}  // namespace sylva::render

namespace sylva::render {
namespace {

// One colour convention (mesh/color.h): a palette entry written #808080 is
// sRGB 128 in the PNG and in OBJ's Kd, and linear 0.2158605 in glTF's
// baseColorFactor.
TEST(RenderCli, MidGreyPaletteEntryIsSrgbInThePngAndLinearInGltf) {
  const fs::path dir = fs::temp_directory_path() / ("sylva_grey_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string grammar = (dir / "grey.lsys").string();
  {
    std::ofstream f(grammar);
    f << "palette: #808080\nangle: 90\naxiom: F+F+F+F\n";
  }
  std::string err;
  const std::string png = (dir / "grey.png").string();
  ASSERT_EQ(RunCli({"render", grammar, "--size", "64x64", "-o", png}, &err), 0) << err;
  int w = 0, h = 0, n = 0;
  unsigned char* px = stbi_load(png.c_str(), &w, &h, &n, 4);
  ASSERT_NE(px, nullptr);
  // Lines are multisampled on white: the darkest pixel is one the line
  // covers whole, so it has the line's colour.
  std::array<int, 3> darkest = {255, 255, 255};
  for (int i = 0; i < w * h; ++i) {
    const unsigned char* p = px + 4 * i;
    if (p[0] + p[1] + p[2] < darkest[0] + darkest[1] + darkest[2]) darkest = {p[0], p[1], p[2]};
  }
  stbi_image_free(px);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(darkest[k], 128, 1) << "channel " << k << " of the line colour in the PNG";
  }

  const std::string gltf = (dir / "grey.gltf").string();
  ASSERT_EQ(RunCli({"mesh", grammar, "-o", gltf}, &err), 0) << err;
  auto text = ReadFile(gltf);
  ASSERT_TRUE(text.ok());
  const nlohmann::json doc = nlohmann::json::parse(*text);
  ASSERT_FALSE(doc["materials"].empty());
  const auto& factor = doc["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"];
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(factor[k].get<double>(), 0.2158605, 1e-5) << "glTF baseColorFactor[" << k << "]";
  }

  const std::string obj = (dir / "grey.obj").string();
  ASSERT_EQ(RunCli({"mesh", grammar, "-o", obj}, &err), 0) << err;
  auto mtl = ReadFile((dir / "grey.mtl").string());
  ASSERT_TRUE(mtl.ok());
  const size_t kd = mtl->find("Kd ");
  ASSERT_NE(kd, std::string::npos) << *mtl;
  EXPECT_NEAR(std::strtod(mtl->c_str() + kd + 3, nullptr), 128.0 / 255, 1e-5) << *mtl;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace sylva::render

namespace sylva::render {
namespace {

TEST(Camera, FramingNonFiniteBoundsGivesAFiniteCamera) {
  const double nan = std::nan(""), inf = std::numeric_limits<double>::infinity();
  const std::pair<Vec3, Vec3> boxes[] = {
      {Vec3(0, nan, 0), Vec3(1, 1, 1)},                                         // NaN in y
      {Vec3(0, 0, 0), Vec3(1, 1, nan)},                                         // NaN in z
      {Vec3(-inf, 0, 0), Vec3(1, 1, 1)},       {Vec3(2, 2, 2), Vec3(1, 1, 1)},  // inverted
      {Vec3(-1e300, 0, 0), Vec3(1e300, 1, 1)},  // its extent overflows
  };
  for (bool ortho : {false, true}) {
    for (const auto& [lo, hi] : boxes) {
      Camera c = Camera::Frame(lo, hi, 16.0 / 9, 30, 12, ortho);
      const Mat4 vp = c.ViewProjection(16.0 / 9);
      EXPECT_TRUE(vp.allFinite()) << "lo " << lo.transpose() << " hi " << hi.transpose()
                                  << " ortho " << ortho;
      EXPECT_TRUE(c.Eye().allFinite()) << "lo " << lo.transpose() << " hi " << hi.transpose();
    }
  }
  Camera c = Camera::Frame(Vec3(0, 0, 0), Vec3(1, 1, 1), nan, nan, inf, false);
  EXPECT_TRUE(c.ViewProjection(1).allFinite());
}

}  // namespace
}  // namespace sylva::render
