// Text drawn into a read-back image on the CPU: cpfg's labels (`@L`), which
// `sylva render` writes over the picture after drawing it. GL-free.
//
// The font is stb_easy_font's (public domain; Debian's libstb-dev): about
// 7 pixels tall and 6 wide a character at scale 1.
#pragma once

#include <string>

#include "core/math.h"
#include "render/renderer.h"

namespace sylva::render {

// Draws `text` (its lines split at '\n') into `image` with the left end of
// its first line's baseline at pixel (x, y) (x right, y down), each font
// pixel `scale` image pixels, in sRGB `color` (0..1). Clipped to the image.
// Returns how many image pixels it set.
size_t DrawText(Image& image, double x, double y, const std::string& text, const Vec3f& color,
                int scale = 1);

}  // namespace sylva::render
