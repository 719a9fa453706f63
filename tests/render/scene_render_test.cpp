// Scenes through the real commands: `sylva render scene.xml --time T` and
// `sylva simulate scene.xml -o frames/%04d.png --dump state.csv`, judged by
// what a user would look for in the pictures and files.
#include <gtest/gtest.h>
#include <stb_image.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "app/commands.h"
#include "app/graphics.h"
#include "app/scene_camera.h"
#include "mesh/screen_detail.h"
#include "render/headless_context.h"
#include "render/renderer.h"
#include "scene/build.h"
#include "scratch_dir.h"

namespace sylva::render {
namespace {

namespace fs = std::filesystem;

int Sylva(std::vector<std::string> args, std::string* err) {
  std::ostringstream o, e;
  const int code = app::RunCliWithGraphics(args, o, e);
  *err = e.str();
  return code;
}

std::string Example(const char* name) {
  return std::string(SYLVA_SOURCE_DIR) + "/examples/scenes/" + name;
}

struct Pixels {
  int w = 0, h = 0;
  std::vector<unsigned char> rgba;
};

Pixels Load(const std::string& path) {
  Pixels p;
  int n = 0;
  unsigned char* px = stbi_load(path.c_str(), &p.w, &p.h, &n, 4);
  if (!px) return p;
  p.rgba.assign(px, px + size_t(p.w) * size_t(p.h) * 4);
  stbi_image_free(px);
  return p;
}

TEST(SceneRender, TheFlagIsRedInTheMiddleOfTheSkyAndWavesWithTime) {
  const fs::path dir = sylva::testing::ScratchDir("sylva_scene_render_");
  std::string err;
  const std::string a = (dir / "a.png").string(), b = (dir / "b.png").string();
  ASSERT_EQ(
      Sylva({"render", Example("flag.xml"), "--time", "2", "--size", "320x180", "-o", a}, &err), 0)
      << err;
  ASSERT_EQ(
      Sylva({"render", Example("flag.xml"), "--time", "2.5", "--size", "320x180", "-o", b}, &err),
      0)
      << err;
  const Pixels pa = Load(a), pb = Load(b);
  ASSERT_EQ(pa.w, 320);
  ASSERT_EQ(pa.h, 180);
  size_t red = 0, differ = 0, skyTop = 0;
  for (int y = 0; y < pa.h; ++y)
    for (int x = 0; x < pa.w; ++x) {
      const unsigned char* p = &pa.rgba[4 * (size_t(y) * 320 + size_t(x))];
      const unsigned char* q = &pb.rgba[4 * (size_t(y) * 320 + size_t(x))];
      if (p[0] > 120 && p[0] > 3 * p[1] && p[0] > 3 * p[2]) ++red;
      if (std::abs(p[0] - q[0]) + std::abs(p[1] - q[1]) + std::abs(p[2] - q[2]) > 30) ++differ;
      // The sky's top colour is #3d6eb4: blue over red in the top rows.
      if (y < 10 && p[2] > p[0] + 60) ++skyTop;
    }
  EXPECT_GT(red, 320u * 180 / 25) << "red flag pixels (over 4% of the picture expected)";
  EXPECT_GT(differ, 200u) << "pixels that changed between t = 2 and 2.5 s (the flag waves)";
  EXPECT_GT(skyTop, 320u * 10 * 9 / 10) << "sky-blue pixels in the top rows";
}

TEST(SceneRender, ABadSceneIsExitTwoAndWritesNothing) {
  const fs::path dir = sylva::testing::ScratchDir("sylva_scene_render_");
  const std::string scene = (dir / "bad.xml").string();
  std::ofstream(scene) << "<scene version=\"1\">\n  <wind gust=\"fast\"/>\n</scene>\n";
  const std::string out = (dir / "out.png").string();
  std::string err;
  EXPECT_EQ(Sylva({"render", scene, "-o", out}, &err), 2) << err;
  EXPECT_NE(err.find("bad.xml:2:15: error: 'gust': expected a decimal number"), std::string::npos)
      << err;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(Sylva({"simulate", scene, "-o", (dir / "f%03d.png").string()}, &err), 2) << err;
  EXPECT_FALSE(fs::exists(dir / "f000.png"));
}

TEST(SceneSimulate, WritesEveryFrameAndTheFinalStateAsCsv) {
  const fs::path dir = sylva::testing::ScratchDir("sylva_scene_simulate_");
  const std::string frames = (dir / "frames" / "%04d.png").string();
  const std::string csv = (dir / "state.csv").string();
  std::string err;
  ASSERT_EQ(Sylva({"simulate", Example("fireworks.xml"), "--duration", "3", "--fps", "2", "-o",
                   frames, "--dump", csv, "--size", "160x90"},
                  &err),
            0)
      << err;
  for (int k = 0; k <= 6; ++k) {
    char name[16];
    std::snprintf(name, sizeof name, "%04d.png", k);
    EXPECT_EQ(Load((dir / "frames" / name).string()).w, 160) << name;
  }
  EXPECT_FALSE(fs::exists(dir / "frames" / "0007.png")) << "3 s at 2 frames a second: 7 frames";
  std::ifstream in(csv);
  std::string header, line;
  std::getline(in, header);
  EXPECT_EQ(header, "system,id,x,y,z,vx,vy,vz,age");
  size_t shells = 0, sparks = 0;
  while (std::getline(in, line)) {
    shells += line.rfind("shells,", 0) == 0;
    sparks += line.rfind("sparks,", 0) == 0;
  }
  EXPECT_GT(shells, 0u);
  EXPECT_GT(sparks, 0u)
      << "by 3 s the first shells (born at 0.67 s, living 1.6 to 1.9 s) have burst";
}

TEST(RenderCli, WireframeDrawsTheTrianglesEdges) {
  const fs::path dir = sylva::testing::ScratchDir("sylva_wire_");
  const std::string grammar =
      std::string(SYLVA_SOURCE_DIR) + "/grammars/abop/fig2_06a_monopodial.lsys";
  std::string err;
  const std::string plain = (dir / "plain.png").string(), wire = (dir / "wire.png").string();
  for (const auto& [out, flag] : {std::pair{plain, ""}, std::pair{wire, "--wireframe"}}) {
    std::vector<std::string> args = {"render",  grammar,    "-n",      "8",  "--size",
                                     "320x180", "--camera", "30,12,3", "-o", out};
    if (*flag) args.push_back(flag);
    ASSERT_EQ(Sylva(args, &err), 0) << err;
  }
  const Pixels a = Load(plain), b = Load(wire);
  ASSERT_EQ(a.rgba.size(), b.rgba.size());
  size_t darkA = 0, darkB = 0;
  for (size_t i = 0; i < a.rgba.size(); i += 4) {
    darkA += a.rgba[i] + a.rgba[i + 1] + a.rgba[i + 2] < 3 * 40;
    darkB += b.rgba[i] + b.rgba[i + 1] + b.rgba[i + 2] < 3 * 40;
  }
  EXPECT_GT(darkB, darkA + 200) << "near-black pixels: " << darkA << " without the wireframe, "
                                << darkB << " with it";
}

}  // namespace
}  // namespace sylva::render

namespace sylva::render {
namespace {

// Scenes' own plant meshes with screen-space detail (scene::DetailForView,
// as `sylva render scene.xml` calls it): with ScreenView::coverage the
// forest's sub-pixel twigs become coverage lines, and the DrawList blends
// them, so the picture is lighter than with the same lines drawn opaque.
TEST(SceneRender, ForestTwigsUnderAPixelAreCoverageLines) {
  std::ostringstream err;
  int exit = 0;
  auto run = app::StartScene({Example("snowy_forest.xml"), {}, 0, false, 1, 8}, err, &exit);
  ASSERT_TRUE(run) << err.str();
  const int W = 480, H = 270;
  const Camera cam = app::SceneCamera(run->scene, run->built, double(W) / H);
  mesh::ScreenView view;
  view.viewProjection = cam.ViewProjection(double(W) / H);
  view.width = W;
  view.height = H;
  view.coverage = true;
  DiagnosticList warnings;
  ASSERT_TRUE(scene::DetailForView(run->built, view, warnings).ok());
  size_t lines = 0, vertices = 0;
  for (const scene::BuiltMesh& m : run->built.meshes) {
    if (!m.drawMesh) continue;
    vertices += m.drawMesh->vertexCount();
    for (float c : m.drawMesh->coverage) lines += c < 1;
  }
  EXPECT_GT(lines, 100u) << "vertices of coverage lines among " << vertices;
  auto context = HeadlessContext::Create();
  ASSERT_TRUE(context.ok());
  auto renderer = Renderer::Create(std::string(SYLVA_SOURCE_DIR) + "/shaders");
  ASSERT_TRUE(renderer.ok());
  ASSERT_TRUE((*renderer)->Resize(W, H).ok());
  auto sum = [&](const draw::DrawList& list) {
    EXPECT_TRUE((*renderer)->Draw(list, cam).ok());
    const Image im = (*renderer)->ReadPixels();
    double s = 0;
    for (uint8_t v : im.rgba) s += v;
    return s / double(im.rgba.size());
  };
  const double blended = sum(scene::MakeDrawList(run->scene, run->built));
  // The same meshes with their coverage dropped: the lines drawn opaque.
  for (scene::BuiltMesh& m : run->built.meshes) {
    if (!m.drawMesh) continue;
    auto opaque = std::make_shared<mesh::TriangleMesh>(*m.drawMesh);
    opaque->coverage.clear();
    m.drawMesh = opaque;
  }
  const double opaque = sum(scene::MakeDrawList(run->scene, run->built));
  EXPECT_GT(blended, opaque + 0.05)
      << "mean 8-bit value with coverage " << blended << ", with the lines opaque " << opaque;
  std::printf("forest: %zu coverage vertices of %zu; mean value %.3f blended, %.3f opaque\n", lines,
              vertices, blended, opaque);
}

}  // namespace
}  // namespace sylva::render
