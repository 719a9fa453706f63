// Screen-space detail through the renderer: culling never changes a pixel,
// and the `sylva render` flags (--stats, --sides, --supersample) do what
// docs/cli.md says.
#include <gtest/gtest.h>

#include <sstream>
#include <string>

#include "app/graphics.h"
#include "mesh/screen_detail.h"
#include "mesh/tessellator.h"
#include "plant/plant_test_util.h"
#include "render/camera.h"
#include "render/render_fixture.h"
#include "render/renderer.h"

namespace sylva::render {
namespace {

class ScreenDetailRender : public testing::RenderFixture {};

// A close-up inside the crown (most of the tree is outside the frustum),
// without and with the ground and its shadows (a branch outside the view
// may cast a shadow into it, so culling keeps it then).
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
    for (bool shadows : {false, true}) {
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
        ASSERT_TRUE(renderer_->Resize(W, H).ok());
        renderer_->SetGround(shadows);
        renderer_->SetShadows(shadows);
        renderer_->SetMesh(m, mesh::DefaultPalette(), &box);
        renderer_->Draw(cam);
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

}  // namespace
}  // namespace sylva::render
