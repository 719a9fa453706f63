// Text into an image with stb_easy_font: see text.h.
#include "render/text.h"

#include <algorithm>
#include <cmath>
#include <vector>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wsign-conversion"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wold-style-cast"
#pragma GCC diagnostic ignored "-Wdouble-promotion"
#pragma GCC diagnostic ignored "-Wuseless-cast"
#include <stb/stb_easy_font.h>
#pragma GCC diagnostic pop

namespace sylva::render {

size_t DrawText(Image& image, double x, double y, const std::string& text, const Vec3f& color,
                int scale) {
  if (text.empty() || image.width <= 0 || image.height <= 0 || !std::isfinite(x) ||
      !std::isfinite(y))
    return 0;
  scale = std::clamp(scale, 1, 16);
  // stb_easy_font writes 4 vertices of 16 bytes a quad; a character is
  // drawn with fewer than 32 quads (its segments), 2 KiB a character.
  std::vector<char> buffer(text.size() * 32 * 64 + 1024);
  // The font covers ' ' to '~' (its table is indexed by c - 32): other
  // characters are drawn as '?'.
  std::string copy = text;
  for (char& c : copy)
    if (c != '\n' && (c < 32 || c > 126)) c = '?';
  unsigned char rgba[4] = {255, 255, 255, 255};
  // The font's rows run 0 (top) to 7 (below the baseline of most letters);
  // its baseline is at row 7 (stb_easy_font's characters sit on y + 7).
  const int quads = stb_easy_font_print(0, 0, copy.data(), rgba, buffer.data(), int(buffer.size()));
  const uint8_t out[3] = {uint8_t(std::clamp(color.x(), 0.f, 1.f) * 255.f + 0.5f),
                          uint8_t(std::clamp(color.y(), 0.f, 1.f) * 255.f + 0.5f),
                          uint8_t(std::clamp(color.z(), 0.f, 1.f) * 255.f + 0.5f)};
  size_t set = 0;
  for (int q = 0; q < quads; ++q) {
    const float* v0 = reinterpret_cast<const float*>(buffer.data() + size_t(q) * 64);
    const float* v2 = reinterpret_cast<const float*>(buffer.data() + size_t(q) * 64 + 32);
    // Font units to pixels: the baseline (font y 7) at image y.
    const double fx0 = x + v0[0] * scale, fx1 = x + v2[0] * scale;
    const double fy0 = y + (v0[1] - 7) * scale, fy1 = y + (v2[1] - 7) * scale;
    const int x0 = std::max(0, int(std::floor(std::min(fx0, fx1)))),
              x1 = std::min(image.width, int(std::floor(std::max(fx0, fx1)))),
              y0 = std::max(0, int(std::floor(std::min(fy0, fy1)))),
              y1 = std::min(image.height, int(std::floor(std::max(fy0, fy1))));
    for (int py = y0; py < y1; ++py) {
      for (int px = x0; px < x1; ++px) {
        uint8_t* p = &image.rgba[4 * (size_t(py) * size_t(image.width) + size_t(px))];
        p[0] = out[0];
        p[1] = out[1];
        p[2] = out[2];
        p[3] = 255;
        ++set;
      }
    }
  }
  return set;
}

}  // namespace sylva::render
