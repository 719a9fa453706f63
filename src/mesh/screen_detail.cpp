#include "mesh/screen_detail.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace sylva::mesh {

int SidesForPixelRadius(double radiusPx, double eps) {
  constexpr double kPi = 3.14159265358979323846;
  if (!(radiusPx <= 1e300) || !(eps > 0)) return 256;
  if (radiusPx <= eps) return 3;
  // r (1 - cos(pi/n)) <= eps  <=>  n >= pi / acos(1 - eps / r).
  const double n = kPi / std::acos(1 - eps / radiusPx);
  // The ceiling, less a rounding margin, so r = 1, eps = 0.5 (n = 3 exactly) is 3.
  const double c = std::ceil(n - 1e-9);
  return int(std::clamp(c, 3.0, 256.0));
}

int ChainLevel(double radiusPx, double eps, bool coverage) {
  if (coverage && radiusPx < kLinePixels / 2) return 0;
  if (radiusPx < 3 * eps) return 1;
  return SidesForPixelRadius(radiusPx, eps);
}

int ChainLevelAfter(int last, double radiusPx, double eps, bool coverage) {
  const int lo = ChainLevel(radiusPx, eps, coverage);
  if (last < 0) return lo;
  const int hi = ChainLevel(radiusPx * (1 + kHysteresis), eps, coverage);
  return std::clamp(last, lo, hi);
}

double PixelsPerUnit(const ScreenView& view, const Vec3& p) {
  const Mat4& m = view.viewProjection;
  const Vec4 c = m * Vec4(p.x(), p.y(), p.z(), 1);
  if (!(c.w() > 1e-12)) return std::numeric_limits<double>::infinity();
  const double x = c.x() / c.w(), y = c.y() / c.w();
  // d(ndc)/dp = (row_i - ndc_i row_3) / w over the first three columns;
  // pixels are ndc * size / 2.
  const Vec3 r3 = m.block<1, 3>(3, 0).transpose();
  const Vec3 jx = (m.block<1, 3>(0, 0).transpose() - x * r3) * (0.5 * view.width / c.w());
  const Vec3 jy = (m.block<1, 3>(1, 0).transpose() - y * r3) * (0.5 * view.height / c.w());
  // Largest singular value of the 2x3 Jacobian: the larger eigenvalue of J J^T.
  const double a = jx.dot(jx), b = jx.dot(jy), d = jy.dot(jy);
  const double h = (a - d) / 2;
  return std::sqrt((a + d) / 2 + std::sqrt(h * h + b * b));
}

Vec2 PixelOffset(const ScreenView& view, const Vec3& p, const Vec3& d) {
  const Mat4& m = view.viewProjection;
  const Vec4 c = m * Vec4(p.x(), p.y(), p.z(), 1);
  if (!(c.w() > 1e-12)) return Vec2::Constant(std::numeric_limits<double>::infinity());
  const double x = c.x() / c.w(), y = c.y() / c.w();
  const Vec3 r3 = m.block<1, 3>(3, 0).transpose();
  return Vec2((m.block<1, 3>(0, 0).transpose() - x * r3).dot(d) * (0.5 * view.width / c.w()),
              (m.block<1, 3>(1, 0).transpose() - y * r3).dot(d) * (0.5 * view.height / c.w()));
}

Vec3 TowardEye(const ScreenView& view, const Vec3& p) {
  const Mat4& m = view.viewProjection;
  const Vec4 c = m * Vec4(p.x(), p.y(), p.z(), 1);
  if (!(std::abs(c.w()) > 1e-12)) return Vec3::Zero();
  const double x = c.x() / c.w(), y = c.y() / c.w(), z = c.z() / c.w();
  const Vec3 r3 = m.block<1, 3>(3, 0).transpose();
  const Vec3 jx = m.block<1, 3>(0, 0).transpose() - x * r3;
  const Vec3 jy = m.block<1, 3>(1, 0).transpose() - y * r3;
  const Vec3 jz = m.block<1, 3>(2, 0).transpose() - z * r3;  // depth grows away from the eye
  Vec3 d = jx.cross(jy);
  if (!(d.norm() > 0)) return Vec3::Zero();
  d.normalize();
  return d.dot(jz) * c.w() > 0 ? Vec3(-d) : d;
}

Frustum Frustum::FromViewProjection(const Mat4& m) {
  Frustum f;
  const Vec4 r0 = m.row(0).transpose(), r1 = m.row(1).transpose(), r2 = m.row(2).transpose(),
             r3 = m.row(3).transpose();
  f.planes[0] = r3 + r0;
  f.planes[1] = r3 - r0;
  f.planes[2] = r3 + r1;
  f.planes[3] = r3 - r1;
  f.planes[4] = r3 + r2;
  f.planes[5] = r3 - r2;
  return f;
}

Frustum::Side Frustum::Classify(const Box& b) const {
  bool inside = true;
  for (const Vec4& p : planes) {
    // The box corner farthest along the plane normal (p-vertex) and the nearest (n-vertex).
    Vec3 far, near;
    for (int k = 0; k < 3; ++k) {
      far[k] = p[k] >= 0 ? b.hi[k] : b.lo[k];
      near[k] = p[k] >= 0 ? b.lo[k] : b.hi[k];
    }
    if (p.head<3>().dot(far) + p[3] < 0) return Side::kOutside;
    if (p.head<3>().dot(near) + p[3] < 0) inside = false;
  }
  return inside ? Side::kInside : Side::kStraddles;
}

namespace {

bool Bounded(const Box& b) {
  return (b.lo.array() <= b.hi.array()).all() && (b.lo.array().abs() <= 1e300).all() &&
         (b.hi.array().abs() <= 1e300).all();
}

constexpr uint32_t kLeafSize = 8;

}  // namespace

BoundingHierarchy::BoundingHierarchy(const std::vector<Box>& boxes) : size_(boxes.size()) {
  for (uint32_t i = 0; i < boxes.size(); ++i) {
    (Bounded(boxes[i]) ? items_ : unbounded_).push_back(i);
  }
  if (!items_.empty()) {
    nodes_.reserve(2 * items_.size() / kLeafSize + 2);
    Build(0, uint32_t(items_.size()), boxes);
  }
}

uint32_t BoundingHierarchy::Build(uint32_t first, uint32_t count, const std::vector<Box>& boxes) {
  const uint32_t id = uint32_t(nodes_.size());
  nodes_.emplace_back();
  Box box, centres;
  for (uint32_t i = first; i < first + count; ++i) {
    const Box& b = boxes[items_[i]];
    box.Add(b);
    centres.Add((b.lo + b.hi) / 2);
  }
  nodes_[id].box = box;
  if (count <= kLeafSize) {
    nodes_[id].first = first;
    nodes_[id].count = count;
    return id;
  }
  // Median split along the longest axis of the centres; ties broken by
  // index, so the tree does not depend on the sort's implementation.
  int axis = 0;
  const Vec3 ext = centres.hi - centres.lo;
  if (ext.y() > ext[axis]) axis = 1;
  if (ext.z() > ext[axis]) axis = 2;
  const uint32_t half = count / 2;
  auto key = [&](uint32_t i) { return boxes[i].lo[axis] + boxes[i].hi[axis]; };
  std::nth_element(items_.begin() + first, items_.begin() + first + half,
                   items_.begin() + first + count, [&](uint32_t a, uint32_t b) {
                     const double ka = key(a), kb = key(b);
                     return ka < kb || (ka == kb && a < b);
                   });
  const uint32_t l = Build(first, half, boxes);
  const uint32_t r = Build(first + half, count - half, boxes);
  nodes_[id].left = l;
  nodes_[id].right = r;
  return id;
}

void BoundingHierarchy::Mark(uint32_t id, const Frustum& f, bool inside,
                             std::vector<uint8_t>& out) const {
  const Node& n = nodes_[id];
  if (!inside) {
    const Frustum::Side s = f.Classify(n.box);
    if (s == Frustum::Side::kOutside) return;
    inside = s == Frustum::Side::kInside;
  }
  if (n.count) {
    for (uint32_t i = n.first; i < n.first + n.count; ++i) out[items_[i]] = 1;
    return;
  }
  Mark(n.left, f, inside, out);
  Mark(n.right, f, inside, out);
}

std::vector<uint8_t> BoundingHierarchy::Visible(const Frustum& f) const {
  std::vector<uint8_t> out(size_, 0);
  for (uint32_t i : unbounded_) out[i] = 1;
  if (!nodes_.empty()) Mark(0, f, false, out);
  return out;
}

}  // namespace sylva::mesh
