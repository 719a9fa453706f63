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

}  // namespace
}  // namespace sylva::app
