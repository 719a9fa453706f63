// Screen-space detail through the renderer: culling never changes a pixel,
// and the `sylva render` flags (--stats, --sides, --supersample) do what
// docs/cli.md says.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>

#include "app/graphics.h"
#include "draw/draw_list.h"
#include "mesh/color.h"
#include "mesh/screen_detail.h"
#include "mesh/tessellator.h"
#include "plant/plant_test_util.h"
#include "render/camera.h"
#include "render/render_fixture.h"
#include "render/renderer.h"
#include "scene/default_scene.h"

namespace sylva::render {
namespace {

class ScreenDetailRender : public testing::RenderFixture {};

// A close-up inside the crown (most of the tree is outside the frustum),
// without and with the default scene's ground, its shadows and coverage
// lines (a branch outside the view may cast a shadow into it, so culling
// keeps it then), drawn as `sylva render` draws a grammar: through the
// DrawList.
TEST_F(ScreenDetailRender, CullingNeverRemovesAVisiblePixel) {
  auto p =
      sylva::testing::PlantFromFile("abop/fig2_06a_monopodial.lsys", 11, plant::Stage::kGeometry);
  ASSERT_TRUE(p);
  const mesh::Box box = mesh::TessellatedBounds(p->geometry, nullptr);
  const int W = 320, H = 180;
  for (const auto& [az, el, shrink] : {std::tuple{30.0, 12.0, 0.12}, std::tuple{200.0, -20.0, 0.15},
                                       std::tuple{75.0, 40.0, 0.1}}) {
    Camera cam = Camera::Frame(box.lo, box.hi, double(W) / H, az, el, false);
    cam.distance *= shrink;
    mesh::ScreenView view;
    view.viewProjection = cam.ViewProjection(double(W) / H);
    view.width = W;
    view.height = H;
    // Shadows and coverage lines (sylva render's default) go together here:
    // without, with both.
    for (bool shadows : {false, true}) {
      view.coverage = shadows;
      view.shadowFrom = shadows ? KeyLightDirection() : Vec3::Zero();
      view.shadowPlaneY = box.lo.y();
      view.shadowTexelsPerUnit = ShadowTexelsPerUnit(box);
      Image images[2];
      size_t triangles[2], culled = 0, items = 0;
      for (int cull = 0; cull < 2; ++cull) {
        mesh::TessellateOptions opt;
        opt.view = view;
        opt.cull = cull == 1;
        mesh::TriangleMesh m;
        mesh::TessellateStats stats;
        ASSERT_TRUE(mesh::Tessellate(p->geometry, opt, m, &stats).ok());
        culled = stats.culled;
        items = stats.chains;
        triangles[cull] = m.triangleCount();
        if (shadows) {
          const size_t lines = size_t(
              std::count_if(m.coverage.begin(), m.coverage.end(), [](float c) { return c < 1; }));
          EXPECT_GT(lines, 0u) << "azimuth " << az << ": no coverage line to test";
        }
        ASSERT_TRUE(renderer_->Resize(W, H).ok());
        auto shared = std::make_shared<const mesh::TriangleMesh>(std::move(m));
        draw::DrawList list = scene::DefaultScene(shared, mesh::DefaultPalette(), box.lo, box.hi);
        if (!shadows) {  // the plant alone, lit by an ambient light: no shadow map
          list.meshes.resize(1);
          list.lights = {draw::Light::Ambient({1, 1, 1}, 0.8f)};
        }
        ASSERT_TRUE(renderer_->Draw(list, cam).ok());
        images[cull] = renderer_->ReadPixels();
      }
      // Without shadows most of the tree is culled; with them, what shades the view stays.
      if (!shadows) {
        EXPECT_GT(culled, items / 3) << "azimuth " << az << ": culling should drop most of the "
                                     << items << " chains; it dropped " << culled;
        EXPECT_LT(triangles[1], triangles[0]) << "azimuth " << az;
      }
      size_t differ = 0;
      for (size_t i = 0; i < images[0].rgba.size(); ++i)
        differ += images[0].rgba[i] != images[1].rgba[i];
      EXPECT_EQ(differ, 0u) << "azimuth " << az << (shadows ? " with" : " without")
                            << " shadows: " << differ
                            << " bytes differ between the culled and the unculled picture";
    }
  }
}

// Mean darkness (1 - pixel / background, mean of the three channels) over
// the whole image, in the stored sRGB values: the renderer resolves its
// multisamples in sRGB space, so this is the quantity that multisampling
// keeps proportional to coverage.
double Darkness(const Image& img, const mesh::Vec3f& background) {
  const mesh::Vec3f bg = mesh::ToSrgb(background) * 255.0f;
  double sum = 0;
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x) {
      const uint8_t* p = img.Pixel(x, y);
      for (int c = 0; c < 3; ++c) sum += 1 - double(p[c]) / double(bg[c]);
    }
  }
  return sum / (3.0 * img.width * img.height);
}

// A grid of nearly vertical twigs radiusPx wide in radius, 4 px apart,
// slanted by 1 in 12 so they cross every sub-pixel offset (a grid aligned
// with the pixels would hit the same multisample positions in every row:
// 2 of 16 samples for 0.3 px centred on a pixel edge). Twig centres in
// pixels: x = W/2 + (x0 + yw / 12) ppu, yw the world height of a row.
struct TwigGrid {
  mesh::PlantGeometry geometry;
  std::vector<double> x0;  // world x of each twig at y = 0
  double ppu = 0;
};

TwigGrid MakeTwigGrid(const Camera& cam, int W, int H, double radiusPx) {
  TwigGrid t;
  t.ppu = (H / 2.0) / (std::tan(cam.fovY * kDegToRad / 2) * cam.distance);
  const double halfW = W / 2.0 / t.ppu, halfH = H / 2.0 / t.ppu;
  uint32_t branch = 0;
  for (double x = -halfW + 2 / t.ppu; x < halfW; x += 4 / t.ppu) {
    mesh::Segment s;
    s.start = Vec3(x - halfH * 0.1, -halfH * 1.2, 0);
    s.end = Vec3(x + halfH * 0.1, halfH * 1.2, 0);
    s.left = Vec3(-1, 0, 0);
    s.radiusStart = s.radiusEnd = float(radiusPx / t.ppu);
    s.branch = s.parent = branch++;
    t.geometry.segments.push_back(s);
    t.x0.push_back(x);
  }
  t.geometry.branchCount = branch;
  return t;
}

Camera TwigCamera() {
  Camera cam;
  cam.target = Vec3(0, 0, 0);
  cam.azimuth = 0;
  cam.elevation = 0;
  cam.distance = 10;
  return cam;
}

// The darkness each twig adds to each row: the sum over the 4 pixels
// centred on it, for every twig and row clear of the image border; with
// `worldX`, the twig's world x in that row.
std::vector<double> TwigRowDarkness(const Image& img, const TwigGrid& t,
                                    const mesh::Vec3f& background,
                                    std::vector<double>* worldX = nullptr) {
  const mesh::Vec3f bg = mesh::ToSrgb(background) * 255.0f;
  std::vector<double> out;
  for (int row = 0; row < img.height; ++row) {
    const double yw = (img.height / 2.0 - (row + 0.5)) / t.ppu;
    for (double x0 : t.x0) {
      const double px = img.width / 2.0 + (x0 + yw / 12) * t.ppu;
      const int first = int(std::ceil(px - 2 - 0.5));
      if (first < 0 || first + 4 > img.width) continue;
      double sum = 0;
      for (int x = first; x < first + 4; ++x)
        for (int c = 0; c < 3; ++c) sum += (1 - double(img.Pixel(x, row)[c]) / double(bg[c])) / 3;
      out.push_back(sum);
      if (worldX) worldX->push_back(x0 + yw / 12);
    }
  }
  return out;
}

double Mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? 0 : s / double(v.size());
}

// Coefficient of variation: 0 for a twig that darkens every row alike.
double Variation(const std::vector<double>& v) {
  const double m = Mean(v);
  double s = 0;
  for (double x : v) s += (x - m) * (x - m);
  return v.empty() || !(m > 0) ? 0 : std::sqrt(s / double(v.size())) / m;
}

// A grid of twigs 0.3 px wide without coverage lines: they are ribbons,
// and with 4x multisampling the picture keeps their coverage (0.3 / 4 of
// each row) on average. The expected mean is that of the same grid at
// 8 x 8 the resolution (2.4 px wide, 16-sided tubes, nearly every pixel
// covered wholly or not at all), and the ribbons darken as much as
// 16-sided tubes at the same resolution do. (Both are about 35 % darker
// than the reference averaged in linear light, because the renderer
// resolves multisamples in sRGB space.)
TEST_F(ScreenDetailRender, SubPixelTwigsKeepTheirCoverage) {
  const int W = 160, H = 120;
  const Camera cam = TwigCamera();
  const TwigGrid grid = MakeTwigGrid(cam, W, H, 0.15);
  const mesh::PlantGeometry& g = grid.geometry;
  const mesh::Vec3f bg = renderer_->background();
  auto draw = [&](const mesh::TessellateOptions& opt, int scale) {
    mesh::TriangleMesh m;
    EXPECT_TRUE(mesh::Tessellate(g, opt, m).ok());
    EXPECT_TRUE(renderer_->Resize(W * scale, H * scale).ok());
    renderer_->SetShadows(false);
    renderer_->SetMesh(m, mesh::DefaultPalette());
    renderer_->Draw(cam);
    return std::pair{renderer_->ReadPixels(), m.vertexCount()};
  };
  mesh::TessellateOptions lod;
  lod.view = mesh::ScreenView{cam.ViewProjection(double(W) / H), W, H, 0.5};
  auto [small, smallVerts] = draw(lod, 1);
  EXPECT_EQ(smallVerts, 4 * g.segments.size()) << "the twigs should be ribbons";
  mesh::TessellateOptions uniform;
  uniform.detail.sides = 16;
  auto [big, bigVerts] = draw(uniform, 8);
  auto [tubes, tubeVerts] = draw(uniform, 1);
  const double got = Darkness(small, bg), want = Darkness(big, bg), tube = Darkness(tubes, bg);
  ASSERT_GT(want, 0.01) << "the reference grid should darken the picture";
  EXPECT_NEAR(got / want, 1.0, 0.1)
      << "mean darkness " << got << " with ribbons at 0.3 px, " << want << " in the 8x reference";
  EXPECT_NEAR(got / tube, 1.0, 0.05) << "mean darkness " << got << " with ribbons, " << tube
                                     << " with 16-sided tubes at the same resolution";
  RecordProperty("darkness", std::to_string(got) + " ribbons, " + std::to_string(tube) +
                                 " tubes, " + std::to_string(want) + " reference");
}

// Issue 15's coverage test: a grid of twigs 0.3 px wide drawn as coverage
// lines (ScreenView::coverage: ribbons kLinePixels wide, alpha the true
// width) darkens each row by the analytic coverage within 10 %: the
// twig's width in pixels times the darkness of its colour, measured from
// the same grid drawn 5 px wide (opaque ribbons covering every pixel, the
// same normal toward the eye). The width is 0.3 px at the image centre;
// perspective widens a vertical cylinder at world x (depth 10) by
// sqrt(1 + (x / 10)^2) (up to 8 % at the border), and the slant of 1 in 12
// widens each row's cut by sqrt(1 + 1/144). The darkness is taken in the
// stored sRGB values: the renderer blends (and resolves multisamples) in
// sRGB space, where alpha a gives exactly a times the opaque darkness; in
// linear light the same picture is darker than the linear coverage (see
// docs/lod.md). And the lines fade instead of aliasing: each twig darkens
// every row alike (a 1 px wide line covers 4 of the 4x pattern's samples
// in each row wherever it lies), where plain 0.3 px ribbons hit 0, 1 or 2
// samples a row.
TEST_F(ScreenDetailRender, SubPixelLinesKeepTheAnalyticCoverage) {
  const int W = 160, H = 120;
  const Camera cam = TwigCamera();
  const mesh::Vec3f bg = renderer_->background();
  auto draw = [&](const TwigGrid& grid, double eps, bool coverage, mesh::TriangleMesh* keep) {
    mesh::TessellateOptions opt;
    opt.view = mesh::ScreenView{cam.ViewProjection(double(W) / H), W, H, eps};
    opt.view->coverage = coverage;
    mesh::TriangleMesh m;
    EXPECT_TRUE(mesh::Tessellate(grid.geometry, opt, m).ok());
    EXPECT_EQ(mesh::Validate(m), "");
    EXPECT_TRUE(renderer_->Resize(W, H).ok());
    renderer_->SetShadows(false);
    renderer_->SetMesh(m, mesh::DefaultPalette());
    renderer_->Draw(cam);
    if (keep) *keep = m;
    return renderer_->ReadPixels();
  };
  const TwigGrid thin = MakeTwigGrid(cam, W, H, 0.15);
  mesh::TriangleMesh lines;
  const Image img = draw(thin, 0.5, true, &lines);
  ASSERT_EQ(lines.coverage.size(), lines.vertexCount());
  ASSERT_EQ(lines.vertexCount(), 4 * thin.geometry.segments.size()) << "one line a twig";
  auto width = [&](double x) {
    return 0.3 * std::sqrt(1 + (x / cam.distance) * (x / cam.distance));
  };
  for (size_t i = 0; i < lines.vertexCount(); ++i) {
    const double c = lines.coverage[i], want = width(lines.positions[i].x());
    ASSERT_NEAR(c / want, 1.0, 0.02)
        << "coverage of a twig 0.3 px wide (at the centre) drawn 1 px "
           "wide, at x = "
        << lines.positions[i].x() << ": " << c << ", expected " << want;
  }
  // eps 2: ribbons up to 6 px in radius, so the 2.5 px twigs are opaque ribbons.
  const Image solid = draw(MakeTwigGrid(cam, W, H, 2.5), 2, true, nullptr);
  const double opaque = Darkness(solid, bg);
  ASSERT_GT(opaque, 0.05) << "the twigs' colour should be darker than the background";
  std::vector<double> xs;
  const std::vector<double> rows = TwigRowDarkness(img, thin, bg, &xs);
  ASSERT_GT(rows.size(), size_t(W * H / 8));
  double expected = 0;
  for (double x : xs) expected += width(x) * std::sqrt(1 + 1.0 / 144) * opaque / double(xs.size());
  const double got = Mean(rows);
  EXPECT_NEAR(got / expected, 1.0, 0.1) << "darkness a twig adds to a row: " << got << ", analytic "
                                        << expected << " (its width times " << opaque << ")";
  // Without coverage lines: the same twigs as 0.3 px ribbons.
  const Image ribbons = draw(thin, 0.5, false, nullptr);
  const std::vector<double> ribbonRows = TwigRowDarkness(ribbons, thin, bg);
  const double lineVar = Variation(rows), ribbonVar = Variation(ribbonRows);
  EXPECT_LT(lineVar, 0.15) << "a coverage line should darken each row alike; ribbons vary by "
                           << ribbonVar;
  EXPECT_LT(lineVar * 3, ribbonVar)
      << "coverage lines vary " << lineVar << " row to row, ribbons " << ribbonVar;
  // For the record: the same comparison in linear light, where sRGB-space
  // blending makes thin twigs darker than their coverage.
  auto linearDarkness = [&](const Image& im) {
    auto lin = [](double c) {
      return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
    };
    const mesh::Vec3f bgs = mesh::ToSrgb(bg);
    double sum = 0;
    for (size_t i = 0; i < im.rgba.size(); i += 4)
      for (int c = 0; c < 3; ++c) sum += 1 - lin(im.rgba[i + size_t(c)] / 255.0) / lin(bgs[c]);
    return sum / (3.0 * im.width * im.height);
  };
  const double linearRatio =
      linearDarkness(img) / (linearDarkness(solid) * Darkness(img, bg) / opaque);
  RecordProperty("coverage", std::to_string(got) + " measured, " + std::to_string(expected) +
                                 " analytic; row variation " + std::to_string(lineVar) +
                                 " lines, " + std::to_string(ribbonVar) + " ribbons");
  std::printf(
      "coverage lines: %.5f a twig a row, analytic %.5f (ratio %.4f); ribbons %.5f\n"
      "row-to-row variation: lines %.4f, ribbons %.4f\n"
      "in linear light: %.3f times the linear coverage\n",
      got, expected, got / expected, Mean(ribbonRows), lineVar, ribbonVar, linearRatio);
}

// The DrawList pipeline (scenes) blends coverage lines as the single-mesh
// path does: the 0.3 px grid darkens the picture by the same amount
// within 2 %, and far less than the same lines drawn opaque (coverage
// dropped) would.
TEST_F(ScreenDetailRender, DrawListBlendsCoverageLinesToo) {
  const int W = 160, H = 120;
  const Camera cam = TwigCamera();
  const TwigGrid grid = MakeTwigGrid(cam, W, H, 0.15);
  mesh::TessellateOptions opt;
  opt.view = mesh::ScreenView{cam.ViewProjection(double(W) / H), W, H, 0.5};
  opt.view->coverage = true;
  auto m = std::make_shared<mesh::TriangleMesh>();
  ASSERT_TRUE(mesh::Tessellate(grid.geometry, opt, *m).ok());
  ASSERT_EQ(m->coverage.size(), m->vertexCount());
  ASSERT_TRUE(renderer_->Resize(W, H).ok());
  auto drawList = [&](std::shared_ptr<const mesh::TriangleMesh> mesh) {
    draw::DrawList list;
    list.background = renderer_->background();
    draw::MeshDraw d;
    d.mesh = std::move(mesh);
    d.palette = mesh::DefaultPalette();
    d.instances.push_back({});
    d.castsShadow = false;
    list.meshes.push_back(d);
    EXPECT_TRUE(renderer_->Draw(list, cam).ok());
    return renderer_->ReadPixels();
  };
  const mesh::Vec3f bg = renderer_->background();
  const double scene = Darkness(drawList(m), bg);
  auto opaque = std::make_shared<mesh::TriangleMesh>(*m);
  opaque->coverage.clear();
  const double solid = Darkness(drawList(opaque), bg);
  renderer_->SetShadows(false);
  renderer_->SetMesh(*m, mesh::DefaultPalette());
  renderer_->Draw(cam);
  const double single = Darkness(renderer_->ReadPixels(), bg);
  ASSERT_GT(single, 0.005);
  // Lighting differs between the pipelines (the scene's default lights),
  // so compare each to its own opaque picture: coverage 0.3 of it.
  EXPECT_NEAR(scene / solid, 0.3, 0.03)
      << "DrawList darkness " << scene << " with coverage, " << solid << " drawn opaque";
  std::printf("DrawList: %.5f with coverage, %.5f opaque (ratio %.3f); single mesh %.5f\n", scene,
              solid, scene / solid, single);
}

// Without popping: a slow dolly toward the tree that wobbles (three steps
// of 3 % in, one back out, as a hand on a mouse does) changes each chain's
// representation (coverage line, ribbon, sides) only one way with the
// history's hysteresis: no chain flips back and forth. Without a history
// some do, so the test can fail. And the pictures change smoothly: the
// mean change between consecutive frames with screen-space detail exceeds
// that with uniform 16 sides (where only the motion changes the picture)
// by little.
TEST_F(ScreenDetailRender, SlowDollyDoesNotFlipDetailBackAndForth) {
  auto p =
      sylva::testing::PlantFromFile("abop/fig2_06a_monopodial.lsys", 10, plant::Stage::kGeometry);
  ASSERT_TRUE(p);
  const mesh::Box box = mesh::TessellatedBounds(p->geometry, nullptr);
  const int W = 480, H = 270;
  Camera cam = Camera::Frame(box.lo, box.hi, double(W) / H, 30, 12, false);
  std::vector<double> distances;
  double d = cam.distance * 1.2;
  for (int k = 0; k < 48; ++k) {
    distances.push_back(d);
    d *= k % 4 == 3 ? 1 / 0.97 : 0.97;
  }
  // Drawn as `sylva render` draws a grammar: in the default scene (its
  // ground and shadows), through the DrawList.
  auto drawScene = [&](mesh::TriangleMesh m) {
    auto shared = std::make_shared<const mesh::TriangleMesh>(std::move(m));
    const draw::DrawList list = scene::DefaultScene(shared, mesh::DefaultPalette(), box.lo, box.hi);
    EXPECT_TRUE(renderer_->Draw(list, cam).ok());
    return renderer_->ReadPixels();
  };
  auto run = [&](bool hysteresis, bool render, std::vector<Image>* frames) {
    mesh::DetailHistory history;
    std::vector<std::vector<int16_t>> levels;
    for (double dist : distances) {
      cam.distance = dist;
      mesh::TessellateOptions opt;
      opt.view = mesh::ScreenView{cam.ViewProjection(double(W) / H), W, H, 0.5};
      opt.view->coverage = true;
      opt.history = &history;
      if (!hysteresis) history.level.clear();
      mesh::TriangleMesh m;
      EXPECT_TRUE(mesh::Tessellate(p->geometry, opt, m).ok());
      levels.push_back(history.level);
      if (!render) continue;
      EXPECT_TRUE(renderer_->Resize(W, H).ok());
      frames->push_back(drawScene(std::move(m)));
    }
    // Reversals: a chain whose level changes against its previous change.
    size_t reversals = 0, changes = 0;
    for (size_t c = 0; c < levels[0].size(); ++c) {
      int lastDir = 0;
      for (size_t k = 1; k < levels.size(); ++k) {
        const int dir = (levels[k][c] > levels[k - 1][c]) - (levels[k][c] < levels[k - 1][c]);
        if (!dir) continue;
        ++changes;
        reversals += lastDir && dir != lastDir;
        lastDir = dir;
      }
    }
    return std::pair{reversals, changes};
  };
  std::vector<Image> lodFrames, uniformFrames;
  const auto [reversals, changes] = run(true, true, &lodFrames);
  const auto [without, changesWithout] = run(false, false, nullptr);
  EXPECT_GT(changes, 0u) << "the dolly should change some chain's detail";
  EXPECT_EQ(reversals, 0u) << reversals << " of " << changes
                           << " detail changes went back against the previous one";
  EXPECT_GT(without, 0u) << "without hysteresis the wobble should flip some chains ("
                         << changesWithout << " changes)";
  for (double dist : distances) {
    cam.distance = dist;
    mesh::TessellateOptions opt;
    opt.detail.sides = 16;
    mesh::TriangleMesh m;
    ASSERT_TRUE(mesh::Tessellate(p->geometry, opt, m).ok());
    uniformFrames.push_back(drawScene(std::move(m)));
  }
  auto change = [](const Image& a, const Image& b) {
    double sum = 0;
    for (size_t i = 0; i < a.rgba.size(); ++i) sum += std::abs(int(a.rgba[i]) - int(b.rgba[i]));
    return sum / double(a.rgba.size());
  };
  double worstExtra = 0, worstLod = 0, worstUniform = 0;
  for (size_t k = 1; k < distances.size(); ++k) {
    const double lod = change(lodFrames[k], lodFrames[k - 1]);
    const double uni = change(uniformFrames[k], uniformFrames[k - 1]);
    worstExtra = std::max(worstExtra, lod - uni);
    worstLod = std::max(worstLod, lod);
    worstUniform = std::max(worstUniform, uni);
  }
  EXPECT_LT(worstExtra, 0.25 * worstUniform)
      << "a frame with screen-space detail changed by " << worstExtra
      << " (mean, 8-bit) more than the uniform one; the largest change from motion alone is "
      << worstUniform;
  std::printf(
      "dolly: %zu detail changes, %zu reversals (%zu without hysteresis in %zu changes); "
      "frame-to-frame change: worst %.4f with detail, %.4f uniform, worst excess %.4f\n",
      changes, reversals, without, changesWithout, worstLod, worstUniform, worstExtra);
}

int RunCli(const std::vector<std::string>& args, std::string* out, std::string* err) {
  std::ostringstream o, e;
  const int code = app::RunCliWithGraphics(args, o, e);
  *out = o.str();
  *err = e.str();
  return code;
}

size_t TrianglesIn(const std::string& stats) {
  const size_t at = stats.find("triangles: ");
  return at == std::string::npos ? 0 : std::stoul(stats.substr(at + 11));
}

TEST(ScreenDetailCli, RenderPrintsStatsAndLodIsTheDefault) {
  const std::string g = std::string(SYLVA_SOURCE_DIR) + "/grammars/abop/fig2_06a_monopodial.lsys";
  const std::string png = ::testing::TempDir() + "sylva_lod_cli.png";
  std::string out, err;
  ASSERT_EQ(RunCli({"render", g, "-n", "12", "--size", "160x90", "--stats", "-o", png}, &out, &err),
            0)
      << err;
  const size_t lod = TrianglesIn(out);
  for (const char* stage : {"derive: ", "turtle: ", "tessellate: ", "draw: ", "total: "}) {
    EXPECT_NE(out.find(stage), std::string::npos) << "no '" << stage << "' in:\n" << out;
  }
  ASSERT_EQ(
      RunCli({"render", g, "-n", "12", "--size", "160x90", "--stats", "--sides", "16", "-o", png},
             &out, &err),
      0)
      << err;
  const size_t uniform = TrianglesIn(out);
  EXPECT_GT(lod, 0u);
  EXPECT_LT(lod * 10, uniform) << lod << " screen-space vs " << uniform << " uniform triangles";
  // --supersample renders larger and filters down: the PNG keeps --size.
  ASSERT_EQ(RunCli({"render", g, "-n", "6", "--size", "80x60", "--supersample", "3", "-o", png},
                   &out, &err),
            0)
      << err;
  EXPECT_NE(err.find("80x60"), std::string::npos) << err;
  // --sides and --lod-eps exclude each other; a too-large supersampled image is refused.
  EXPECT_EQ(RunCli({"render", g, "--sides", "8", "--lod-eps", "1", "-o", png}, &out, &err), 2);
  EXPECT_EQ(
      RunCli({"render", g, "--size", "4000x100", "--supersample", "4", "-o", png}, &out, &err), 2);
  EXPECT_NE(err.find("--supersample"), std::string::npos) << err;
}

// `sylva mesh --lod-eps` writes the mesh of one view: fewer triangles than
// the uniform default, and a valid file.
TEST(ScreenDetailCli, MeshForOneView) {
  const std::string g = std::string(SYLVA_SOURCE_DIR) + "/grammars/abop/fig2_06a_monopodial.lsys";
  const std::string glb = ::testing::TempDir() + "sylva_lod_cli.glb";
  auto trianglesOf = [](const std::string& err) {
    const size_t at = err.find(" triangles,");
    size_t begin = err.rfind(' ', at - 1);
    return at == std::string::npos ? size_t(0) : std::stoul(err.substr(begin + 1, at - begin));
  };
  std::string out, err;
  ASSERT_EQ(RunCli({"mesh", g, "-n", "12", "-o", glb}, &out, &err), 0) << err;
  const size_t uniform = trianglesOf(err);
  ASSERT_EQ(RunCli({"mesh", g, "-n", "12", "--lod-eps", "0.5", "--size", "320x180", "-o", glb},
                   &out, &err),
            0)
      << err;
  const size_t lod = trianglesOf(err);
  EXPECT_GT(lod, 0u) << err;
  EXPECT_LT(lod * 5, uniform) << lod << " for the view, " << uniform << " uniform (8 sides)";
  EXPECT_EQ(RunCli({"mesh", g, "--lod-eps", "0.5", "--sides", "8", "-o", glb}, &out, &err), 2);
  EXPECT_EQ(RunCli({"mesh", g, "--lod-eps", "0.5", "--size", "0x9", "-o", glb}, &out, &err), 2);
  EXPECT_NE(err.find("--size '0x9'"), std::string::npos) << err;
}

}  // namespace
}  // namespace sylva::render

namespace sylva::render {
namespace {

using StagedUpload = testing::RenderFixture;

// The viewer's swap (Renderer::Stage): a new tessellation uploaded in
// slices of 64 KB, and its shadow map drawn in bands, while the previous
// one is drawn in between, shows exactly the picture Draw makes of it in
// one go (on a fresh renderer). The slices are counted, so the test fails
// if the budget is not kept.
TEST_F(StagedUpload, SlicesShowTheSamePictureAsOneUpload) {
  auto p =
      sylva::testing::PlantFromFile("abop/fig2_06a_monopodial.lsys", 11, plant::Stage::kGeometry);
  ASSERT_TRUE(p);
  const mesh::Box box = mesh::TessellatedBounds(p->geometry, nullptr);
  const int W = 320, H = 180;
  auto sceneFor = [&](const Camera& cam) {
    mesh::TessellateOptions opt;
    opt.view = mesh::ScreenView{cam.ViewProjection(double(W) / H), W, H, 0.5};
    opt.view->coverage = true;  // coverage lines: the sorted index buffer and attribute 8
    opt.view->shadowFrom = KeyLightDirection();
    opt.view->shadowPlaneY = box.lo.y();
    opt.view->shadowTexelsPerUnit = ShadowTexelsPerUnit(box);
    auto m = std::make_shared<mesh::TriangleMesh>();
    EXPECT_TRUE(mesh::Tessellate(p->geometry, opt, *m).ok());
    return scene::DefaultScene(m, mesh::DefaultPalette(), box.lo, box.hi);
  };
  Camera before = Camera::Frame(box.lo, box.hi, double(W) / H, 30, 12, false);
  Camera after = before;
  after.azimuth += 40;
  after.distance *= 0.5;
  const draw::DrawList shown = sceneFor(before), next = sceneFor(after);
  const size_t bytes =
      next.meshes[0].mesh->vertexCount() * 40 + next.meshes[0].mesh->indices.size() * 4;
  ASSERT_TRUE(renderer_->Resize(W, H).ok());
  ASSERT_TRUE(renderer_->Draw(shown, before).ok());
  int calls = 0;
  for (bool done = false; !done && calls < 10000; ++calls) {
    auto r = renderer_->Stage(next, 64 << 10);
    ASSERT_TRUE(r.ok()) << r.error().Format();
    done = *r;
    ASSERT_TRUE(renderer_->Draw(shown, before).ok());  // the shown mesh meanwhile
  }
  EXPECT_GE(calls, int(bytes / (64 << 10))) << bytes << " bytes in " << calls << " calls";
  ASSERT_TRUE(renderer_->Draw(next, after).ok());
  const Image staged = renderer_->ReadPixels();

  auto fresh = Renderer::Create(std::string(SYLVA_SOURCE_DIR) + "/shaders");
  ASSERT_TRUE(fresh.ok());
  ASSERT_TRUE((*fresh)->Resize(W, H).ok());
  ASSERT_TRUE((*fresh)->Draw(next, after).ok());
  const Image whole = (*fresh)->ReadPixels();
  ASSERT_EQ(staged.rgba.size(), whole.rgba.size());
  size_t differ = 0;
  for (size_t i = 0; i < whole.rgba.size(); ++i) differ += staged.rgba[i] != whole.rgba[i];
  EXPECT_EQ(differ, 0u) << "bytes that differ after " << calls << " staged calls";
}

}  // namespace
}  // namespace sylva::render
