// Camera: orbit parameters to view and projection matrices (OpenGL
// conventions: right-handed, clip z in [-1, 1]). GL-free, so it is tested
// without a context.
//
// The eye sits at target + distance * (cos(el) sin(az), sin(el),
// cos(el) cos(az)): azimuth 0 and elevation 0 look from +Z toward -Z, the
// default of GRAMMAR.md, so 2D ABOP figures come out as printed.
#pragma once

#include "core/math.h"

namespace sylva::render {

struct Camera {
  Vec3 target{0, 0, 0};
  double azimuth = 30;    // degrees
  double elevation = 15;  // degrees, -89..89
  double distance = 10;
  double fovY = 35;  // degrees (perspective)
  bool orthographic = false;
  double orthoHeight = 10;  // world units shown vertically (orthographic)
  // Clip planes; 0: from the distance (distance / 1000 and 4 distance + 1).
  double nearPlane = 0, farPlane = 0;

  Vec3 Eye() const;
  Mat4 View() const;
  Mat4 Projection(double aspect) const;
  Mat4 ViewProjection(double aspect) const { return Projection(aspect) * View(); }
  // Zooms by `factor` (under 1: closer, what is shown grows by 1 / factor):
  // the distance in perspective, the extent shown (orthoHeight) in an
  // orthographic view, where moving the eye changes nothing on screen.
  void Zoom(double factor) { (orthographic ? orthoHeight : distance) *= factor; }

  // A camera at the given angles that frames the box [lo, hi] with a margin.
  // Always a usable camera: a box with a non-finite, inverted or huge
  // (beyond +-1e30) component
  // (NaN hides in y and z too) is framed as the unit box at the origin, a
  // non-finite angle as 0 and a non-positive or non-finite aspect as 1.
  // Callers frame meshes the exporters would accept, so this is a guard.
  static Camera Frame(const Vec3& lo, const Vec3& hi, double aspect, double azimuth,
                      double elevation, bool orthographic);
};

// Pixel coordinates (x right, y down, pixel centres at +0.5) of a world point.
Vec2 ToPixel(const Mat4& viewProjection, const Vec3& p, int width, int height);

}  // namespace sylva::render
