#include "particles/collider.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <numeric>

#include "core/assert.h"
#include "particles/capsules.h"
#include "particles/def_check.h"
#include "particles/segment_box.h"

// The contact functions below inline everything they call (gnu::flatten):
// faster in a normal build, but under AddressSanitizer each call then gets a
// stack frame of about 50 KB whose redzones are written on every call (the
// contact tests ran 90x slower than in Release), so sanitized builds inline
// as usual.
#if defined(__SANITIZE_ADDRESS__)
#define SYLVA_FLATTEN
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SYLVA_FLATTEN
#endif
#endif
#ifndef SYLVA_FLATTEN
#define SYLVA_FLATTEN gnu::flatten
#endif

namespace sylva::particles {
namespace {

// Offset of a contact on a thin surface toward the particle's side.
Vec3 Skin(const Vec3& p, const Vec3& n) {
  return p + n * (1e-9 * std::max(1.0, p.cwiseAbs().maxCoeff()));
}

[[gnu::always_inline]] inline Vec3 Friction(const Vec3& vt, double maxChange) {
  const double len = vt.norm();
  if (len <= maxChange) return Vec3::Zero();
  return vt * (1 - maxChange / len);
}

// Crossing of the segment a -> b with the plane through p with normal n (not
// necessarily unit), from either side. Returns the fraction and the signed
// distances' sign of the side the path came from (+1 or -1).
bool CrossPlane(const Vec3& a, const Vec3& b, const Vec3& p, const Vec3& n, double* s,
                double* side) {
  const double d0 = n.dot(a - p), d1 = n.dot(b - p);
  if (d0 > 0 && d1 < 0) {
    *side = 1;
  } else if (d0 < 0 && d1 > 0) {
    *side = -1;
  } else if (d0 == 0 && d1 != 0) {
    *side = d1 < 0 ? 1 : -1;
  } else {
    return false;
  }
  *s = d0 / (d0 - d1);
  return true;
}

// Both roots of A s^2 + B s + C = 0 in ascending order (false if none).
bool Roots(double A, double B, double C, double* r0, double* r1) {
  const double disc = B * B - 4 * A * C;
  if (!(A > 0) || disc < 0) return false;
  const double q = -0.5 * (B + std::copysign(std::sqrt(disc), B));
  double x0 = q / A, x1 = q != 0 ? C / q : 0;
  if (x0 > x1) std::swap(x0, x1);
  *r0 = x0;
  *r1 = x1;
  return true;
}

Vec3 UnitOr(const Vec3& d, const Vec3& fallback) {
  const double len = d.norm();
  return len > 0 ? Vec3(d / len) : fallback;
}

Vec3 ClosestOnSegment(const Vec3& p0, const Vec3& p1, const Vec3& x) {
  const Vec3 e = p1 - p0;
  const double ee = e.squaredNorm();
  const double t = ee > 0 ? std::clamp(e.dot(x - p0) / ee, 0.0, 1.0) : 0.0;
  return p0 + t * e;
}

// The point of triangle (p0, p1, p2) nearest x (Ericson, "Real-Time
// Collision Detection", 5.1.5).
Vec3 ClosestOnTriangle(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec3& x) {
  const Vec3 ab = p1 - p0, ac = p2 - p0, ap = x - p0;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return p0;
  const Vec3 bp = x - p1;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return p1;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return p0 + (d1 / (d1 - d3)) * ab;
  const Vec3 cp = x - p2;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return p2;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return p0 + (d2 / (d2 - d6)) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return p1 + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (p2 - p1);
  const double denom = va + vb + vc;
  if (!(denom != 0)) return p0;  // degenerate: treated as its first vertex
  return p0 + ab * (vb / denom) + ac * (vc / denom);
}

// Whether q, on the plane of the convex polygon `poly` (counter-clockwise
// about the unit normal n), lies inside it.
bool InsidePolygon(const Vec3* poly, size_t count, const Vec3& n, const Vec3& q) {
  for (size_t i = 0; i < count; ++i) {
    const Vec3& p0 = poly[i];
    const Vec3& p1 = poly[(i + 1) % count];
    if ((p1 - p0).cross(q - p0).dot(n) < -1e-12 * (p1 - p0).squaredNorm()) return false;
  }
  return true;
}

// First entry of the path a -> b into a convex planar polygon grown by r > 0
// (its two faces offset by r along the unit normal n, and a capsule of
// radius r about each edge): where a ball of radius r on the path first
// touches the polygon. The contact point is the ball's centre, nudged out by
// the skin; a path that starts within r of the polygon reports s = 0 at the
// nearest point at distance r.
[[SYLVA_FLATTEN]] bool IntersectGrown(const Vec3* poly, size_t count, const Vec3& n, const Vec3& a,
                                      const Vec3& b, double r, double sBound, Contact* c) {
  const Vec3 d = b - a;
  const double d0 = n.dot(a - poly[0]), d1 = n.dot(b - poly[0]);
  const double side = d0 > 0 ? 1 : d0 < 0 ? -1 : (d1 <= 0 ? 1 : -1);
  const double e0 = side * d0, e1 = side * d1;
  if (std::min(e0, e1) > r) return false;  // stays beyond the slab on one side
  // Starts within r of the face: inside the grown polygon if its foot is.
  if (e0 < r) {
    const Vec3 foot = a - d0 * n;
    if (InsidePolygon(poly, count, n, foot)) {
      c->s = 0;
      c->normal = side * n;
      c->point = Skin(foot + r * c->normal, c->normal);
      return true;
    }
  }
  double best = sBound;
  Vec3 bestNormal = Vec3::Zero(), bestPoint = Vec3::Zero();
  if (e0 >= r && e1 < r) {  // the offset face
    const double s = (e0 - r) / (e0 - e1);
    const Vec3 q = a + s * d;
    if (s < best && InsidePolygon(poly, count, n, q - n.dot(q - poly[0]) * n)) {
      best = s;
      bestNormal = side * n;
      bestPoint = q;
    }
  }
  // The rim: only edges whose box, grown by r, meets the path's box.
  const Vec3 plo = a.cwiseMin(b) - Vec3::Constant(r), phi = a.cwiseMax(b) + Vec3::Constant(r);
  for (size_t i = 0; i < count; ++i) {
    const Capsule cap{poly[i], poly[(i + 1) % count], r};
    if ((cap.a.cwiseMin(cap.b).array() > phi.array()).any() ||
        (cap.a.cwiseMax(cap.b).array() < plo.array()).any()) {
      continue;
    }
    double s;
    Vec3 m;
    if (!IntersectCapsule(cap, a, b, &s, &m) || !(s < best)) continue;
    best = s;
    bestNormal = m;
    bestPoint = s == 0 ? Vec3(ClosestOnSegment(cap.a, cap.b, a) + r * m) : Vec3(a + s * d);
  }
  if (!(best < sBound) || best > 1) return false;
  c->s = best;
  c->normal = bestNormal;
  c->point = Skin(bestPoint, bestNormal);
  return true;
}

// The sphere's radius R and the box L..H of `c` grown by a particle's
// radius r (inside kinds: the room shrunk by r, never below a point).
void Grown(const Collider& c, double r, double* R, Vec3* L, Vec3* H) {
  *R = c.inside ? std::max(c.radius - r, 0.0) : c.radius + r;
  *L = c.lo;
  *H = c.hi;
  if (!(r > 0)) return;
  for (int k = 0; k < 3; ++k) {
    if (!c.inside) {
      (*L)[k] -= r;
      (*H)[k] += r;
    } else if (c.hi[k] - c.lo[k] > 2 * r) {
      (*L)[k] += r;
      (*H)[k] -= r;
    } else {
      (*L)[k] = (*H)[k] = 0.5 * (c.lo[k] + c.hi[k]);
    }
  }
}

}  // namespace

bool Collider::IntersectGrownPolygon(const Vec3& a, const Vec3& b, double r, Contact* c) const {
  return IntersectGrown(polygon.data(), polygon.size(), normal, a, b, r, 2, c);
}

// --- TriangleBvh ---

TriangleBvh::TriangleBvh(std::vector<Vec3> vertices, std::vector<std::array<uint32_t, 3>> triangles)
    : v_(std::move(vertices)), tris_(std::move(triangles)) {
  static std::atomic<uint64_t> serials{0};
  serial_ = ++serials;
  for (const auto& t : tris_) {
    for (uint32_t k : t) SYLVA_ASSERT(k < v_.size());
  }
  if (!tris_.empty()) {
    Build(0, uint32_t(tris_.size()), 1);
    BuildGrid();
  }
  faces_.resize(tris_.size());
  for (size_t i = 0; i < tris_.size(); ++i) {
    Face& f = faces_[i];
    for (int k = 0; k < 3; ++k) f.v[k] = v_[tris_[i][k]];
    f.n = (f.v[1] - f.v[0]).cross(f.v[2] - f.v[0]);
    f.nn = f.n.squaredNorm();
    f.unit = f.nn > 0 ? Vec3(f.n / std::sqrt(f.nn)) : Vec3::Zero();
    f.lo = f.v[0].cwiseMin(f.v[1]).cwiseMin(f.v[2]);
    f.hi = f.v[0].cwiseMax(f.v[1]).cwiseMax(f.v[2]);
  }
}

uint32_t TriangleBvh::Build(uint32_t first, uint32_t count, int depth) {
  return BuildMedianSplit(
      nodes_, tris_, first, count, depth, depth_,
      [&](const std::array<uint32_t, 3>& t, Vec3& lo, Vec3& hi) {
        for (uint32_t k : t) {
          lo = lo.cwiseMin(v_[k]);
          hi = hi.cwiseMax(v_[k]);
        }
      },
      [&](const std::array<uint32_t, 3>& t) { return Vec3(v_[t[0]] + v_[t[1]] + v_[t[2]]); });
}

bool TriangleBvh::ClearOfColumns(const Vec3& lo, const Vec3& hi) const {
  // Clear of the triangles of the columns it covers, where they are few (a
  // flake in the air over a terrain).
  if (columns_.empty()) return false;
  const int u = (up_ + 1) % 3, w = (up_ + 2) % 3;
  // A NaN (in a point or the radius) is clear of nothing; CellOf could not
  // place it.
  if (!(lo[u] <= hi[u] && lo[w] <= hi[w])) return false;
  const int lu = CellOf(lo[u], u), hu = CellOf(hi[u], u);
  const int lw = CellOf(lo[w], w), hw = CellOf(hi[w], w);
  if ((hu - lu + 1) * (hw - lw + 1) > 4) return false;
  for (int cw = lw; cw <= hw; ++cw)
    for (int cu = lu; cu <= hu; ++cu) {
      const Column& col = columns_[size_t(cu) + size_t(dims_[u]) * size_t(cw)];
      if (!(lo[up_] > double(col.hi) || hi[up_] < double(col.lo))) return false;
    }
  return true;
}

bool TriangleBvh::Near(const Vec3& a, const Vec3& b, double r, const MeshMemo* memo) const {
  if (Clear(a, b, r)) return false;
  if (const double reach = MemoReach(memo, a, b, r); reach >= 0) {
    for (int k = 0; k < memo->count; ++k) {
      if (double(memo->dist[k]) <= reach) return true;
    }
    return false;
  }
  const Vec3 lo = a.cwiseMin(b) - Vec3::Constant(r), hi = a.cwiseMax(b) + Vec3::Constant(r);
  if (dims_[0] > 0) {  // the grid: whether a cell the box covers lists a triangle
    const Vec3 glo = (lo - gridLo_) / cell_, ghi = (hi - gridLo_) / cell_;
    if (((ghi - glo).array() + 1).prod() <= 8.5) {
      int l[3], h[3];
      for (int k = 0; k < 3; ++k) {
        if (!(ghi[k] >= 0 && glo[k] < dims_[k])) return false;
        l[k] = std::max(0, int(std::floor(glo[k])));
        h[k] = std::min(dims_[k] - 1, int(std::floor(ghi[k])));
      }
      for (int z = l[2]; z <= h[2]; ++z)
        for (int y = l[1]; y <= h[1]; ++y)
          for (int x = l[0]; x <= h[0]; ++x) {
            const size_t cell =
                (size_t(z) * size_t(dims_[1]) + size_t(y)) * size_t(dims_[0]) + size_t(x);
            if (start_[cell + 1] > start_[cell]) return true;
          }
      return false;
    }
  }
  uint32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if ((lo.array() > node.hi.array()).any() || (hi.array() < node.lo.array()).any()) continue;
    if (node.count > 0) return true;
    if (top + 2 > 128) return true;  // cannot happen for depth < 64
    stack[top++] = node.left;
    stack[top++] = node.right;
  }
  return false;
}

// Triangle i against the path a -> b (of a ball of radius r): its entry s
// if below `best`, with the normal (and, for r > 0, the point).
bool TriangleBvh::HitTriangle(uint32_t i, const Vec3& a, const Vec3& b, double r, double best,
                              Contact* c) const {
  const Face& f = faces_[i];
  if (r > 0) {
    // The triangle's box against the path's box grown by r (most of a
    // cell's triangles miss a short path's box).
    const Vec3 plo = a.cwiseMin(b) - Vec3::Constant(r), phi = a.cwiseMax(b) + Vec3::Constant(r);
    if ((f.lo.array() > phi.array()).any() || (f.hi.array() < plo.array()).any()) return false;
  }
  const Vec3 &v0 = f.v[0], &v1 = f.v[1], &v2 = f.v[2], &n = f.n;
  const double nn = f.nn;
  if (!(nn > 0)) return false;  // degenerate
  if (r > 0) return IntersectGrown(f.v, 3, f.unit, a, b, r, best, c);
  double s, side;
  if (!CrossPlane(a, b, v0, n, &s, &side) || s >= best) return false;
  const Vec3 q = a + s * (b - a);
  const double tol = -1e-12 * nn;
  if ((v1 - v0).cross(q - v0).dot(n) < tol || (v2 - v1).cross(q - v1).dot(n) < tol ||
      (v0 - v2).cross(q - v2).dot(n) < tol) {
    return false;
  }
  c->s = s;
  c->normal = side * f.unit;  // side * n / sqrt(nn): the same bits (side is +-1)
  return true;
}

[[gnu::noinline]] bool TriangleBvh::Intersect(const Vec3& a, const Vec3& b, Contact* c, double r,
                                              MeshMemo* memo) const {
  if (nodes_.empty()) return false;
  const Vec3 d = b - a;
  double best = 2;
  Contact found;
  auto test = [&](uint32_t i) {
    Contact ct;
    if (HitTriangle(i, a, b, r, best, &ct) && ct.s < best) {
      best = ct.s;
      found = ct;
    }
  };
  // A short path (its grown box within 8 cells): the grid's lists; a
  // triangle listed in several cells is tested again, to the same answer.
  const Vec3 glo = (a.cwiseMin(b) - Vec3::Constant(r) - gridLo_) / cell_;
  const Vec3 ghi = (a.cwiseMax(b) + Vec3::Constant(r) - gridLo_) / cell_;
  if (dims_[0] > 0 && ((ghi - glo).array() + 1).prod() <= 8.5) {
    int l[3], h[3];
    for (int k = 0; k < 3; ++k) {
      if (!(ghi[k] >= 0 && glo[k] < dims_[k])) return false;  // outside the grid: no triangle
      l[k] = std::max(0, int(std::floor(glo[k])));
      h[k] = std::min(dims_[k] - 1, int(std::floor(ghi[k])));
    }
    // Within the memo's ball: only its triangles are in reach.
    if (const double reach = MemoReach(memo, a, b, r); reach >= 0)
      return IntersectNear(*memo, reach, a, b, c, r, l, h);
    for (int z = l[2]; z <= h[2]; ++z)
      for (int y = l[1]; y <= h[1]; ++y)
        for (int x = l[0]; x <= h[0]; ++x) {
          const size_t cell =
              (size_t(z) * size_t(dims_[1]) + size_t(y)) * size_t(dims_[0]) + size_t(x);
          for (uint32_t t = start_[cell]; t < start_[cell + 1]; ++t) test(items_[t]);
        }
    // The memo about where the path meets the mesh, where the queries of
    // the rest of the step start.
    if (memo && best <= 1) Remember(a + best * d, r, memo);
  } else {
    WalkSegment(
        nodes_, a, d, best,
        [&](uint32_t first, uint32_t count) {
          for (uint32_t i = first; i < first + count; ++i) test(i);
        },
        r);
  }
  if (best > 1) return false;
  *c = found;
  if (r == 0) c->point = Skin(a + best * d, found.normal);
  return true;
}

double TriangleBvh::MemoReach(const MeshMemo* memo, const Vec3& a, const Vec3& b, double r) const {
  if (!memo || memo->mesh != serial_) return -1;
  // A margin far above the rounding of the triangle tests.
  const double margin = 1e-6 * (1 + memo->centre.cwiseAbs().maxCoeff() + r);
  const double room = memo->clear - r - margin;
  const double far =
      std::sqrt(std::max((a - memo->centre).squaredNorm(), (b - memo->centre).squaredNorm()));
  if (!(far <= room)) return -1;
  return far + r + margin;
}

bool TriangleBvh::IntersectNear(const MeshMemo& memo, double reach, const Vec3& a, const Vec3& b,
                                Contact* c, double r, const int l[3], const int h[3]) const {
  // The full query meets triangle t first in the first cell of [l, h] (z,
  // then y, then x) that lists it, and a cell lists its triangles in
  // increasing order; of equal entries the first met wins. A triangle no
  // cell of [l, h] lists is not tested at all.
  double best = 2;
  size_t bestKey = SIZE_MAX;
  uint32_t bestTri = 0;
  Contact found;
  for (int k = 0; k < memo.count; ++k) {
    if (double(memo.dist[k]) > reach) continue;  // farther than r from the path
    const uint32_t t = memo.near[k];
    const std::array<uint8_t, 6>& cells = cells_[t];  // lo x y z, hi x y z
    bool listed = true;
    int at[3];
    for (int q = 0; q < 3; ++q) {
      listed = listed && cells[q] <= h[q] && cells[3 + q] >= l[q];
      at[q] = std::max(l[q], int(cells[q]));
    }
    if (!listed) continue;
    Contact ct;
    if (!HitTriangle(t, a, b, r, 2, &ct)) continue;
    const size_t key =
        (size_t(at[2]) * size_t(dims_[1]) + size_t(at[1])) * size_t(dims_[0]) + size_t(at[0]);
    if (ct.s < best || (ct.s == best && (key < bestKey || (key == bestKey && t < bestTri)))) {
      best = ct.s;
      bestKey = key;
      bestTri = t;
      found = ct;
    }
  }
  if (best > 1) return false;
  *c = found;
  if (r == 0) c->point = Skin(a + best * (b - a), found.normal);
  return true;
}

void TriangleBvh::Remember(const Vec3& centre, double r, MeshMemo* memo) const {
  // Every triangle within R of the centre, from the grid cells about it
  // (a triangle no such cell lists is farther: its box misses the cube of
  // half-width R). A tenth of a cell of room for the particle to move.
  memo->mesh = 0;
  const double R = r + 0.1 * cell_;
  int l[3], h[3], cells = 1;
  for (int k = 0; k < 3; ++k) {
    const double lo = (centre[k] - R - gridLo_[k]) / cell_,
                 hi = (centre[k] + R - gridLo_[k]) / cell_;
    if (!(hi >= 0 && lo < dims_[k])) return;
    l[k] = std::max(0, int(std::floor(lo)));
    h[k] = std::min(dims_[k] - 1, int(std::floor(hi)));
    cells *= h[k] - l[k] + 1;
  }
  if (cells > 27) return;
  int count = 0;
  for (int z = l[2]; z <= h[2]; ++z)
    for (int y = l[1]; y <= h[1]; ++y)
      for (int x = l[0]; x <= h[0]; ++x) {
        const size_t cell =
            (size_t(z) * size_t(dims_[1]) + size_t(y)) * size_t(dims_[0]) + size_t(x);
        for (uint32_t i = start_[cell]; i < start_[cell + 1]; ++i) {
          const uint32_t t = items_[i];
          if (std::find(memo->near, memo->near + count, t) != memo->near + count) continue;
          const std::array<uint32_t, 3>& tri = tris_[t];
          const Vec3 q = ClosestOnTriangle(v_[tri[0]], v_[tri[1]], v_[tri[2]], centre);
          const double dist = (q - centre).norm();
          if (dist >= R) continue;
          if (count == MeshMemo::kNear) return;  // too many to be worth it
          float rounded = float(dist);           // rounded down
          if (double(rounded) > dist) rounded = std::nextafter(rounded, 0.0f);
          memo->dist[count] = rounded;
          memo->near[count++] = t;
        }
      }
  memo->mesh = serial_;
  memo->centre = centre;
  memo->clear = R;
  memo->count = count;
}

void TriangleBvh::BuildGrid() {
  // About eight cells a triangle, at most 256 an axis.
  Vec3 lo = nodes_[0].lo, hi = nodes_[0].hi;
  const Vec3 extent = (hi - lo).cwiseMax(Vec3::Constant(1e-9));
  if (!extent.allFinite()) return;
  double cell = std::cbrt(extent.prod() / (8.0 * double(tris_.size())));
  cell = std::max({cell, extent.maxCoeff() / 256, 1e-9});
  int dims[3];
  for (int k = 0; k < 3; ++k) dims[k] = std::clamp(int(std::ceil(extent[k] / cell)), 1, 256);
  const size_t cells = size_t(dims[0]) * size_t(dims[1]) * size_t(dims[2]);
  auto range = [&](const std::array<uint32_t, 3>& t, int l[3], int h[3]) {
    const Vec3 tl = v_[t[0]].cwiseMin(v_[t[1]]).cwiseMin(v_[t[2]]);
    const Vec3 th = v_[t[0]].cwiseMax(v_[t[1]]).cwiseMax(v_[t[2]]);
    for (int k = 0; k < 3; ++k) {
      l[k] = std::clamp(int(std::floor((tl[k] - lo[k]) / cell)), 0, dims[k] - 1);
      h[k] = std::clamp(int(std::floor((th[k] - lo[k]) / cell)), 0, dims[k] - 1);
    }
  };
  // Counting pass, prefix sums, then the lists in triangle order.
  std::vector<uint32_t> count(cells + 1, 0);
  size_t total = 0;
  for (const auto& t : tris_) {
    int l[3], h[3];
    range(t, l, h);
    total += size_t(h[0] - l[0] + 1) * size_t(h[1] - l[1] + 1) * size_t(h[2] - l[2] + 1);
    if (total > (size_t(1) << 26)) return;  // lists past 256 MiB: the hierarchy alone
    for (int z = l[2]; z <= h[2]; ++z)
      for (int y = l[1]; y <= h[1]; ++y)
        for (int x = l[0]; x <= h[0]; ++x)
          ++count[(size_t(z) * size_t(dims[1]) + size_t(y)) * size_t(dims[0]) + size_t(x) + 1];
  }
  for (size_t i = 1; i <= cells; ++i) count[i] += count[i - 1];
  start_ = count;
  cells_.resize(tris_.size());
  for (uint32_t ti = 0; ti < tris_.size(); ++ti) {
    int l[3], h[3];
    range(tris_[ti], l, h);
    for (int k = 0; k < 3; ++k) {
      cells_[ti][k] = uint8_t(l[k]);  // dims <= 256
      cells_[ti][3 + k] = uint8_t(h[k]);
    }
  }
  items_.resize(total);
  for (uint32_t ti = 0; ti < tris_.size(); ++ti) {
    int l[3], h[3];
    range(tris_[ti], l, h);
    for (int z = l[2]; z <= h[2]; ++z)
      for (int y = l[1]; y <= h[1]; ++y)
        for (int x = l[0]; x <= h[0]; ++x)
          items_[count[(size_t(z) * size_t(dims[1]) + size_t(y)) * size_t(dims[0]) + size_t(x)]++] =
              ti;
  }
  gridLo_ = lo;
  cell_ = cell;
  for (int k = 0; k < 3; ++k) dims_[k] = dims[k];
  // The columns along the thinnest axis (the first of equals).
  up_ = 0;
  for (int k = 1; k < 3; ++k) {
    if (dims[k] < dims[up_]) up_ = k;
  }
  const int u = (up_ + 1) % 3, w = (up_ + 2) % 3;
  columns_.assign(size_t(dims[u]) * size_t(dims[w]), Column{HUGE_VALF, -HUGE_VALF});
  for (uint32_t ti = 0; ti < tris_.size(); ++ti) {
    int l[3], h[3];
    range(tris_[ti], l, h);
    const auto& t = tris_[ti];
    const double tl = std::min({v_[t[0]][up_], v_[t[1]][up_], v_[t[2]][up_]});
    const double th = std::max({v_[t[0]][up_], v_[t[1]][up_], v_[t[2]][up_]});
    float fl = float(tl), fh = float(th);  // rounded outward
    if (double(fl) > tl) fl = std::nextafter(fl, -HUGE_VALF);
    if (double(fh) < th) fh = std::nextafter(fh, HUGE_VALF);
    for (int cw = l[w]; cw <= h[w]; ++cw)
      for (int cu = l[u]; cu <= h[u]; ++cu) {
        Column& col = columns_[size_t(cu) + size_t(dims[u]) * size_t(cw)];
        col.lo = std::min(col.lo, fl);
        col.hi = std::max(col.hi, fh);
      }
  }
}

// --- Collider ---

Status Validate(const Collider& c) {
  using namespace check;
  switch (c.kind) {
    case Collider::Kind::kPolygon:
      if (c.polygon.size() < 3) {
        return Error("Collider.polygon has " + std::to_string(c.polygon.size()) +
                     " vertices, fewer than 3");
      }
      for (size_t k = 0; k < c.polygon.size(); ++k) {
        SYLVA_CHECK_OK(
            Finite("Collider.polygon[" + std::to_string(k) + "]", c.polygon[k], 1e12, "m"));
      }
      [[fallthrough]];
    case Collider::Kind::kPlane:
      SYLVA_CHECK_OK(Finite("Collider.point", c.point, 1e12, "m"));
      SYLVA_CHECK_OK(Finite("Collider.normal", c.normal, 1e12));
      if (!(std::abs(c.normal.norm() - 1) < 1e-6)) {
        return Error(std::string("Collider.normal ") + Vec(c.normal) + " of a " +
                     (c.kind == Collider::Kind::kPlane ? "plane" : "polygon (from its winding)") +
                     " is not a unit direction");
      }
      break;
    case Collider::Kind::kSphere:
      SYLVA_CHECK_OK(Finite("Collider.point", c.point, 1e12, "m"));
      SYLVA_CHECK_OK(Range("Collider.radius", c.radius, 1e-12, 1e12, "m"));
      break;
    case Collider::Kind::kBox:
      SYLVA_CHECK_OK(Finite("Collider.lo", c.lo, 1e12, "m"));
      SYLVA_CHECK_OK(Finite("Collider.hi", c.hi, 1e12, "m"));
      if (!(c.lo.array() <= c.hi.array()).all()) {
        return Error("Collider.lo " + Vec(c.lo) + " is above hi " + Vec(c.hi) + " in some axis");
      }
      break;
    case Collider::Kind::kMesh:
      if (!c.mesh) return Error("Collider.mesh is null");
      break;
    case Collider::Kind::kCapsules:
      if (!c.capsules) return Error("Collider.capsules is null");
      break;
  }
  SYLVA_CHECK_OK(Finite("Collider.velocity", c.velocity, 1e12, "m/s"));
  SYLVA_CHECK_OK(Finite("Collider.offset", c.offset, 1e12, "m"));
  SYLVA_CHECK_OK(Range("Collider.restitution", c.restitution, 0, 1));
  SYLVA_CHECK_OK(Range("Collider.friction", c.friction, 0, 1e3));
  return {};
}

void Collider::Translate(const Vec3& d) {
  point += d;
  lo += d;
  hi += d;
  for (Vec3& p : polygon) p += d;
  offset += d;
}

Collider Collider::Plane(const Vec3& point, const Vec3& normal) {
  Collider c;
  c.kind = Kind::kPlane;
  c.point = point;
  c.normal = normal.normalized();
  return c;
}

Collider Collider::Sphere(const Vec3& centre, double radius, bool inside) {
  Collider c;
  c.kind = Kind::kSphere;
  c.point = centre;
  c.radius = radius;
  c.inside = inside;
  return c;
}

Collider Collider::Box(const Vec3& lo, const Vec3& hi, bool inside) {
  Collider c;
  c.kind = Kind::kBox;
  c.lo = lo.cwiseMin(hi);
  c.hi = lo.cwiseMax(hi);
  c.inside = inside;
  return c;
}

Collider Collider::Polygon(std::vector<Vec3> vertices) {
  Collider c;
  c.kind = Kind::kPolygon;
  Vec3 n = Vec3::Zero();  // Newell's normal
  for (size_t i = 0; i < vertices.size(); ++i)
    n += vertices[i].cross(vertices[(i + 1) % vertices.size()]);
  c.normal = n.normalized();
  c.point = vertices[0];
  c.polygon = std::move(vertices);
  return c;
}

Collider Collider::Mesh(std::shared_ptr<const TriangleBvh> bvh) {
  Collider c;
  c.kind = Kind::kMesh;
  c.mesh = std::move(bvh);
  return c;
}

Collider Collider::Capsules(std::shared_ptr<const CapsuleBvh> bvh) {
  Collider c;
  c.kind = Kind::kCapsules;
  c.capsules = std::move(bvh);
  return c;
}

[[gnu::noinline, SYLVA_FLATTEN]] bool Collider::IntersectAny(const Vec3& a, const Vec3& b,
                                                             Contact* c, double r,
                                                             MeshMemo* memo) const {
  const Vec3 d = b - a;
  // The thin kinds and the plane first: they need no grown sphere or box.
  switch (kind) {
    case Kind::kPlane:
      return Intersect(a, b, c, r);  // inline in the header
    case Kind::kPolygon: {
      if (r > 0) return IntersectGrownPolygon(a, b, r, c);
      double s, side;
      if (!CrossPlane(a, b, point, normal, &s, &side)) return false;
      const Vec3 q = a + s * d;
      for (size_t i = 0; i < polygon.size(); ++i) {
        const Vec3& p0 = polygon[i];
        const Vec3& p1 = polygon[(i + 1) % polygon.size()];
        if ((p1 - p0).cross(q - p0).dot(normal) < -1e-12 * (p1 - p0).squaredNorm()) return false;
      }
      c->s = s;
      c->normal = side * normal;
      c->point = Skin(q, c->normal);
      return true;
    }
    case Kind::kMesh:
    case Kind::kCapsules: {
      // In the hierarchy's coordinates (offset 0 unless the solid moved).
      const Vec3 ao = a - offset, bo = b - offset;
      const bool hit = kind == Kind::kMesh ? mesh && mesh->Intersect(ao, bo, c, r, memo)
                                           : capsules && capsules->Intersect(ao, bo, c, r);
      if (hit) c->point += offset;
      return hit;
    }
    case Kind::kSphere:
    case Kind::kBox:
      break;
  }
  double R;
  Vec3 L, H;
  Grown(*this, r, &R, &L, &H);
  switch (kind) {
    case Kind::kSphere: {
      const Vec3 ac = a - point;
      const double C = ac.squaredNorm() - R * R;
      if (!inside) {
        if (C < 0) {  // starts inside the ball
          c->s = 0;
          c->normal = UnitOr(ac, Vec3(0, 1, 0));
          c->point = point + R * c->normal;
          return true;
        }
        double s0, s1;
        if (!Roots(d.squaredNorm(), 2 * d.dot(ac), C, &s0, &s1) || s0 < 0 || s0 > 1) return false;
        c->s = s0;
      } else {
        if (C > 0) {  // starts outside the bowl
          c->s = 0;
          const Vec3 u = UnitOr(ac, Vec3(0, 1, 0));
          c->point = point + R * u;
          c->normal = -u;
          return true;
        }
        if ((b - point).squaredNorm() <= R * R) return false;
        double s0, s1;
        if (!Roots(d.squaredNorm(), 2 * d.dot(ac), C, &s0, &s1)) return false;
        c->s = std::clamp(s1, 0.0, 1.0);
      }
      const Vec3 u = UnitOr(a + c->s * d - point, Vec3(0, 1, 0));
      c->point = point + R * u;
      c->normal = inside ? Vec3(-u) : u;
      return true;
    }
    case Kind::kBox: {
      if (!inside) {
        if ((a.array() > L.array()).all() && (a.array() < H.array()).all()) {
          c->s = 0;
          return Project(a, &c->point, &c->normal, r);
        }
        double t0 = -HUGE_VAL, t1 = HUGE_VAL;
        int axis = -1;
        for (int k = 0; k < 3; ++k) {
          if (d[k] == 0) {
            if (a[k] < L[k] || a[k] > H[k]) return false;
            continue;
          }
          double ta = (L[k] - a[k]) / d[k], tb = (H[k] - a[k]) / d[k];
          if (ta > tb) std::swap(ta, tb);
          if (ta > t0) {
            t0 = ta;
            axis = k;
          }
          t1 = std::min(t1, tb);
        }
        if (axis < 0 || t0 > t1 || t0 < 0 || t0 > 1) return false;
        if (t0 == t1) return false;  // grazes an edge or a corner
        c->s = t0;
        c->point = a + t0 * d;
        c->normal = Vec3::Zero();
        c->normal[axis] = d[axis] > 0 ? -1 : 1;
        c->point[axis] = d[axis] > 0 ? L[axis] : H[axis];
        return true;
      }
      if ((a.array() < L.array()).any() || (a.array() > H.array()).any()) {
        c->s = 0;
        return Project(a, &c->point, &c->normal, r);
      }
      double best = 2;
      int axis = -1;
      for (int k = 0; k < 3; ++k) {
        double s = 2;
        if (b[k] < L[k]) s = (a[k] - L[k]) / (a[k] - b[k]);
        if (b[k] > H[k]) s = (H[k] - a[k]) / (b[k] - a[k]);
        if (s < best) {
          best = s;
          axis = k;
        }
      }
      if (axis < 0) return false;
      c->s = best;
      c->point = (a + best * d).cwiseMax(L).cwiseMin(H);
      c->normal = Vec3::Zero();
      c->normal[axis] = b[axis] < L[axis] ? 1 : -1;
      c->point[axis] = b[axis] < L[axis] ? L[axis] : H[axis];
      return true;
    }
    case Kind::kPlane:
    case Kind::kPolygon:
    case Kind::kMesh:
    case Kind::kCapsules:
      break;  // above
  }
  return false;
}

[[gnu::noinline, SYLVA_FLATTEN]] bool Collider::ProjectAny(const Vec3& x, Vec3* surface, Vec3* n,
                                                           double r) const {
  double R;
  Vec3 L, H;
  if (kind == Kind::kPlane) return Project(x, surface, n, r);  // inline in the header
  // Thin kinds are entered from outside; a point inside is not projected.
  if (kind != Kind::kSphere && kind != Kind::kBox) return false;
  Grown(*this, r, &R, &L, &H);
  switch (kind) {
    case Kind::kSphere: {
      const Vec3 rel = x - point;
      const double r2 = rel.squaredNorm();
      if (inside ? r2 <= R * R : r2 >= R * R) return false;
      const Vec3 u = UnitOr(rel, Vec3(0, 1, 0));
      *surface = point + R * u;
      *n = inside ? Vec3(-u) : u;
      return true;
    }
    case Kind::kBox: {
      if (!inside) {
        if (!((x.array() > L.array()).all() && (x.array() < H.array()).all())) return false;
        // Out through the nearest face.
        double best = HUGE_VAL;
        int axis = 0;
        double sign = 1;
        for (int k = 0; k < 3; ++k) {
          if (x[k] - L[k] < best) {
            best = x[k] - L[k];
            axis = k;
            sign = -1;
          }
          if (H[k] - x[k] < best) {
            best = H[k] - x[k];
            axis = k;
            sign = 1;
          }
        }
        *surface = x;
        (*surface)[axis] = sign < 0 ? L[axis] : H[axis];
        *n = Vec3::Zero();
        (*n)[axis] = sign;
        return true;
      }
      const Vec3 clamped = x.cwiseMax(L).cwiseMin(H);
      if (clamped == x) return false;
      int axis;
      (clamped - x).cwiseAbs().maxCoeff(&axis);
      *surface = clamped;
      *n = Vec3::Zero();
      (*n)[axis] = x[axis] < L[axis] ? 1 : -1;
      return true;
    }
    case Kind::kPlane:
    case Kind::kPolygon:
    case Kind::kMesh:
    case Kind::kCapsules:
      return false;  // above
  }
  return false;
}

// --- contact response ---
//
// The hot functions here are flattened (every call inlined but those marked
// noinline): since particles have a radius and colliders can move, GCC's
// inliner gave up on the small Eigen expressions (a dot of a difference, a
// sum assigned) in them and called them out of line, a third slower in
// the cube benchmark. -ffp-contract=off keeps inlining from changing a bit.

namespace {

// The first time t in [0, T] where d0 + b t + c t^2 / 2 reaches 0, given
// d0 > 0 and d(T) < 0 (so there is exactly one root in between); the
// stable form of the quadratic formula, clamped against rounding.
[[gnu::noinline]] double FirstRoot(double d0, double b, double c, double T) {
  const double A = 0.5 * c;
  double t;
  if (std::abs(A) * T <= 1e-12 * std::abs(b)) {
    t = -d0 / b;
  } else {
    const double disc = std::max(0.0, b * b - 4 * A * d0);
    const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
    const double r0 = q / A, r1 = q != 0 ? d0 / q : r0;
    // The smaller root in [0, T] (the other lies outside it).
    t = (r0 >= 0 && r0 <= T) ? r0 : r1;
    if (r0 >= 0 && r0 <= T && r1 >= 0 && r1 <= T) t = std::min(r0, r1);
  }
  return std::clamp(std::isfinite(t) ? t : 0.0, 0.0, T);
}

// Removes the inward part of u against a resting contact of normal n and
// against the earlier resting contacts of the step: u ends tangent to all
// (along their crease, or zero in a corner of three).
[[gnu::noinline]] Vec3 Tangent(const Vec3& u, const Vec3& n, const Vec3* earlier, int count) {
  Vec3 out = u - std::min(u.dot(n), 0.0) * n;
  for (int k = 0; k < count; ++k) {
    const Vec3& m = earlier[k];
    if (out.dot(m) >= 0) continue;
    const Vec3 crease = n.cross(m);
    const double c2 = crease.squaredNorm();
    if (c2 < 1e-24) {  // parallel surfaces: both normals agree
      out -= out.dot(m) * m;
      continue;
    }
    out = crease * (u.dot(crease) / c2);
    for (int j = 0; j < count; ++j) {
      if (out.dot(earlier[j]) < -1e-12 * out.norm()) return Vec3::Zero();  // a corner
    }
    return out;
  }
  return out;
}

// On two surfaces at once (normals n and m, through pn and pm): the point of
// their crease nearest a (projecting on each in turn would only approach
// it); `fallback` if they are parallel.
[[gnu::noinline]] Vec3 CreasePoint(const Vec3& a, const Vec3& n, const Vec3& pn, const Vec3& m,
                                   const Vec3& pm, const Vec3& fallback) {
  const double c = n.dot(m), det = 1 - c * c;
  if (!(det > 1e-12)) return fallback;
  const double dn = n.dot(pn - a), dm = m.dot(pm - a);
  return a + ((dn - c * dm) / det) * n + ((dm - c * dn) / det) * m;
}

// The first contact on the chord a -> x that the response must handle
// (null if none), skipping what needs none: a path that starts on the
// surface and stays on it within rounding (sliding along it, or along a
// crease; *grazed is set, and the final projection puts its end exactly on
// the surface), and a sphere the particle rests on this step (the path left
// along its tangent, which the surface bends away from; the projection puts
// the end back on it). u is h times the path's velocity at a. A path
// that starts at most `skin` above a static plane and ends behind it meets
// it at its start (s = 0, at a itself; see RespondToContacts).
[[gnu::always_inline]] inline const Collider* FindContact(
    const std::vector<Collider>& colliders, const Vec3& a, const Vec3& x, const Vec3& u,
    const Collider* const* restingOn, Contact* best, bool* grazed, double r, double e, double h,
    MeshMemo* memo, double skin = 0) {
  best->s = 2;
  const Collider* hit = nullptr;
  for (const Collider& c : colliders) {
    Contact ct;
    bool sliding;
    if (!c.moving()) [[likely]] {
      if (!c.Intersect(a, x, &ct, r, memo)) continue;
      if (skin > 0 && c.kind == Collider::Kind::kPlane) {
        // Above by d0 (the plane's, as Intersect takes it; its s may have
        // underflowed to 0 for a tiny d0), but within the skin.
        const double d0 = c.normal.dot(a - c.point) - r;
        if (d0 > 0 && d0 <= skin) {
          ct.s = 0;
          ct.point = a;  // where it is: in the skin
        }
      }
      if (ct.s >= best->s) continue;
      sliding = ct.normal.dot(ct.point - x) <= 1e-12 * std::max(1.0, x.cwiseAbs().maxCoeff()) &&
                u.dot(ct.normal) >= -1e-12 * std::max(1e-300, u.cwiseAbs().maxCoeff());
    } else {
      // A moving collider: the path in its frame at the start of the step
      // (a is e of the step in, x at its end). The contact found is in that
      // frame too.
      const Vec3 w = h * c.velocity;
      const Vec3 ar = a - e * w, xr = x - w, ur = u - w;
      if (!c.Intersect(ar, xr, &ct, r, memo) || ct.s >= best->s) continue;
      sliding = ct.normal.dot(ct.point - xr) <= 1e-12 * std::max(1.0, xr.cwiseAbs().maxCoeff()) &&
                ur.dot(ct.normal) >= -1e-12 * std::max(1e-300, ur.cwiseAbs().maxCoeff());
    }
    if (sliding) {
      *grazed = true;
      continue;
    }
    if (c.kind == Collider::Kind::kSphere && (&c == restingOn[0] || &c == restingOn[1])) {
      *grazed = true;
      continue;
    }
    *best = ct;
    hit = &c;
  }
  return hit;
}

// Projects x out of every half-space solid it ended in, removing the
// velocity into it.
[[gnu::always_inline]] inline void ProjectOut(const std::vector<Collider>& colliders, Vec3& x,
                                              Vec3& v, double r, double h) {
  for (const Collider& c : colliders) {
    Vec3 sp, sn;
    if (!c.moving()) {
      if (c.Project(x, &sp, &sn, r)) {
        x = sp;
        const double vn = v.dot(sn);
        if (vn < 0) v -= vn * sn;
      }
      continue;
    }
    // Where the collider is at the end of the step; the velocity relative
    // to it.
    const Vec3 w = h * c.velocity;
    if (c.Project(x - w, &sp, &sn, r)) {
      x = sp + w;
      const double vn = (v - c.velocity).dot(sn);
      if (vn < 0) v -= vn * sn;
    }
  }
}

}  // namespace

[[SYLVA_FLATTEN]] ContactOutcome RespondToContacts(const std::vector<Collider>& colliders, Vec3 a,
                                                   Vec3 va, Vec3& x, Vec3& v, double h,
                                                   double radius, MeshMemo* memo, double skin) {
  // The step as a path of constant acceleration from a, through x at its
  // end: p(tau) = a + tau u + tau^2 A / 2 for tau = t / h in [0, 1], with
  // u = h w (w the path's velocity at a) and A = h^2 acc, so that nothing
  // here divides by h until a bounce needs the velocity back. The
  // integrator's end velocity differs from the path's by a constant offset
  // (symplectic Euler's v is the path's velocity half a step later: offset
  // -h acc / 2), which the contacts leave alone. So a bounce reflects the
  // path's own velocity at the time of impact, and at restitution 1 keeps
  // the energy the integrator conserves.
  const Vec3 dv = v - va;  // what the forces give over the step (h acc)
  Vec3 A = h * dv;
  Vec3 u = (x - a) - 0.5 * A;
  // The common case first, a particle lying on a surface: one resting
  // contact at the start of the step and nothing more on its path. The
  // same operations as the loop below takes for it, without its
  // bookkeeping; anything else goes to the loop.
  {
    const Collider* none[2] = {nullptr, nullptr};
    Contact c0;
    bool grazed0 = false;
    const Collider* hit =
        FindContact(colliders, a, x, u, none, &c0, &grazed0, radius, 0, h, memo, skin);
    if (!hit) {
      if (!grazed0) return ContactOutcome::kNone;
      ProjectOut(colliders, x, v, radius, h);
      return ContactOutcome::kResponded;
    }
    const Vec3& n = c0.normal;
    if (c0.s == 0 && !hit->moving() && hit->response == Response::kBounce &&
        !(-u.dot(n) > std::max(0.0, -h * dv.dot(n)))) {
      const double en = v.dot(n);
      const double jn = std::max(0.0, -en);
      const Vec3 out = Friction(v - en * n, hit->friction * jn) + std::max(en, 0.0) * n;
      const Vec3 u1 = h * out;
      const Vec3 x1 = c0.point + u1;
      const Collider* resting0[2] = {hit, nullptr};
      Contact c1;
      bool grazed1 = false;
      if (!FindContact(colliders, c0.point, x1, u1, resting0, &c1, &grazed1, radius, 0, h, memo)) {
        x = x1;
        v = out;
        ProjectOut(colliders, x, v, radius, h);
        return ContactOutcome::kResponded;
      }
    }
  }
  Vec3 hOffset = h * v - (u + A);  // h times the offset
  double rem = 1;                  // of the step, as a fraction of h
  int contacts = 0;
  // Resting contacts of this step: their normals, points and colliders.
  Vec3 resting[2], restingPoint[2];
  const Collider* restingOn[2] = {nullptr, nullptr};
  int restingCount = 0;
  bool grazed = false;
  for (;;) {
    Contact best;
    const double e = 1 - rem;  // of the step, at a
    const Collider* hit = FindContact(colliders, a, x, u, restingOn, &best, &grazed, radius, e, h,
                                      memo, contacts == 0 ? skin : 0);
    if (!hit) break;
    const Vec3& n = best.normal;
    if (++contacts > kMaxContacts) [[unlikely]] {
      // Stopped at its last contact point, which is on a surface.
      x = a;
      v = Vec3::Zero();
      return ContactOutcome::kUnresolved;
    }
    // A moving collider: into its frame at the start of the step (h times
    // its velocity is w); back out below.
    const bool moving = hit->moving();
    const Vec3 w = moving ? Vec3(h * hit->velocity) : Vec3::Zero();
    if (moving) {
      a -= e * w;
      x -= w;
      u -= w;
      v -= hit->velocity;
    }
    // Time of impact along the path. On a flat face (plane, polygon, box,
    // triangle) it is exact: the root of the path against the face's
    // plane; on a sphere, the chord's fraction of the remaining time.
    double tau = best.s * rem;
    Vec3 point = best.point;
    if (hit->kind != Collider::Kind::kSphere && best.s > 0) {
      const double d0 = n.dot(a - point), d1 = n.dot(x - point);
      if (d0 > 0 && d1 < 0) {
        tau = FirstRoot(d0, n.dot(u), n.dot(A), rem);
        point = a + tau * u + (0.5 * tau * tau) * A;
        point -= n.dot(point - best.point) * n;  // on the face (its skin, if thin)
      }
    }
    const Vec3 uc = u + tau * A;  // h times the path's velocity at the contact
    const double r = rem - tau;
    if (hit->response == Response::kKill) [[unlikely]] {
      x = point + (e + tau) * w;
      v = (uc + hOffset) * (1 / h) + hit->velocity;
      return ContactOutcome::kKilled;
    }
    if (hit->response == Response::kStick) [[unlikely]] {
      x = point + (e + tau) * w;  // where it met the collider; it stays there
      v = Vec3::Zero();
      return ContactOutcome::kStuck;
    }
    const double un = uc.dot(n);
    // Speed a step gains toward the surface (times h): a slower approach is
    // resting or sliding contact, not a bounce.
    const double gained = std::max(0.0, -h * dv.dot(n));
    // A contact where a resting contact of this step left the particle
    // touches two surfaces at once: it rests on both (slides along their
    // crease). Past kInelasticContacts contacts in one step the particle is
    // caught in a crevice (an inelastic particle in a wedge would bounce
    // without end, nearer and nearer its crease): every further contact is
    // resting or sliding, which ends on the crease.
    const bool twoSurfaces = best.s == 0 && restingCount > 0;
    if (twoSurfaces && !moving) [[unlikely]] {
      point = CreasePoint(a, n, best.point, resting[restingCount - 1],
                          restingPoint[restingCount - 1], point);
    }
    if (-un > gained && !twoSurfaces && contacts <= kInelasticContacts) {
      // Bounce: reverse the normal speed times e; Coulomb friction takes at
      // most mu times the normal impulse from the tangential speed (all
      // scaled by h, which Friction is indifferent to).
      const double jn = (1 + hit->restitution) * -un;
      u = Friction(uc - un * n, hit->friction * jn) + hit->restitution * -un * n;
      x = point + r * u + (0.5 * r * r) * A;
      v = (u + r * A + hOffset) * (1 / h);
    } else {
      // Resting or sliding: the surface removes the inward normal velocity
      // the step would end with (its impulse is what the forces pressed
      // in), and friction removes up to mu times that from the tangential
      // one. Against earlier resting contacts of this step, the velocity
      // slides along their crease.
      const Vec3 end = v;
      const double en = end.dot(n);
      const double jn = std::max(0.0, -en);
      Vec3 out;
      if (restingCount == 0) {
        out = Friction(end - en * n, hit->friction * jn) + std::max(en, 0.0) * n;
      } else {
        out = Tangent(end, n, resting, restingCount);
        const Vec3 along = out - std::max(out.dot(n), 0.0) * n;
        out = Friction(along, hit->friction * jn) + (out - along);
      }
      if (restingCount < 2) {
        resting[restingCount] = n;
        restingPoint[restingCount] = point;
        restingOn[restingCount++] = hit;
      }
      u = h * out;
      x = point + r * u;
      v = out;
      A = Vec3::Zero();
      hOffset = Vec3::Zero();
    }
    if (moving) {  // back to the world
      point += (e + tau) * w;
      x += w;
      u += w;
      v += hit->velocity;
    }
    a = point;
    rem = r;
  }
  // Never leave a particle inside a solid.
  if (contacts == 0 && !grazed) return ContactOutcome::kNone;
  ProjectOut(colliders, x, v, radius, h);
  return ContactOutcome::kResponded;
}

}  // namespace sylva::particles
