// Views for mesh tests: a perspective view-projection built by hand (the
// mesh library has no camera; render::Camera is GL-side).
#pragma once

#include <cmath>

#include "core/math.h"

namespace sylva::testing {

// A perspective view-projection (OpenGL conventions) looking from eye at target.
inline Mat4 LookAtPerspective(const Vec3& eye, const Vec3& target, double fovYDeg, double aspect) {
  const Vec3 f = (target - eye).normalized();
  Vec3 up = std::abs(f.y()) > 0.99 ? Vec3::UnitZ() : Vec3::UnitY();
  const Vec3 s = f.cross(up).normalized(), u = s.cross(f);
  Mat4 v = Mat4::Identity();
  v.block<1, 3>(0, 0) = s.transpose();
  v.block<1, 3>(1, 0) = u.transpose();
  v.block<1, 3>(2, 0) = -f.transpose();
  v(0, 3) = -s.dot(eye);
  v(1, 3) = -u.dot(eye);
  v(2, 3) = f.dot(eye);
  const double zn = 0.01, zf = 1000, t = 1 / std::tan(fovYDeg * 3.14159265358979323846 / 360);
  Mat4 p = Mat4::Zero();
  p(0, 0) = t / aspect;
  p(1, 1) = t;
  p(2, 2) = -(zf + zn) / (zf - zn);
  p(2, 3) = -2 * zf * zn / (zf - zn);
  p(3, 2) = -1;
  return p * v;
}

}  // namespace sylva::testing
