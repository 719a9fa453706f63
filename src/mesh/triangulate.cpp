// Ear clipping with a grid of reflex vertices.
//
// An ear is a convex vertex b (with neighbours a, c) whose triangle abc
// contains no other vertex of the polygon. Only reflex vertices can lie
// inside it (a convex vertex inside abc would make the polygon's boundary
// cross itself), so the test looks only at reflex vertices, and only at
// those in the grid cells the triangle's box covers. A clipped ear changes
// the angles of its two neighbours only: a reflex neighbour may become
// convex (never the other way round), so reflex vertices only leave the
// grid. The walk around the ring restarts at the previous vertex after a
// clip, as in Mapbox's earcut (which hashes vertices in z-order to the same
// end). Meisters, "Polygons have ears" (1975); Held, "FIST: fast
// industrial-strength triangulation of polygons" (Algorithmica 30, 2001).
#include "mesh/triangulate.h"

#include <algorithm>
#include <cmath>

namespace sylva::mesh {
namespace {

Vec3 AnyPerpendicular(const Vec3& t) {
  Vec3 a = std::abs(t.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  return (a - t * t.dot(a)).normalized();
}

double Cross(const Vec2& a, const Vec2& b, const Vec2& c) {
  return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}

// Reflex vertices bucketed in a uniform grid over the polygon's box.
class ReflexGrid {
 public:
  ReflexGrid(const std::vector<Vec2>& p, const std::vector<uint8_t>& reflex) : p_(p) {
    lo_ = hi_ = p[0];
    for (const Vec2& q : p) {
      lo_ = lo_.cwiseMin(q);
      hi_ = hi_.cwiseMax(q);
    }
    size_t count = 0;
    for (uint8_t r : reflex) count += r;
    // About one reflex vertex a cell, cells about square.
    const Vec2 ext = (hi_ - lo_).cwiseMax(Vec2(1e-300, 1e-300));
    const double aspect = std::clamp(ext.x() / ext.y(), 1e-6, 1e6);
    const double cells = std::max<double>(1, double(count));
    nx_ = std::clamp(int(std::sqrt(cells * aspect)), 1, 1 << 15);
    ny_ = std::clamp(int(cells / nx_), 1, 1 << 15);
    scale_ = Vec2(nx_ / ext.x(), ny_ / ext.y());
    cells_.resize(size_t(nx_) * size_t(ny_));
    slot_.assign(p.size(), 0);
    for (uint32_t i = 0; i < p.size(); ++i) {
      if (!reflex[i]) continue;
      auto& cell = cells_[Cell(p[i])];
      slot_[i] = uint32_t(cell.size());
      cell.push_back(i);
    }
  }

  // Takes vertex v out (it turned convex or was removed), so cells hold
  // only live reflex vertices.
  void Erase(uint32_t v) {
    auto& cell = cells_[Cell(p_[v])];
    const uint32_t last = cell.back();
    cell[slot_[v]] = last;
    slot_[last] = slot_[v];
    cell.pop_back();
  }

  // True when a reflex vertex other than a, b, c lies in triangle abc
  // (boundary included). `work` counts the vertices looked at.
  bool AnyInside(uint32_t a, uint32_t b, uint32_t c, uint64_t* work) const {
    const Vec2 &pa = p_[a], &pb = p_[b], &pc = p_[c];
    const Vec2 lo = pa.cwiseMin(pb).cwiseMin(pc), hi = pa.cwiseMax(pb).cwiseMax(pc);
    const int x0 = Coord(lo.x(), 0, nx_), x1 = Coord(hi.x(), 0, nx_), y0 = Coord(lo.y(), 1, ny_),
              y1 = Coord(hi.y(), 1, ny_);
    const Vec2* tri[3] = {&pa, &pb, &pc};
    for (int y = y0; y <= y1; ++y) {
      // Only the cells of this row that the triangle itself crosses: its x
      // extent within the row's band (vertices in the band, edges crossing
      // the band's two lines), so a long thin ear does not scan its box.
      const double yl = std::max(lo.y(), lo_.y() + y / scale_.y());
      const double yh = std::min(hi.y(), lo_.y() + (y + 1) / scale_.y());
      double xmin = hi.x(), xmax = lo.x();
      for (int e = 0; e < 3; ++e) {
        const Vec2& u = *tri[e];
        const Vec2& w = *tri[(e + 1) % 3];
        if (u.y() >= yl && u.y() <= yh) {
          xmin = std::min(xmin, u.x());
          xmax = std::max(xmax, u.x());
        }
        if (u.y() == w.y()) continue;
        for (double line : {yl, yh}) {
          const double t = (line - u.y()) / (w.y() - u.y());
          if (t < 0 || t > 1) continue;
          const double xx = u.x() + t * (w.x() - u.x());
          xmin = std::min(xmin, xx);
          xmax = std::max(xmax, xx);
        }
      }
      if (xmin > xmax) {  // rounding at a corner: fall back to the box
        xmin = lo.x();
        xmax = hi.x();
      }
      const int xa = std::max(x0, Coord(xmin, 0, nx_) - 1),
                xb = std::min(x1, Coord(xmax, 0, nx_) + 1);
      for (int x = xa; x <= xb; ++x) {
        for (uint32_t q : cells_[size_t(y) * size_t(nx_) + size_t(x)]) {
          ++*work;
          if (q == a || q == b || q == c) continue;
          const Vec2& pq = p_[q];
          if (pq.x() < lo.x() || pq.x() > hi.x() || pq.y() < lo.y() || pq.y() > hi.y()) continue;
          if (Cross(pa, pb, pq) >= 0 && Cross(pb, pc, pq) >= 0 && Cross(pc, pa, pq) >= 0)
            return true;
        }
      }
    }
    return false;
  }

 private:
  int Coord(double v, int axis, int cells) const {
    const double t = (v - lo_[axis]) * scale_[axis];
    return std::clamp(int(t), 0, cells - 1);
  }
  size_t Cell(const Vec2& q) const {
    return size_t(Coord(q.y(), 1, ny_)) * size_t(nx_) + size_t(Coord(q.x(), 0, nx_));
  }

  const std::vector<Vec2>& p_;
  Vec2 lo_, hi_, scale_;
  int nx_ = 1, ny_ = 1;
  std::vector<std::vector<uint32_t>> cells_;
  std::vector<uint32_t> slot_;  // a reflex vertex's place in its cell
};

}  // namespace

std::vector<uint32_t> TriangulatePolygon(const std::vector<Vec3>& in, Vec3* normalOut) {
  std::vector<uint32_t> tris;
  const size_t n = in.size();
  if (n < 3) return tris;
  // Newell's normal: robust for non-planar and concave outlines.
  Vec3 normal = Vec3::Zero();
  for (size_t i = 0; i < n; ++i) {
    const Vec3& a = in[i];
    const Vec3& b = in[(i + 1) % n];
    normal += Vec3((a.y() - b.y()) * (a.z() + b.z()), (a.z() - b.z()) * (a.x() + b.x()),
                   (a.x() - b.x()) * (a.y() + b.y()));
  }
  const double area2 = normal.norm();
  double scale = 0;
  for (const Vec3& v : in) scale = std::max(scale, (v - in[0]).norm());
  if (!(area2 > 1e-12 * scale * scale) || !std::isfinite(area2)) return tris;
  normal /= area2;
  if (normalOut) *normalOut = normal;
  // The plane's basis (e1, e2, normal) is right-handed, so the outline
  // projects counter-clockwise: convex corners have a positive cross product.
  const Vec3 e1 = AnyPerpendicular(normal), e2 = normal.cross(e1);
  std::vector<Vec2> p(n);
  for (size_t i = 0; i < n; ++i) p[i] = Vec2((in[i] - in[0]).dot(e1), (in[i] - in[0]).dot(e2));
  const double eps = 1e-12 * scale * scale;

  std::vector<uint32_t> prev(n), next(n);
  for (uint32_t i = 0; i < n; ++i) {
    prev[i] = uint32_t((i + n - 1) % n);
    next[i] = uint32_t((i + 1) % n);
  }
  std::vector<uint8_t> reflex(n);
  for (uint32_t i = 0; i < n; ++i) reflex[i] = Cross(p[prev[i]], p[i], p[next[i]]) <= eps;
  ReflexGrid grid(p, reflex);

  tris.reserve(3 * (n - 2));
  size_t left = n;
  uint64_t work = 0;
  // Work (ear tests and vertices looked at) is bounded: n (64 + sqrt n),
  // several times what spirals, stars and combs of 10^5 vertices need.
  const uint64_t budget = uint64_t(double(n) * (64 + std::sqrt(double(n)))) + 4096;
  // Candidates to test: every vertex at first, then the two neighbours of
  // each clipped ear (only their angles and triangles changed). An ear
  // blocked by a reflex vertex that later turns convex is found by a
  // refill: when the queue runs dry, every remaining vertex goes back in.
  std::vector<uint32_t> queue;
  std::vector<uint8_t> queued(n, 0), removed(n, 0);
  auto push = [&](uint32_t v) {
    if (!queued[v] && !removed[v]) {
      queued[v] = 1;
      queue.push_back(v);
    }
  };
  auto remove = [&](uint32_t v) {
    if (reflex[v]) grid.Erase(v);  // gone: never inside an ear again
    reflex[v] = 0;
    removed[v] = 1;
    next[prev[v]] = next[v];
    prev[next[v]] = prev[v];
    --left;
  };
  auto update = [&](uint32_t v) {  // a neighbour's angle changed
    if (reflex[v] && Cross(p[prev[v]], p[v], p[next[v]]) > eps) {
      reflex[v] = 0;
      grid.Erase(v);
    }
    push(v);
  };
  uint32_t any = 0;  // a vertex still in the ring
  for (uint32_t i = n; i-- > 0;) push(i);
  bool clippedSinceRefill = true;
  while (left > 3) {
    if (queue.empty()) {
      if (!clippedSinceRefill) {
        // Nothing is an ear: the rest is collinear or crosses itself. Drop
        // one flat vertex and go on, or give up.
        uint32_t v = any;
        bool dropped = false;
        for (size_t k = 0; k < left && !dropped; ++k, v = next[v]) {
          if (std::abs(Cross(p[prev[v]], p[v], p[next[v]])) <= eps) {
            const uint32_t a2 = prev[v], c2 = next[v];
            remove(v);
            update(a2);
            update(c2);
            any = a2;
            dropped = true;
          }
        }
        if (!dropped) break;
        continue;
      }
      clippedSinceRefill = false;
      uint32_t v = any;
      for (size_t k = 0; k < left; ++k, v = next[v]) push(v);
      work += left;
    }
    if (++work > budget) return {};  // pathological: give up, counted as degenerate
    const uint32_t ear = queue.back();
    queue.pop_back();
    queued[ear] = 0;
    if (removed[ear]) continue;
    const uint32_t a = prev[ear], c = next[ear];
    if (reflex[ear] || !(Cross(p[a], p[ear], p[c]) > eps) || grid.AnyInside(a, ear, c, &work))
      continue;
    tris.insert(tris.end(), {a, ear, c});
    remove(ear);
    update(a);
    update(c);
    any = a;
    clippedSinceRefill = true;
  }
  uint32_t ear = any;
  if (left == 3) {
    const uint32_t a = prev[ear], c = next[ear];
    if (Cross(p[a], p[ear], p[c]) > eps) tris.insert(tris.end(), {a, ear, c});
  }
  return tris;
}

}  // namespace sylva::mesh
