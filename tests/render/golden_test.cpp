// Golden images: small renders compared with PNGs kept in tests/render/golden
// with a tolerance (a pixel differs when a channel is off by more than 24;
// at most 1% of pixels may differ), so Mesa versions and MSAA patterns may
// vary slightly. On failure the test writes the new image and a diff image
// (differing pixels red) beside the build. SYLVA_UPDATE_GOLDEN=1 rewrites
// the goldens instead.
#include <gtest/gtest.h>
#include <stb_image.h>

#include <cstdlib>
#include <filesystem>
#include <random>

#include "mesh/tessellator.h"
#include "plant/plant_test_util.h"
#include "render/headless_context.h"
#include "render/render_fixture.h"
#include "render/renderer.h"

namespace sylva::render {
namespace {

namespace fs = std::filesystem;

class Golden : public testing::RenderFixture {
 protected:
  void SetUp() override {
    RenderFixture::SetUp();
    if (HasFatalFailure()) return;
    ASSERT_TRUE(renderer_->Resize(kW, kH).ok());
  }

  void Compare(const std::string& name) {
    renderer_->Finish();
    Image img = renderer_->ReadPixels();
    const fs::path golden = fs::path(SYLVA_SOURCE_DIR) / "tests/render/golden" / (name + ".png");
    if (std::getenv("SYLVA_UPDATE_GOLDEN")) {
      ASSERT_TRUE(WritePng(img, golden.string()).ok());
      return;
    }
    int w = 0, h = 0, n = 0;
    unsigned char* want = stbi_load(golden.string().c_str(), &w, &h, &n, 4);
    ASSERT_NE(want, nullptr) << "missing golden " << golden;
    ASSERT_EQ(w, kW);
    ASSERT_EQ(h, kH);
    Image diff = img;
    size_t differing = 0;
    for (size_t i = 0; i < size_t(w) * size_t(h); ++i) {
      bool off = false;
      for (int k = 0; k < 3; ++k)
        off |= std::abs(int(img.rgba[4 * i + k]) - int(want[4 * i + k])) > 24;
      differing += off;
      diff.rgba[4 * i] = off ? 255 : img.rgba[4 * i] / 3;
      diff.rgba[4 * i + 1] = off ? 0 : img.rgba[4 * i + 1] / 3;
      diff.rgba[4 * i + 2] = off ? 0 : img.rgba[4 * i + 2] / 3;
    }
    stbi_image_free(want);
    const double fraction = double(differing) / (double(w) * h);
    if (fraction > 0.01) {
      const fs::path out = fs::temp_directory_path();
      (void)WritePng(img, (out / (name + ".actual.png")).string());
      (void)WritePng(diff, (out / (name + ".diff.png")).string());
      ADD_FAILURE() << name << ": " << differing << " pixels (" << fraction * 100
                    << "%) differ from the golden; wrote " << (out / (name + ".diff.png"));
    }
  }

  void DrawPlant(const std::string& file, int steps, bool lines) {
    // Through the plant library, interpretation rules included.
    auto p = sylva::testing::PlantFromFile(
        "abop/" + file + ".lsys", steps, lines ? plant::Stage::kGeometry : plant::Stage::kMesh, 8);
    ASSERT_TRUE(p);
    const mesh::PlantGeometry* g = &p->geometry;
    renderer_->SetMesh({}, {});
    ASSERT_TRUE(renderer_->SetLines({}).ok());
    ASSERT_TRUE(renderer_->SetPoints({}).ok());
    if (lines) {
      LineBatch b;
      for (const auto& s : g->segments) {
        b.points.push_back(s.start.cast<float>());
        b.points.push_back(s.end.cast<float>());
        b.colors.push_back(mesh::Srgb(0.2f, 0.15f, 0.1f));
        b.colors.push_back(mesh::Srgb(0.2f, 0.15f, 0.1f));
      }
      renderer_->SetBackground(mesh::Vec3f(1, 1, 1));
      ASSERT_TRUE(renderer_->SetLines(b).ok());
      renderer_->Draw(Camera::Frame(g->boundsMin, g->boundsMax, double(kW) / kH, 0, 0, true));
      return;
    }
    const mesh::TriangleMesh& m = p->mesh;
    Vec3 lo = m.positions[0].cast<double>(), hi = lo;
    for (const auto& p : m.positions) {
      lo = lo.cwiseMin(p.cast<double>());
      hi = hi.cwiseMax(p.cast<double>());
    }
    renderer_->SetBackground(mesh::Srgb(0.94f, 0.95f, 0.96f));
    renderer_->SetMesh(m, mesh::DefaultPalette());
    renderer_->Draw(Camera::Frame(lo, hi, double(kW) / kH, 30, 12, false));
  }

  static constexpr int kW = 240, kH = 180;
};

TEST_F(Golden, MonopodialTreeMesh) {
  DrawPlant("fig2_06a_monopodial", 10, false);
  Compare("monopodial_2_6a");
}

TEST_F(Golden, BracketedPlantLines) {
  DrawPlant("fig1_24c_bracketed_plant", 4, true);
  Compare("bracketed_1_24c");
}

TEST_F(Golden, PointBatch) {
  PointBatch pts;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1, 1);
  for (int i = 0; i < 400; ++i) {
    pts.positions.push_back(mesh::Vec3f(u(rng), u(rng), u(rng)));
    pts.sizes.push_back(0.08f);
    pts.colors.push_back(mesh::Srgb(0.9f, 0.5f + 0.4f * u(rng), 0.2f));
  }
  renderer_->SetMesh({}, {});
  ASSERT_TRUE(renderer_->SetLines({}).ok());
  renderer_->SetBackground(mesh::Srgb(0.1f, 0.1f, 0.15f));
  ASSERT_TRUE(renderer_->SetPoints(pts).ok());
  renderer_->Draw(Camera::Frame(Vec3(-1, -1, -1), Vec3(1, 1, 1), double(kW) / kH, 30, 20, false));
  Compare("points");
}

}  // namespace
}  // namespace sylva::render
