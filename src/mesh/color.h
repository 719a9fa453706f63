// Colour: one convention for all of Sylva. Colours are sRGB where people
// write or read them (grammar `palette:` entries, OBJ `Kd`, PLY's 8-bit
// vertex colours, PNG pixels) and linear RGB everywhere inside (Palette,
// the renderer's mesh, line, point and background colours, glTF's
// baseColorFactor, which the glTF spec defines as linear). Each value is
// converted once, where it crosses that boundary, with the exact sRGB
// transfer function (IEC 61966-2-1), not a 2.2 power.
#pragma once

#include <cmath>

#include "mesh/triangle_mesh.h"

namespace sylva::mesh {

inline float SrgbToLinear(float c) {
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

inline float LinearToSrgb(float c) {
  return c <= 0.0031308f ? c * 12.92f : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

// A colour written as sRGB (0..1 a channel, as in a colour picker or
// `#rrggbb` / 255), in linear RGB.
inline Vec3f Srgb(float r, float g, float b) {
  return Vec3f(SrgbToLinear(r), SrgbToLinear(g), SrgbToLinear(b));
}
inline Vec3f Srgb(const Vec3f& c) {
  return Srgb(c.x(), c.y(), c.z());
}

// A linear colour as sRGB (0..1 a channel).
inline Vec3f ToSrgb(const Vec3f& c) {
  return Vec3f(LinearToSrgb(c.x()), LinearToSrgb(c.y()), LinearToSrgb(c.z()));
}

}  // namespace sylva::mesh
