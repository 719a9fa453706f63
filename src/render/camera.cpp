#include "render/camera.h"

#include <algorithm>
#include <cmath>

namespace sylva::render {

Vec3 Camera::Eye() const {
  const double az = azimuth * kDegToRad, el = elevation * kDegToRad;
  return target +
         distance * Vec3(std::cos(el) * std::sin(az), std::sin(el), std::cos(el) * std::cos(az));
}

Mat4 Camera::View() const {
  const Vec3 eye = Eye();
  const Vec3 f = (target - eye).normalized();
  Vec3 up = Vec3::UnitY();
  if (std::abs(f.dot(up)) > 0.999) up = Vec3::UnitZ();
  const Vec3 s = f.cross(up).normalized();
  const Vec3 u = s.cross(f);
  Mat4 m = Mat4::Identity();
  m.block<1, 3>(0, 0) = s.transpose();
  m.block<1, 3>(1, 0) = u.transpose();
  m.block<1, 3>(2, 0) = -f.transpose();
  m(0, 3) = -s.dot(eye);
  m(1, 3) = -u.dot(eye);
  m(2, 3) = f.dot(eye);
  return m;
}

Mat4 Camera::Projection(double aspect) const {
  const double zn = nearPlane > 0 ? nearPlane : std::max(distance * 1e-3, 1e-6);
  const double zf = farPlane > zn ? farPlane : std::max(distance * 4 + 1, zn * 2);
  Mat4 p = Mat4::Zero();
  if (orthographic) {
    const double h = orthoHeight / 2, w = h * aspect;
    p(0, 0) = 1 / w;
    p(1, 1) = 1 / h;
    p(2, 2) = -2 / (zf - zn);
    p(2, 3) = -(zf + zn) / (zf - zn);
    p(3, 3) = 1;
    return p;
  }
  const double t = 1 / std::tan(fovY * kDegToRad / 2);
  p(0, 0) = t / aspect;
  p(1, 1) = t;
  p(2, 2) = -(zf + zn) / (zf - zn);
  p(2, 3) = -2 * zf * zn / (zf - zn);
  p(3, 2) = -1;
  return p;
}

Camera Camera::Frame(const Vec3& loIn, const Vec3& hiIn, double aspect, double azimuth,
                     double elevation, bool orthographic) {
  // Components within +-1e30 (so the products below stay finite); the
  // comparisons are false for NaN in any component.
  auto within = [](const Vec3& v) { return (v.array().abs() <= 1e30).all(); };
  const bool box = within(loIn) && within(hiIn) && (hiIn - loIn).minCoeff() >= 0;
  const Vec3 lo = box ? loIn : Vec3(0, 0, 0), hi = box ? hiIn : Vec3(1, 1, 1);
  if (!(std::isfinite(aspect) && aspect > 0)) aspect = 1;
  if (!std::isfinite(azimuth)) azimuth = 0;
  if (!std::isfinite(elevation)) elevation = 0;
  Camera c;
  c.azimuth = azimuth;
  c.elevation = elevation;
  c.orthographic = orthographic;
  c.target = (lo + hi) / 2;
  const double radius = std::max((hi - lo).norm() / 2, 1e-6);
  const double margin = 1.08;
  if (orthographic) {
    // Fit the box's extent as seen along the view direction.
    c.distance = radius * 3;
    const Mat4 v = c.View();
    double w = 0, h = 0;
    for (int k = 0; k < 8; ++k) {
      Vec3 corner((k & 1) ? hi.x() : lo.x(), (k & 2) ? hi.y() : lo.y(), (k & 4) ? hi.z() : lo.z());
      Vec4 q = v * Vec4(corner.x(), corner.y(), corner.z(), 1);
      w = std::max(w, std::abs(q.x()));
      h = std::max(h, std::abs(q.y()));
    }
    c.orthoHeight = 2 * std::max(h, w / aspect) * margin;
    if (c.orthoHeight <= 0) c.orthoHeight = 1;
    return c;
  }
  // Perspective: the smallest distance at which every corner of the box
  // projects inside the frame (less the margin), found by bisection between
  // "touching the box" and the distance that fits its bounding sphere.
  const double half = c.fovY * kDegToRad / 2;
  const double halfH = std::atan(std::tan(half) * aspect);
  const double limit = 1 / margin;
  auto fits = [&](double d) {
    Camera t = c;
    t.distance = d;
    const Mat4 vp = t.ViewProjection(aspect);
    for (int k = 0; k < 8; ++k) {
      Vec3 p((k & 1) ? hi.x() : lo.x(), (k & 2) ? hi.y() : lo.y(), (k & 4) ? hi.z() : lo.z());
      Vec4 q = vp * Vec4(p.x(), p.y(), p.z(), 1);
      if (q.w() <= 1e-9 || std::abs(q.x() / q.w()) > limit || std::abs(q.y() / q.w()) > limit)
        return false;
    }
    return true;
  };
  double far = margin * radius / std::sin(std::min(half, halfH)), near = radius * 1.001;
  if (!fits(far)) {
    c.distance = far;
    return c;
  }
  for (int i = 0; i < 40 && near < far; ++i) {
    const double mid = (near + far) / 2;
    (fits(mid) ? far : near) = mid;
  }
  c.distance = far;
  return c;
}

Vec2 ToPixel(const Mat4& vp, const Vec3& p, int width, int height) {
  const Vec4 c = vp * Vec4(p.x(), p.y(), p.z(), 1);
  const double x = c.x() / c.w(), y = c.y() / c.w();
  return Vec2((x * 0.5 + 0.5) * width, (1 - (y * 0.5 + 0.5)) * height);
}

}  // namespace sylva::render
