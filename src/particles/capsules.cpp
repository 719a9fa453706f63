#include "particles/capsules.h"

#include <algorithm>
#include <cmath>

#include "particles/segment_box.h"

namespace sylva::particles {
namespace {

// The first root in [0, 1] of A s^2 + 2 B s + C = 0 that enters (the
// smaller root), or false.
bool Entry(double A, double B, double C, double* s) {
  if (!(A > 0)) return false;
  const double h = B * B - A * C;
  if (h < 0) return false;
  const double root = (-B - std::sqrt(h)) / A;
  if (!(root >= 0 && root <= 1)) return false;
  *s = root;
  return true;
}

// The closest point of segment pa-pb to x.
Vec3 Closest(const Capsule& c, const Vec3& x) {
  const Vec3 ba = c.b - c.a;
  const double baba = ba.squaredNorm();
  const double h = baba > 0 ? std::clamp((x - c.a).dot(ba) / baba, 0.0, 1.0) : 0.0;
  return c.a + h * ba;
}

Vec3 OutwardNormal(const Capsule& c, const Vec3& x, const Vec3& fallback) {
  const Vec3 d = x - Closest(c, x);
  const double len = d.norm();
  return len > 0 ? Vec3(d / len) : fallback;
}

// The contact point of an entry at s with normal n, on the surface, nudged
// out by a relative 1e-9 so rounding keeps it outside (as thin colliders
// do); a path that starts inside (s = 0) gets the nearest surface point.
Vec3 SurfacePoint(const Capsule& cap, const Vec3& a, const Vec3& b, double s, const Vec3& n) {
  Vec3 p = a + s * (b - a);
  if (s == 0 && (a - Closest(cap, a)).squaredNorm() < cap.radius * cap.radius)
    p = Closest(cap, a) + cap.radius * n;
  return p + n * (1e-9 * std::max(1.0, p.cwiseAbs().maxCoeff()));
}

}  // namespace

bool IntersectCapsule(const Capsule& cap, const Vec3& a, const Vec3& b, double* s, Vec3* normal) {
  const Vec3 d = b - a;
  const double r2 = cap.radius * cap.radius;
  // Starting inside: contact at once, at the nearest surface point.
  if ((a - Closest(cap, a)).squaredNorm() < r2) {
    *s = 0;
    *normal = OutwardNormal(cap, a, d.norm() > 0 ? Vec3(-d.normalized()) : Vec3::UnitY());
    return true;
  }
  double best = 2;
  const Vec3 ba = cap.b - cap.a, oa = a - cap.a;
  const double baba = ba.squaredNorm(), bad = ba.dot(d), baoa = ba.dot(oa);
  // Side: the path's distance from the axis, scaled by |ba|^2.
  double t;
  if (baba > 0 && Entry(baba * d.squaredNorm() - bad * bad, baba * d.dot(oa) - baoa * bad,
                        baba * oa.squaredNorm() - baoa * baoa - r2 * baba, &t)) {
    const double y = baoa + t * bad;
    if (y > 0 && y < baba) best = t;
  }
  // The end balls.
  for (const Vec3& centre : {cap.a, cap.b}) {
    const Vec3 oc = a - centre;
    if (Entry(d.squaredNorm(), d.dot(oc), oc.squaredNorm() - r2, &t) && t < best) best = t;
  }
  if (best > 1) return false;
  *s = best;
  *normal = OutwardNormal(cap, a + best * d, Vec3::UnitY());
  return true;
}

CapsuleBvh::CapsuleBvh(std::vector<Capsule> capsules) {
  for (const Capsule& c : capsules) {
    if (c.a.allFinite() && c.b.allFinite() && std::isfinite(c.radius) && c.radius > 0)
      capsules_.push_back(c);
    else
      ++dropped_;
  }
  if (!capsules_.empty()) Build(0, uint32_t(capsules_.size()), 1);
  BuildGrid();
}

void CapsuleBvh::BuildGrid() {
  if (nodes_.empty()) return;
  const Vec3 lo = nodes_[0].lo, hi = nodes_[0].hi;
  const Vec3 extent = (hi - lo).cwiseMax(Vec3::Constant(1e-9));
  // About four cells a capsule, at most 256 an axis.
  double cell = std::cbrt(extent.prod() / (4.0 * double(capsules_.size())));
  cell = std::max({cell, extent.maxCoeff() / 256, 1e-9});
  for (int k = 0; k < 3; ++k) dims_[k] = std::clamp(int(std::ceil(extent[k] / cell)), 1, 256);
  cell_ = cell;
  gridLo_ = lo;
  const size_t cells = size_t(dims_[0]) * size_t(dims_[1]) * size_t(dims_[2]);
  auto range = [&](const Capsule& c, int lo3[3], int hi3[3]) {
    const Vec3 a = (c.a.cwiseMin(c.b) - Vec3::Constant(c.radius) - gridLo_) / cell_;
    const Vec3 b = (c.a.cwiseMax(c.b) + Vec3::Constant(c.radius) - gridLo_) / cell_;
    for (int k = 0; k < 3; ++k) {
      lo3[k] = std::clamp(int(std::floor(a[k])), 0, dims_[k] - 1);
      hi3[k] = std::clamp(int(std::floor(b[k])), 0, dims_[k] - 1);
    }
  };
  // Counting pass, prefix sums, then the lists, capsule by capsule (so
  // each cell lists its capsules in order: the answer does not depend on
  // how the grid was filled).
  std::vector<uint32_t> count(cells + 1, 0);
  size_t total = 0;
  for (const Capsule& c : capsules_) {
    int l[3], h[3];
    range(c, l, h);
    const size_t n = size_t(h[0] - l[0] + 1) * size_t(h[1] - l[1] + 1) * size_t(h[2] - l[2] + 1);
    total += n;
    if (total > (size_t(1) << 28)) {  // a capsule list past 1 GiB: keep the hierarchy alone
      dims_[0] = dims_[1] = dims_[2] = 0;
      return;
    }
    for (int k = l[2]; k <= h[2]; ++k)
      for (int j = l[1]; j <= h[1]; ++j)
        for (int i = l[0]; i <= h[0]; ++i)
          ++count[(size_t(k) * size_t(dims_[1]) + size_t(j)) * size_t(dims_[0]) + size_t(i) + 1];
  }
  for (size_t i = 1; i <= cells; ++i) count[i] += count[i - 1];
  start_ = count;
  items_.resize(total);
  for (uint32_t ci = 0; ci < capsules_.size(); ++ci) {
    int l[3], h[3];
    range(capsules_[ci], l, h);
    for (int k = l[2]; k <= h[2]; ++k)
      for (int j = l[1]; j <= h[1]; ++j)
        for (int i = l[0]; i <= h[0]; ++i)
          items_[count[(size_t(k) * size_t(dims_[1]) + size_t(j)) * size_t(dims_[0]) +
                       size_t(i)]++] = ci;
  }
}

bool CapsuleBvh::IntersectGrid(const Vec3& a, const Vec3& b, Contact* c, double r) const {
  const Vec3 pad = Vec3::Constant(r);
  const Vec3 lo = (a.cwiseMin(b) - pad - gridLo_) / cell_,
             hi = (a.cwiseMax(b) + pad - gridLo_) / cell_;
  int l[3], h[3];
  for (int k = 0; k < 3; ++k) {
    if (hi[k] < 0 || lo[k] >= dims_[k]) return false;  // wholly outside the grid: no capsule
    l[k] = std::max(0, int(std::floor(lo[k])));
    h[k] = std::min(dims_[k] - 1, int(std::floor(hi[k])));
  }
  double best = 2;
  Vec3 bestNormal = Vec3::Zero();
  Capsule bestCap;
  for (int k = l[2]; k <= h[2]; ++k)
    for (int j = l[1]; j <= h[1]; ++j)
      for (int i = l[0]; i <= h[0]; ++i) {
        const size_t cellIndex =
            (size_t(k) * size_t(dims_[1]) + size_t(j)) * size_t(dims_[0]) + size_t(i);
        for (uint32_t t = start_[cellIndex]; t < start_[cellIndex + 1]; ++t) {
          double s;
          Vec3 n;
          Capsule cap = capsules_[items_[t]];
          cap.radius += r;
          if (IntersectCapsule(cap, a, b, &s, &n) && s < best) {
            best = s;
            bestNormal = n;
            bestCap = cap;
          }
        }
      }
  if (best > 1) return false;
  c->s = best;
  c->normal = bestNormal;
  c->point = SurfacePoint(bestCap, a, b, best, bestNormal);
  return true;
}

uint32_t CapsuleBvh::Build(uint32_t first, uint32_t count, int depth) {
  return BuildMedianSplit(
      nodes_, capsules_, first, count, depth, depth_,
      [](const Capsule& c, Vec3& lo, Vec3& hi) {
        lo = lo.cwiseMin(c.a.cwiseMin(c.b) - Vec3::Constant(c.radius));
        hi = hi.cwiseMax(c.a.cwiseMax(c.b) + Vec3::Constant(c.radius));
      },
      [](const Capsule& c) { return Vec3(c.a + c.b); });
}

bool CapsuleBvh::Intersect(const Vec3& a, const Vec3& b, Contact* c, double r) const {
  if (nodes_.empty()) return false;
  // A short path (its box within 8 cells): the grid's lists.
  if (dims_[0] > 0) {
    const Vec3 span = ((b - a).cwiseAbs().array() + 2 * r) / cell_;
    if (span.allFinite() && (span.array() + 1).prod() <= 8.5) return IntersectGrid(a, b, c, r);
  }
  const Vec3 d = b - a;
  double best = 2;
  Vec3 bestNormal = Vec3::Zero();
  Capsule bestCap;
  WalkSegment(
      nodes_, a, d, best,
      [&](uint32_t first, uint32_t count) {
        for (uint32_t i = first; i < first + count; ++i) {
          double s;
          Vec3 n;
          Capsule cap = capsules_[i];
          cap.radius += r;
          if (IntersectCapsule(cap, a, b, &s, &n) && s < best) {
            best = s;
            bestNormal = n;
            bestCap = cap;
          }
        }
      },
      r);
  if (best > 1) return false;
  c->s = best;
  c->normal = bestNormal;
  // On the surface, nudged out by a relative 1e-9 so rounding keeps the
  // point outside (as thin colliders do).
  c->point = SurfacePoint(bestCap, a, b, best, bestNormal);
  return true;
}

bool CapsuleBvh::Contains(const Vec3& x) const {
  if (nodes_.empty()) return false;
  uint32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if ((x.array() < node.lo.array()).any() || (x.array() > node.hi.array()).any()) continue;
    if (node.count == 0) {
      if (top + 2 > 128) continue;
      stack[top++] = node.left;
      stack[top++] = node.right;
      continue;
    }
    for (uint32_t i = node.first; i < node.first + node.count; ++i) {
      const Capsule& c = capsules_[i];
      if ((x - Closest(c, x)).squaredNorm() < c.radius * c.radius) return true;
    }
  }
  return false;
}

}  // namespace sylva::particles
