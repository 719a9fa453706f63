#include "mesh/tessellator.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <span>
#include <type_traits>

#include "core/assert.h"
#include "core/memory.h"
#include "core/parallel.h"
#include "mesh/pixel_widths.h"
#include "mesh/screen_detail.h"

namespace sylva::mesh {
namespace {

constexpr double kTwoPi = 6.283185307179586476925;
// Indices are 32-bit: a mesh keeps well under 2^32 vertices (a triangle
// adds at most 3).
constexpr uint64_t kMaxIndexedTriangles = (uint64_t(1) << 32) / 3 - 1;

Vec3f F(const Vec3& v) {
  return v.cast<float>();
}

Vec3 AnyPerpendicular(const Vec3& t) {
  Vec3 a = std::abs(t.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  return (a - t * t.dot(a)).normalized();
}

// Where a surface's vertex p lands (for bounds; the tessellation below
// places it with the same arithmetic up to rounding).
Vec3 SurfacePoint(const SurfaceInstance& si, const Vec3f& p) {
  const Vec3 sp = p.cast<double>().cwiseProduct(si.scale);
  return si.position + sp.x() * si.frame.left + sp.y() * si.frame.heading + sp.z() * si.frame.up;
}

int ClampSides(int s) {
  return std::clamp(s, 3, 256);
}

// Builds chains: runs of segments of one branch where each starts where the
// previous ended.
// Every chain's segments, in order, in one array (a chain is a span of it):
// one allocation for all, not one for each of a million twigs.
struct Chains {
  std::vector<uint32_t> start;     // chain c is segments [start[c], start[c + 1])
  std::vector<uint32_t> segments;  // indices into g.segments
  // 1: chain c is a loop (a branch of g.loops whose last segment ends where
  // its first began): its end is joined to its start, without caps.
  std::vector<uint8_t> loop;
  size_t size() const { return start.empty() ? 0 : start.size() - 1; }
  std::span<const uint32_t> operator[](size_t c) const {
    return {segments.data() + start[c], segments.data() + start[c + 1]};
  }
};

Chains BuildChains(const PlantGeometry& g) {
  // First each segment's chain (-1: zero length, no chain) and each chain's
  // length, then the segments in place: a chain's segments in their order.
  std::vector<int64_t> chainOf(g.segments.size(), -1);
  std::vector<uint32_t> lastOf, count;
  std::vector<int64_t> open(std::max<size_t>(g.branchCount, 1), -1);
  for (uint32_t k = 0; k < g.segments.size(); ++k) {
    const Segment& s = g.segments[k];
    const double len = (s.end - s.start).norm();
    if (!(len > 1e-12)) continue;
    if (s.branch >= open.size()) open.resize(s.branch + 1, -1);
    int64_t c = open[s.branch];
    if (c >= 0) {
      const Segment& last = g.segments[lastOf[size_t(c)]];
      if ((last.end - s.start).norm() <= 1e-9 * (1 + last.end.norm())) {
        chainOf[k] = c;
        lastOf[size_t(c)] = k;
        ++count[size_t(c)];
        continue;
      }
    }
    c = int64_t(lastOf.size());
    open[s.branch] = c;
    chainOf[k] = c;
    lastOf.push_back(k);
    count.push_back(1);
  }
  Chains chains;
  chains.start.assign(count.size() + 1, 0);
  for (size_t c = 0; c < count.size(); ++c) chains.start[c + 1] = chains.start[c] + count[c];
  chains.segments.resize(chains.start.back());
  std::vector<uint32_t> at(chains.start.begin(), chains.start.end() - 1);
  for (uint32_t k = 0; k < g.segments.size(); ++k) {
    if (chainOf[k] >= 0) chains.segments[at[size_t(chainOf[k])]++] = k;
  }
  chains.loop.assign(chains.size(), 0);
  if (!g.loops.empty()) {
    std::vector<uint8_t> closed(open.size(), 0);
    for (uint32_t b : g.loops)
      if (b < closed.size()) closed[b] = 1;
    for (size_t c = 0; c < chains.size(); ++c) {
      const auto chain = chains[c];
      const Segment& first = g.segments[chain.front()];
      const Segment& last = g.segments[chain.back()];
      chains.loop[c] = chain.size() >= 2 && closed[first.branch] &&
                       (last.end - first.start).norm() <= 1e-9 * (1 + first.start.norm());
    }
  }
  return chains;
}

// The ring frames of a chain: joints P, tangents T, rotation-minimizing
// normals N, radii R and the distance along the chain V.
struct ChainFrames {
  std::vector<Vec3> P, T, N;
  std::vector<double> R, V;
  std::vector<double> ppu;  // PlanChain's scratch: pixels per unit at each joint
};

// How much of a chain's frames to compute: the axis (P, R) for planning,
// with tangents and lengths (T, V) for a ribbon, everything for a tube.
enum class FramePart { kAxis, kTangents, kAll };

// A loop (Chains::loop) ends with the frame it starts with: the last joint
// is the first, its tangent the mean of the two segments' there, and the
// normals carried round are turned back by the angle they miss the first
// by, spread along the chain by length, so the last ring is the first.
void BuildFrames(const PlantGeometry& g, std::span<const uint32_t> chain, bool loop, ChainFrames& f,
                 FramePart part = FramePart::kAll) {
  const size_t m = chain.size();
  auto& P = f.P;
  auto& T = f.T;
  auto& N = f.N;
  auto& R = f.R;
  auto& V = f.V;
  P.resize(m + 1);
  R.resize(m + 1);
  P[0] = g.segments[chain[0]].start;
  for (size_t k = 0; k < m; ++k) P[k + 1] = g.segments[chain[k]].end;
  R[0] = g.segments[chain[0]].radiusStart;
  for (size_t k = 1; k < m; ++k) R[k] = g.segments[chain[k]].radiusStart;
  R[m] = g.segments[chain[m - 1]].radiusEnd;
  if (loop) {
    P[m] = P[0];
    R[m] = R[0];
  }
  double rmax = *std::max_element(R.begin(), R.end());
  for (double& r : R) r = std::max(r, rmax * 1e-3);
  if (part == FramePart::kAxis) return;
  T.resize(m + 1);
  V.resize(m + 1);
  auto dir = [&](size_t k) { return (P[k + 1] - P[k]).normalized(); };
  T[0] = dir(0);
  T[m] = dir(m - 1);
  if (loop) {
    const Vec3 t = dir(m - 1) + dir(0);
    T[0] = T[m] = t.norm() > 1e-9 ? Vec3(t.normalized()) : dir(0);
  }
  for (size_t k = 1; k < m; ++k) {
    Vec3 t = dir(k - 1) + dir(k);
    T[k] = t.norm() > 1e-9 ? t.normalized() : dir(k);
  }
  V[0] = 0;
  for (size_t k = 0; k < m; ++k) V[k + 1] = V[k] + (P[k + 1] - P[k]).norm();
  if (part == FramePart::kTangents) return;
  N.resize(m + 1);

  // First normal: the turtle's L, made perpendicular to the tangent.
  Vec3 n0 = g.segments[chain[0]].left;
  n0 -= T[0] * T[0].dot(n0);
  N[0] = n0.norm() > 1e-9 ? n0.normalized() : AnyPerpendicular(T[0]);
  // Double reflection (Wang et al. 2008).
  for (size_t k = 0; k < m; ++k) {
    const Vec3 v1 = P[k + 1] - P[k];
    const double c1 = v1.dot(v1);
    const Vec3 rL = N[k] - (2 / c1) * v1.dot(N[k]) * v1;
    const Vec3 tL = T[k] - (2 / c1) * v1.dot(T[k]) * v1;
    const Vec3 v2 = T[k + 1] - tL;
    const double c2 = v2.dot(v2);
    Vec3 n = c2 > 1e-18 ? Vec3(rL - (2 / c2) * v2.dot(rL) * v2) : rL;
    n -= T[k + 1] * T[k + 1].dot(n);
    N[k + 1] = n.norm() > 1e-9 ? n.normalized() : AnyPerpendicular(T[k + 1]);
  }
  if (loop && V[m] > 0) {
    // The carried normal comes back turned by `miss` about T[0].
    const double miss = std::atan2(T[0].dot(N[m].cross(N[0])), N[m].dot(N[0]));
    for (size_t k = 1; k < m; ++k) {
      const double a = miss * V[k] / V[m], c = std::cos(a), s = std::sin(a);
      N[k] = N[k] * c + T[k].cross(N[k]) * s;  // N[k] is perpendicular to T[k]
    }
    N[m] = N[0];
  }
}

// How one chain is drawn: its sides, the joints that get a ring (empty:
// all of them) and whether its ends are capped.
struct ChainPlan {
  int sides = 0;  // 0: not drawn (zero width, or culled)
  bool caps = true;
  bool ribbon = false;  // a camera-facing strip: 2 vertices a ring, no caps
  bool line = false;    // a ribbon kLinePixels wide with its coverage per vertex
  std::vector<uint32_t> joints;
  size_t rings(size_t segments) const { return joints.empty() ? segments + 1 : joints.size(); }
  size_t vertices(size_t segments) const {
    if (ribbon) return 2 * rings(segments);
    return (rings(segments) + (caps ? 2 : 0)) * size_t(sides + 1);
  }
  size_t triangles(size_t segments) const {
    if (ribbon) return 2 * (rings(segments) - 1);
    return 2 * size_t(sides) * (rings(segments) - 1) + (caps ? 2 * size_t(sides) : 0);
  }
};

// Screen-space plan of a chain (docs/lod.md): its level (ChainLevel: a
// coverage line, a ribbon or the sides) from the largest projected radius,
// with hysteresis against `last` when there is a history (in shadow-map
// texels and without history for a chain outside the view that may shade
// it: a tube then); a joint is dropped when the tube straight from the
// last kept joint to a later one passes within eps/2 pixels of it (axis
// and radius) and the colour does not change there; caps only on tubes
// at least a pixel wide.
void PlanChain(const PlantGeometry& g, std::span<const uint32_t> chain, ChainFrames& f,
               const ScreenView& view, bool shadowOnly, int16_t* last, uint16_t* lastRings,
               ChainPlan& plan) {
  const size_t m = chain.size();
  std::vector<double>& ppu = f.ppu;
  ppu.resize(m + 1);
  double rPx = 0;
  for (size_t k = 0; k <= m; ++k) {
    ppu[k] = shadowOnly ? view.shadowTexelsPerUnit : PixelsPerUnit(view, f.P[k]);
    rPx = std::max(rPx, f.R[k] * ppu[k]);
  }
  int level;
  if (shadowOnly) {
    // A ribbon faces the camera, not the light: never for a shadow caster.
    level = SidesForPixelRadius(rPx, view.eps);
  } else {
    level = last ? ChainLevelAfter(*last, rPx, view.eps, view.coverage)
                 : ChainLevel(rPx, view.eps, view.coverage);
    if (last) *last = int16_t(level);
  }
  plan.sides = std::max(level, 3);
  plan.caps = !(rPx < 1);
  plan.ribbon = level < 3;
  plan.line = level == 0;
  plan.joints.clear();
  if (m < 2) return;
  const double budget = view.eps / 2;
  constexpr size_t kMaxSpan = 64;
  auto fits = [&](size_t a, size_t b, double tolerance) {
    const Vec3 d = f.P[b] - f.P[a];
    const double len2 = d.dot(d);
    for (size_t i = a + 1; i < b; ++i) {
      if (g.segments[chain[i]].color != g.segments[chain[a]].color) return false;
      const Vec3 q = f.P[i] - f.P[a];
      const double t = len2 > 0 ? std::clamp(q.dot(d) / len2, 0.0, 1.0) : 0.0;
      const double off = (q - t * d).norm();
      const double dr = std::abs(f.R[i] - (f.R[a] + t * (f.R[b] - f.R[a])));
      if (!((off + dr) * ppu[i] <= tolerance)) return false;
    }
    return true;
  };
  // The joints kept at a tolerance (pixels): greedy, each span as long as fits.
  auto keep = [&](double tolerance, std::vector<uint32_t>& joints) {
    joints.assign(1, 0);
    size_t a = 0;
    while (a < m) {
      size_t b = a + 1;
      while (b < m && b + 1 - a <= kMaxSpan && fits(a, b + 1, tolerance)) ++b;
      joints.push_back(uint32_t(b));
      a = b;
    }
    return joints.size();
  };
  const size_t coarse = keep(budget, plan.joints);
  if (lastRings && !shadowOnly) {
    // Hysteresis for the rings (as for the level): fewer rings than last
    // frame only down to what a tolerance kHysteresis tighter keeps, and
    // between the two the fewest rings at least as many as last frame's,
    // by bisection on the tolerance. Never more error than eps / 2.
    const size_t lastCount = *lastRings;
    if (lastCount > coarse) {
      std::vector<uint32_t> fine, mid;
      const size_t most = keep(budget / (1 + kHysteresis), fine);
      if (lastCount < most) {
        double lo = 0, hi = 1;  // exponents of the tightening; count(lo) < lastCount <= count(hi)
        for (int k = 0; k < 8; ++k) {
          const double t = (lo + hi) / 2;
          if (keep(budget / std::pow(1 + kHysteresis, t), mid) >= lastCount) {
            hi = t;
            fine = mid;
          } else {
            lo = t;
          }
        }
      }
      plan.joints.swap(fine);
    }
    *lastRings = uint16_t(std::min<size_t>(plan.joints.size(), UINT16_MAX));
  }
  if (plan.joints.size() == m + 1) plan.joints.clear();  // every joint kept
}

// Writes the chain's vertices from out.positions[vbase] and its triangles
// from triangle tbase on; the arrays are already sized.
// A ribbon: at every kept joint two vertices, the axis point moved by the
// radius either way along the direction perpendicular to both the axis and
// the line of sight, with the normal turned toward the eye. A line is
// at least kLinePixels wide, its coverage the true width over the drawn one.
void EmitRibbon(const PlantGeometry& g, std::span<const uint32_t> chain, const ChainFrames& f,
                const ChainPlan& plan, const ScreenView& view, size_t vbase, size_t tbase,
                TriangleMesh& out) {
  const size_t m = chain.size();
  const size_t K = plan.rings(m);
  auto joint = [&](size_t r) { return plan.joints.empty() ? r : size_t(plan.joints[r]); };
  Vec3f* pos = out.positions.data() + vbase;
  Vec3f* nor = out.normals.data() + vbase;
  Vec2f* uv = out.uvs.data() + vbase;
  for (size_t r = 0; r < K; ++r) {
    const size_t k = joint(r);
    const Vec3 toEye = TowardEye(view, f.P[k]);
    Vec3 side = f.T[k].cross(toEye);
    side = side.norm() > 1e-9 ? Vec3(side.normalized()) : AnyPerpendicular(f.T[k]);
    Vec3 normal = toEye - f.T[k] * f.T[k].dot(toEye);
    normal = normal.norm() > 1e-9 ? Vec3(normal.normalized()) : f.T[k].cross(side);
    const float v = float(f.V[k]);
    double half = f.R[k];
    if (plan.line) {
      // Pixels per unit across the line's image: the side's image less its
      // part along the axis's image (PixelsPerUnit, the largest stretch,
      // overstates the width off the image centre).
      const Vec2 s = PixelOffset(view, f.P[k], side), t = PixelOffset(view, f.P[k], f.T[k]);
      const double tn = t.norm();
      const double ppu = tn > 1e-12 ? std::abs(s.x() * t.y() - s.y() * t.x()) / tn : s.norm();
      // Non-finite or zero (at the eye's plane, end-on): the tube's own width.
      const double drawn =
          ppu > 0 && std::isfinite(ppu) ? std::max(half, kLinePixels / 2 / ppu) : half;
      out.coverage[vbase + 2 * r] = out.coverage[vbase + 2 * r + 1] =
          float(std::clamp(half / drawn, 1e-3, 1.0));
      half = drawn;
    }
    for (int e = 0; e < 2; ++e) {
      *pos++ = F(f.P[k] + side * (e ? half : -half));
      *nor++ = F(normal);
      *uv++ = Vec2f(float(e), v);
    }
  }
  uint32_t* idx = out.indices.data() + 3 * tbase;
  uint16_t* mat = out.material.data() + tbase;
  for (size_t r = 0; r + 1 < K; ++r) {
    const uint16_t sm = g.segments[chain[joint(r)]].color;
    const uint32_t a = uint32_t(vbase + 2 * r), b = a + 1, c = a + 3, d = a + 2;
    idx[0] = a;
    idx[1] = b;
    idx[2] = c;
    idx[3] = a;
    idx[4] = c;
    idx[5] = d;
    idx += 6;
    *mat++ = sm;
    *mat++ = sm;
  }
}

void EmitChain(const PlantGeometry& g, std::span<const uint32_t> chain, const ChainFrames& f,
               const ChainPlan& plan, size_t vbase, size_t tbase, TriangleMesh& out) {
  const size_t m = chain.size();
  const int S = plan.sides;
  const size_t K = plan.rings(m);
  auto joint = [&](size_t r) { return plan.joints.empty() ? r : size_t(plan.joints[r]); };
  std::vector<double> cs(S + 1), sn(S + 1);
  for (int j = 0; j < S; ++j) {
    cs[j] = std::cos(kTwoPi * j / S);
    sn[j] = std::sin(kTwoPi * j / S);
  }
  cs[S] = cs[0];  // the seam vertex repeats the first exactly (only u differs)
  sn[S] = sn[0];
  const uint32_t base = uint32_t(vbase);
  const size_t ring = size_t(S + 1);
  Vec3f* pos = out.positions.data() + vbase;
  Vec3f* nor = out.normals.data() + vbase;
  Vec2f* uv = out.uvs.data() + vbase;
  uint32_t* idx = out.indices.data() + 3 * tbase;
  uint16_t* mat = out.material.data() + tbase;
  // Tube rings: S + 1 vertices each (the seam is duplicated for u = 1).
  // N and B are orthonormal, so the radial direction is already unit.
  for (size_t r = 0; r < K; ++r) {
    const size_t k = joint(r);
    const Vec3 B = f.T[k].cross(f.N[k]);
    const float v = float(f.V[k]);
    for (int j = 0; j <= S; ++j) {
      const Vec3 radial = f.N[k] * cs[j] + B * sn[j];
      *pos++ = F(f.P[k] + radial * f.R[k]);
      *nor++ = F(radial);
      *uv++ = Vec2f(float(j) / float(S), v);
    }
  }
  for (size_t r = 0; r + 1 < K; ++r) {
    const uint16_t sm = g.segments[chain[joint(r)]].color;
    for (int j = 0; j < S; ++j) {
      const uint32_t a = base + uint32_t(r * ring) + uint32_t(j), b = a + 1, d = a + uint32_t(ring),
                     c = d + 1;
      idx[0] = a;
      idx[1] = b;
      idx[2] = c;
      idx[3] = a;
      idx[4] = c;
      idx[5] = d;
      idx += 6;
      *mat++ = sm;
      *mat++ = sm;
    }
  }
  // Caps: a centre and a ring of S vertices with the axis as normal.
  auto cap = [&](size_t k, bool tip) {
    const Vec3 B = f.T[k].cross(f.N[k]);
    const Vec3f normal = F(tip ? f.T[k] : Vec3(-f.T[k]));
    const uint32_t center = uint32_t(pos - out.positions.data());
    *pos++ = F(f.P[k]);
    *nor++ = normal;
    *uv++ = Vec2f(0.5f, 0.5f);
    for (int j = 0; j < S; ++j) {
      *pos++ = F(f.P[k] + (f.N[k] * cs[j] + B * sn[j]) * f.R[k]);
      *nor++ = normal;
      *uv++ = Vec2f(float(0.5 + 0.5 * cs[j]), float(0.5 + 0.5 * sn[j]));
    }
    const uint16_t cm = g.segments[chain[tip ? m - 1 : 0]].color;
    for (int j = 0; j < S; ++j) {
      const uint32_t p = center + 1 + uint32_t(j), q = center + 1 + uint32_t((j + 1) % S);
      idx[0] = center;
      idx[1] = tip ? p : q;
      idx[2] = tip ? q : p;
      idx += 3;
      *mat++ = cm;
    }
  };
  if (plan.caps) {
    cap(0, false);
    cap(m, true);
  }
}

// A polygon or surface under a pixel across, drawn as a point: a square
// kLinePixels on a side facing the eye, whose coverage is the projected
// area of what it stands for (a fraction of the square; 0: not a point).
struct SubPixelPoint {
  Vec3 center = Vec3::Zero(), normal = Vec3::Zero(), toEye = Vec3::Zero();
  double halfSide = 0;  // world units
  float coverage = 0;
};

// Areas are |a . toEye| ppu^2 for each triangle's area vector a (the
// perspective at the centre, which is exact to first order for something
// under a pixel). Both faces of a closed surface count, so its coverage
// is up to twice its silhouette's.
SubPixelPoint PointOf(const Box& box, const Vec3& areaNormal, double areaPx2Sum,
                      const ScreenView& view) {
  SubPixelPoint p;
  if (!(box.lo.array() <= box.hi.array()).all()) return p;
  const Vec3 c = (box.lo + box.hi) / 2;
  const double ppu = PixelsPerUnit(view, c);
  if (!std::isfinite(ppu) || !((box.hi - box.lo).norm() * ppu < 1)) return p;
  p.center = c;
  p.toEye = TowardEye(view, c);
  if (!(p.toEye.norm() > 0.5)) return p;
  p.normal = areaNormal.norm() > 1e-30 ? Vec3(areaNormal.normalized()) : p.toEye;
  p.halfSide = kLinePixels / 2 / ppu;
  const double side2 = kLinePixels * kLinePixels;
  p.coverage = float(std::clamp(areaPx2Sum / side2, 1e-3, 1.0));
  return p;
}

SubPixelPoint PointOfPolygon(const Polygon& poly, const ScreenView& view) {
  if (poly.vertices.size() < 3) return {};
  Box box;
  Vec3 area = Vec3::Zero();  // Newell: twice the area vector
  for (size_t i = 0; i < poly.vertices.size(); ++i) {
    box.Add(poly.vertices[i]);
    area += poly.vertices[i].cross(poly.vertices[(i + 1) % poly.vertices.size()]);
  }
  area /= 2;
  const Vec3 c = (box.lo + box.hi) / 2;
  const double ppu = PixelsPerUnit(view, c);
  return PointOf(box, area, std::abs(area.dot(TowardEye(view, c))) * ppu * ppu, view);
}

SubPixelPoint PointOfSurface(const SurfaceInstance& si, const TriangleMesh& m,
                             const ScreenView& view) {
  Box box;
  std::vector<Vec3> placed(m.positions.size());
  for (size_t i = 0; i < placed.size(); ++i) {
    placed[i] = SurfacePoint(si, m.positions[i]);
    box.Add(placed[i]);
  }
  if (!(box.lo.array() <= box.hi.array()).all()) return {};
  const Vec3 c = (box.lo + box.hi) / 2;
  const double ppu = PixelsPerUnit(view, c);
  if (!std::isfinite(ppu) || !((box.hi - box.lo).norm() * ppu < 1)) return {};
  const Vec3 d = TowardEye(view, c);
  Vec3 sum = Vec3::Zero();
  double projected = 0;
  for (size_t t = 0; t < m.triangleCount(); ++t) {
    const Vec3& a = placed[m.indices[3 * t]];
    const Vec3& b = placed[m.indices[3 * t + 1]];
    const Vec3& e = placed[m.indices[3 * t + 2]];
    const Vec3 n = (b - a).cross(e - a) / 2;
    sum += n.dot(d) >= 0 ? n : Vec3(-n);
    projected += std::abs(n.dot(d));
  }
  return PointOf(box, sum, projected * ppu * ppu, view);
}

void EmitPoint(const SubPixelPoint& p, uint16_t color, TriangleMesh& out) {
  const Vec3 u = AnyPerpendicular(p.toEye) * p.halfSide;
  const Vec3 v = p.toEye.normalized().cross(u);
  out.coverage.resize(out.positions.size(), 1.0f);
  const uint32_t base = uint32_t(out.positions.size());
  const Vec3 corners[4] = {p.center - u - v, p.center + u - v, p.center + u + v, p.center - u + v};
  for (int k = 0; k < 4; ++k) {
    out.positions.push_back(F(corners[k]));
    out.normals.push_back(F(p.normal));
    out.uvs.push_back(Vec2f(float(k == 1 || k == 2), float(k >= 2)));
    out.coverage.push_back(p.coverage);
  }
  out.indices.insert(out.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
  out.material.push_back(color);
  out.material.push_back(color);
}

void TessellateSphere(const Sphere& s, int sides, TriangleMesh& out) {
  const int S = sides, Rn = std::max(2, S / 2);
  const uint32_t base = uint32_t(out.positions.size());
  for (int i = 0; i <= Rn; ++i) {
    const double th = kTwoPi * 0.5 * i / Rn;
    // Exact poles and seam, so coincident vertices are bit-identical.
    const double st = (i == 0 || i == Rn) ? 0.0 : std::sin(th);
    const double ct = i == 0 ? 1.0 : (i == Rn ? -1.0 : std::cos(th));
    for (int j = 0; j <= S; ++j) {
      const double ph = j == S ? 0.0 : kTwoPi * j / S;
      const Vec3 n(st * std::cos(ph), ct, st * std::sin(ph));
      out.positions.push_back(F(s.center + n * s.radius));
      out.normals.push_back(F(n));
      out.uvs.push_back(Vec2f(float(j) / float(S), float(i) / float(Rn)));
    }
  }
  const uint32_t W = uint32_t(S + 1);
  for (int i = 0; i < Rn; ++i) {
    for (int j = 0; j < S; ++j) {
      const uint32_t a = base + uint32_t(i) * W + uint32_t(j), b = a + 1, d = a + W, c = d + 1;
      if (i != Rn - 1) {
        out.indices.insert(out.indices.end(), {a, c, d});
        out.material.push_back(s.color);
      }
      if (i != 0) {
        out.indices.insert(out.indices.end(), {a, b, c});
        out.material.push_back(s.color);
      }
    }
  }
}

// Triangles of a contour tube: two a quad between consecutive rings.
size_t TubeTriangleCount(const ContourTube& t) {
  const size_t r = t.rings();
  return r >= 2 && t.ringSize >= 2 ? 2 * (r - 1) * (size_t(t.ringSize) - 1) : 0;
}

// A contour tube (a generalized cylinder with a cpfg contour): its points
// as they are, two triangles a quad, the normals the area-weighted sums of
// the quads around each point (shared across the seam of a closed
// contour). u runs 0..1 around, v 0..1 along.
void EmitTube(const ContourTube& t, TriangleMesh& out) {
  const size_t R = t.rings(), W = t.ringSize;
  if (TubeTriangleCount(t) == 0) return;
  const uint32_t base = uint32_t(out.positions.size());
  std::vector<Vec3> normal(R * W, Vec3::Zero());
  for (size_t i = 0; i + 1 < R; ++i) {
    for (size_t j = 0; j + 1 < W; ++j) {
      const size_t a = i * W + j, b = a + 1, d = a + W, c = d + 1;
      const Vec3& pa = t.points[a];
      const Vec3& pb = t.points[b];
      const Vec3& pc = t.points[c];
      const Vec3& pd = t.points[d];
      const Vec3 n1 = (pb - pa).cross(pc - pa), n2 = (pc - pa).cross(pd - pa);
      normal[a] += n1 + n2;
      normal[b] += n1;
      normal[c] += n1 + n2;
      normal[d] += n2;
      out.indices.insert(out.indices.end(),
                         {base + uint32_t(a), base + uint32_t(b), base + uint32_t(c),
                          base + uint32_t(a), base + uint32_t(c), base + uint32_t(d)});
      out.material.push_back(t.color);
      out.material.push_back(t.color);
    }
  }
  if (t.closed) {
    for (size_t i = 0; i < R; ++i) {
      const Vec3 n = normal[i * W] + normal[i * W + W - 1];
      normal[i * W] = normal[i * W + W - 1] = n;
    }
  }
  for (size_t i = 0; i < R; ++i) {
    for (size_t j = 0; j < W; ++j) {
      const Vec3& n = normal[i * W + j];
      const double len = n.norm();
      out.positions.push_back(F(t.points[i * W + j]));
      out.normals.push_back(len > 0 ? F(n / len) : Vec3f(0, 1, 0));
      out.uvs.push_back(Vec2f(float(j) / float(W - 1), float(i) / float(R - 1)));
    }
  }
}

// Tessellate's stream path (MeshStream): spheres, polygons and surfaces
// first (small; the totals must be known before the first piece), the
// triangles per material from the plans, then the chains in pieces of
// about stream.pieceVertices vertices, then the rest. The pieces are the
// mesh Tessellate would append to an empty mesh, cut between chains.
template <typename EmitChains, typename EmitRest>
Status StreamMesh(const MeshStream& stream, const PlantGeometry& g, const Chains& chains,
                  const std::vector<ChainPlan>& plans, const std::vector<size_t>& vOffset,
                  const std::vector<size_t>& tOffset, bool coverage, EmitChains& emitChains,
                  EmitRest& emitRest, TriangleMesh& piece) {
  SYLVA_ASSERT(piece.positions.empty() && piece.indices.empty());
  const size_t nc = chains.size();
  TriangleMesh rest;
  emitRest(rest);
  if (coverage) rest.coverage.resize(rest.positions.size(), 1.0f);
  std::vector<size_t> perMaterial;
  auto count = [&](uint16_t m, size_t n) {
    if (m >= perMaterial.size()) perMaterial.resize(size_t(m) + 1, 0);
    perMaterial[m] += n;
  };
  // As EmitChain and EmitRibbon assign materials: a span takes the colour
  // of the segment at its first ring, a cap that of its end segment.
  for (size_t c = 0; c < nc; ++c) {
    const ChainPlan& p = plans[c];
    if (!p.sides) continue;
    const std::span<const uint32_t> chain = chains[c];
    const size_t m = chain.size(), K = p.rings(m);
    const size_t perSpan = p.ribbon ? 2 : 2 * size_t(p.sides);
    for (size_t r = 0; r + 1 < K; ++r) {
      count(g.segments[chain[p.joints.empty() ? r : size_t(p.joints[r])]].color, perSpan);
    }
    if (!p.ribbon && p.caps) {
      count(g.segments[chain[0]].color, size_t(p.sides));
      count(g.segments[chain[m - 1]].color, size_t(p.sides));
    }
  }
  for (uint16_t m : rest.material) count(m, 1);
  const size_t chainVerts = vOffset[nc];
  if (Status s = stream.begin(chainVerts + rest.vertexCount(), perMaterial); !s.ok()) return s;
  for (size_t c0 = 0; c0 < nc;) {
    size_t c1 = c0 + 1;
    while (c1 < nc && vOffset[c1] - vOffset[c0] < stream.pieceVertices) ++c1;
    const size_t nv = vOffset[c1] - vOffset[c0], nt = tOffset[c1] - tOffset[c0];
    piece.positions.resize(nv);
    piece.normals.resize(nv);
    piece.uvs.resize(nv);
    piece.indices.resize(3 * nt);
    piece.material.resize(nt);
    if (coverage) piece.coverage.assign(nv, 1.0f);
    emitChains(c0, c1, 0, 0, piece);
    const uint32_t shift = uint32_t(vOffset[c0]);
    for (uint32_t& i : piece.indices) i += shift;
    if (nv > 0 || nt > 0) {
      if (Status s = stream.piece(piece, vOffset[c0]); !s.ok()) return s;
    }
    c0 = c1;
  }
  piece.Clear();
  if (rest.vertexCount() > 0 || !rest.indices.empty()) {
    for (uint32_t& i : rest.indices) i += uint32_t(chainVerts);
    if (Status s = stream.piece(rest, chainVerts); !s.ok()) return s;
  }
  return {};
}

}  // namespace

Status Tessellate(const PlantGeometry& g, const TessellateOptions& options, TriangleMesh& out,
                  TessellateStats* stats) {
  const ScreenView* view = options.view ? &*options.view : nullptr;
  if (g.widthInPixels) {
    // cpfg's pixel widths: world radii for this view (mesh/pixel_widths.h).
    if (!view && stats) {
      stats->warnings.push_back(
          "the widths are pixels (the view file's line style) and this mesh has no view: a "
          "pixel is drawn as 1/" +
          std::to_string(int(kNominalPixels)) + " of the plant's largest extent");
    }
    return Tessellate(ResolvePixelWidths(g, view), options, out, stats);
  }
  auto detailFor = [&](const Vec3& c, double r) {
    if (view) return SidesForPixelRadius(r * PixelsPerUnit(*view, c), view->eps);
    return ClampSides(options.detailFn ? options.detailFn(c, r).sides : options.detail.sides);
  };
  // Surfaces first: an unknown name fails before anything is appended.
  for (const SurfaceInstance& si : g.surfaces) {
    if (!options.surfaces || !options.surfaces->count(si.name)) {
      Diagnostic d;
      d.message = "unknown surface '" + si.name + "'";
      return d;
    }
  }
  const auto chains = BuildChains(g);
  // Culling: one hierarchy over the boxes of every chain (tube radius
  // included), sphere, polygon and surface, in that order, and one over
  // the same boxes swept away from the light (their shadows).
  std::vector<uint8_t> inView, inShadow;
  const size_t nc = chains.size(), ns = g.spheres.size(), np = g.polygons.size(),
               nf = g.surfaces.size(), nt = g.tubes.size();
  if (view) {
    std::vector<Box> boxes(nc + ns + np + nf + nt);
    ForRanges(options.pool, nc, BalancedGrain(options.pool, nc, 1024),
              [&](size_t begin, size_t end) {
                for (size_t c = begin; c < end; ++c) {
                  Box& b = boxes[c];
                  b.Add(g.segments[chains[c][0]].start);
                  double r = 0;
                  for (uint32_t k : chains[c]) {
                    const Segment& s = g.segments[k];
                    b.Add(s.end);
                    r = std::max({r, double(s.radiusStart), double(s.radiusEnd)});
                  }
                  b.Grow(r);
                }
              });
    for (size_t i = 0; i < ns; ++i) {
      boxes[nc + i].Add(g.spheres[i].center);
      boxes[nc + i].Grow(g.spheres[i].radius);
    }
    for (size_t i = 0; i < np; ++i)
      for (const Vec3& v : g.polygons[i].vertices) boxes[nc + ns + i].Add(v);
    for (size_t i = 0; i < nf; ++i) {
      const SurfaceInstance& si = g.surfaces[i];
      const TriangleMesh& sm = options.surfaces->at(si.name);
      Box& b = boxes[nc + ns + np + i];
      for (const Vec3f& p : sm.positions) b.Add(SurfacePoint(si, p));
      b.Grow(1e-6 * (1 + si.position.norm()));  // the tessellation's rounding
    }
    for (size_t i = 0; i < nt; ++i)
      for (const Vec3& v : g.tubes[i].points) boxes[nc + ns + np + nf + i].Add(v);
    const Frustum frustum = Frustum::FromViewProjection(view->viewProjection);
    // Everything inside (a framed plant): no hierarchy needed.
    auto visibleIn = [&](const std::vector<Box>& b) {
      Box all;
      bool bounded = true;
      for (const Box& x : b) {
        all.Add(x);
        bounded = bounded && x.lo.allFinite() && x.hi.allFinite();
      }
      if (bounded && frustum.Classify(all) == Frustum::Side::kInside) {
        return std::vector<uint8_t>(b.size(), 1);
      }
      return BoundingHierarchy(b).Visible(frustum);
    };
    inView = visibleIn(boxes);
    const Vec3 L = view->shadowFrom;
    if (L.y() > 1e-6) {
      // Only what is outside the view needs its shadow tested.
      std::vector<uint32_t> outside;
      std::vector<Box> swept;
      for (size_t i = 0; i < boxes.size(); ++i) {
        if (inView[i]) continue;
        const Box& b = boxes[i];
        Box s = b;
        if (b.lo.y() <= b.hi.y()) {
          const double t = std::max(0.0, (b.hi.y() - view->shadowPlaneY) / L.y());
          s.Add(b.lo - t * L);
          s.Add(b.hi - t * L);
        }
        outside.push_back(uint32_t(i));
        swept.push_back(s);
      }
      inShadow = inView;
      if (!outside.empty()) {
        const std::vector<uint8_t> shaded = visibleIn(swept);
        for (size_t k = 0; k < outside.size(); ++k) inShadow[outside[k]] = shaded[k];
      }
    }
  }
  auto shown = [&](size_t item) {
    return !view || !options.cull || inView[item] || (!inShadow.empty() && inShadow[item]);
  };
  // Outside the view, with shadows: detail for the shadow map, not the view.
  auto shadowOnly = [&](size_t item) { return view && !inShadow.empty() && !inView[item]; };
  // Choose every chain's detail first, so the arrays are sized exactly once.
  std::vector<ChainPlan> plans(nc);
  DetailHistory* history = view ? options.history : nullptr;
  if (history && (history->level.size() != nc || history->rings.size() != nc)) {
    history->level.assign(nc, -1);
    history->rings.assign(nc, 0);
  }
  auto plan = [&](size_t c, ChainFrames& frames) {
    const auto& chain = chains[c];
    double rmax = 0;
    for (uint32_t k : chain) rmax = std::max<double>(rmax, g.segments[k].radiusStart);
    if (!(rmax > 0) || !shown(c)) return;  // zero width, or culled: nothing to draw
    if (view) {
      BuildFrames(g, chain, chains.loop[c], frames, FramePart::kAxis);
      PlanChain(g, chain, frames, *view, shadowOnly(c), history ? &history->level[c] : nullptr,
                history ? &history->rings[c] : nullptr, plans[c]);
      if (chains.loop[c]) plans[c].caps = false;  // joined end to start
      return;
    }
    plans[c].caps = !chains.loop[c];
    Vec3 lo = g.segments[chain[0]].start, hi = lo;
    for (uint32_t k : chain) {
      lo = lo.cwiseMin(g.segments[k].end);
      hi = hi.cwiseMax(g.segments[k].end);
    }
    plans[c].sides = detailFor((lo + hi) / 2, (hi - lo).norm() / 2 + rmax);
  };
  // A detailFn is the caller's and may not be thread-safe: plan on one thread then.
  ThreadPool* pool = options.detailFn && !view ? nullptr : options.pool;
  ForRanges(pool, nc, BalancedGrain(pool, nc, 256), [&](size_t begin, size_t end) {
    ChainFrames frames;
    for (size_t c = begin; c < end; ++c) plan(c, frames);
  });
  // Where each chain's vertices and triangles start (fixed before any is
  // written, so the mesh is the same for any thread count).
  std::vector<size_t> vOffset(nc + 1, 0), tOffset(nc + 1, 0);
  for (size_t c = 0; c < nc; ++c) {
    const bool drawn = plans[c].sides > 0;
    vOffset[c + 1] = vOffset[c] + (drawn ? plans[c].vertices(chains[c].size()) : 0);
    tOffset[c + 1] = tOffset[c] + (drawn ? plans[c].triangles(chains[c].size()) : 0);
  }
  const size_t verts = vOffset[nc], tris = tOffset[nc];
  // Everything else counted too, before any memory is allocated: spheres
  // (S(2R - 2) triangles, R = max(2, S/2) rings), polygons (n - 2 at most),
  // surfaces (their mesh each).
  uint64_t total = tris;
  std::vector<int> sphereSides(ns, 0);
  for (size_t i = 0; i < ns; ++i) {
    const Sphere& s = g.spheres[i];
    if (!(s.radius > 0) || !shown(nc + i)) continue;
    sphereSides[i] = shadowOnly(nc + i)
                         ? SidesForPixelRadius(s.radius * view->shadowTexelsPerUnit, view->eps)
                         : detailFor(s.center, s.radius);
    const uint64_t S = uint64_t(sphereSides[i]), R = std::max<uint64_t>(2, S / 2);
    total += S * (2 * R - 2);
  }
  // Polygons and surfaces under a pixel across, with coverage: points.
  std::vector<SubPixelPoint> points(np + nf);
  if (view && view->coverage) {
    ForRanges(options.pool, np + nf, BalancedGrain(options.pool, np + nf, 256),
              [&](size_t begin, size_t end) {
                for (size_t i = begin; i < end; ++i) {
                  if (!shown(nc + ns + i) || shadowOnly(nc + ns + i)) continue;
                  if (i < np) {
                    points[i] = PointOfPolygon(g.polygons[i], *view);
                  } else {
                    const SurfaceInstance& si = g.surfaces[i - np];
                    points[i] = PointOfSurface(si, options.surfaces->at(si.name), *view);
                  }
                }
              });
  }
  for (size_t i = 0; i < np; ++i) {
    const Polygon& poly = g.polygons[i];
    if (!shown(nc + ns + i)) continue;
    if (points[i].coverage > 0) {
      total += 2;
    } else {
      total += poly.vertices.size() >= 3 ? poly.vertices.size() - 2 : 0;
    }
  }
  for (size_t i = 0; i < nf; ++i) {
    if (!shown(nc + ns + np + i)) continue;
    total +=
        points[np + i].coverage > 0 ? 2 : options.surfaces->at(g.surfaces[i].name).triangleCount();
  }
  for (size_t i = 0; i < nt; ++i) {
    if (shown(nc + ns + np + nf + i)) total += TubeTriangleCount(g.tubes[i]);
  }
  const uint64_t limit = std::min<uint64_t>(options.maxTriangles, kMaxIndexedTriangles);
  if (out.triangleCount() + total > limit) {
    Diagnostic d;
    d.kind = ErrorKind::kRuntime;
    d.message =
        "the mesh would have " + std::to_string(out.triangleCount() + total) +
        " triangles, more than the limit of " + std::to_string(limit) +
        "; lower the derivation length (-n) or the sides (--sides), or raise --max-triangles";
    return d;
  }
  // Chains [first, last) written into `dst` (in parallel), chain `first`'s
  // vertices at vAt and its triangles at tAt, the others after it.
  auto emitChains = [&](size_t first, size_t last, size_t vAt, size_t tAt, TriangleMesh& dst) {
    const size_t vShift = vOffset[first] - vAt, tShift = tOffset[first] - tAt;
    ForRanges(options.pool, last - first, BalancedGrain(options.pool, last - first, 256),
              [&](size_t begin, size_t end) {
                ChainFrames frames;
                for (size_t c = first + begin; c < first + end; ++c) {
                  if (!plans[c].sides) continue;
                  BuildFrames(g, chains[c], chains.loop[c], frames,
                              plans[c].ribbon ? FramePart::kTangents : FramePart::kAll);
                  if (plans[c].ribbon) {
                    EmitRibbon(g, chains[c], frames, plans[c], *view, vOffset[c] - vShift,
                               tOffset[c] - tShift, dst);
                    continue;
                  }
                  EmitChain(g, chains[c], frames, plans[c], vOffset[c] - vShift,
                            tOffset[c] - tShift, dst);
                }
              });
  };
  // Spheres, polygons, surfaces and contour tubes, appended to `dst`.
  auto emitRest = [&](TriangleMesh& dst) {
    for (size_t i = 0; i < ns; ++i) {
      if (sphereSides[i]) TessellateSphere(g.spheres[i], sphereSides[i], dst);
    }
    for (size_t i = 0; i < np; ++i) {
      const Polygon& poly = g.polygons[i];
      if (!shown(nc + ns + i)) continue;
      if (points[i].coverage > 0) {
        EmitPoint(points[i], poly.color, dst);
        continue;
      }
      Vec3 normal;
      std::vector<uint32_t> polyTris = TriangulatePolygon(poly.vertices, &normal);
      if (polyTris.empty()) {
        if (stats) {
          ++stats->polygonsSkipped;
          stats->warnings.push_back(
              "polygon at module " + std::to_string(poly.module + 1) +
              " is degenerate, crosses itself or is too complex to triangulate; skipped");
        }
        continue;
      }
      const Vec3 e1 = AnyPerpendicular(normal), e2 = normal.cross(e1);
      Vec2 lo(1e300, 1e300), hi(-1e300, -1e300);
      for (const Vec3& v : poly.vertices) {
        Vec2 q(v.dot(e1), v.dot(e2));
        lo = lo.cwiseMin(q);
        hi = hi.cwiseMax(q);
      }
      const Vec2 ext = (hi - lo).cwiseMax(Vec2(1e-12, 1e-12));
      const uint32_t base = uint32_t(dst.positions.size());
      for (const Vec3& v : poly.vertices) {
        dst.positions.push_back(F(v));
        dst.normals.push_back(F(normal));
        Vec2 q((v.dot(e1) - lo.x()) / ext.x(), (v.dot(e2) - lo.y()) / ext.y());
        dst.uvs.push_back(q.cast<float>());
      }
      for (size_t t = 0; t < polyTris.size(); t += 3) {
        dst.indices.insert(dst.indices.end(),
                           {base + polyTris[t], base + polyTris[t + 1], base + polyTris[t + 2]});
        dst.material.push_back(poly.color);
      }
    }
    for (size_t f = 0; f < nf; ++f) {
      if (!shown(nc + ns + np + f)) continue;
      const SurfaceInstance& si = g.surfaces[f];
      if (points[np + f].coverage > 0) {
        EmitPoint(points[np + f], si.color, dst);
        continue;
      }
      const TriangleMesh& s = options.surfaces->at(si.name);
      const uint32_t base = uint32_t(dst.positions.size());
      // ~name(s) scales all axes alike (the common case, computed as it
      // always was); ~name(sx,sy,sz) each its own, normals by the inverse.
      const Vec3 sc = si.scale;
      const bool uniform = sc.x() == sc.y() && sc.y() == sc.z();
      std::optional<Vec3> inverseScale;
      if (!uniform && sc.x() != 0 && sc.y() != 0 && sc.z() != 0) inverseScale = sc.cwiseInverse();
      for (size_t i = 0; i < s.positions.size(); ++i) {
        const Vec3 p = s.positions[i].cast<double>(), n = s.normals[i].cast<double>();
        const Vec3 sp = uniform ? p : Vec3(p.cwiseProduct(sc));
        const Vec3 local =
            sp.x() * si.frame.left + sp.y() * si.frame.heading + sp.z() * si.frame.up;
        const Vec3 wp = si.position + (uniform ? sc.x() * local : local);
        const Vec3 sn = inverseScale ? Vec3(n.cwiseProduct(*inverseScale)) : n;
        const Vec3 wn = sn.x() * si.frame.left + sn.y() * si.frame.heading + sn.z() * si.frame.up;
        dst.positions.push_back(F(wp));
        dst.normals.push_back(F(wn.normalized()));
        dst.uvs.push_back(s.uvs[i]);
      }
      for (uint32_t i : s.indices) dst.indices.push_back(base + i);
      for (size_t t = 0; t < s.triangleCount(); ++t) dst.material.push_back(si.color);
    }
    for (size_t i = 0; i < nt; ++i) {
      if (shown(nc + ns + np + nf + i)) EmitTube(g.tubes[i], dst);
    }
  };
  if (stats) {
    stats->chains += chains.size();
    for (size_t i = 0; i < inView.size(); ++i) stats->culled += shown(i) ? 0 : 1;
  }
  if (options.stream)
    return StreamMesh(*options.stream, g, chains, plans, vOffset, tOffset, view && view->coverage,
                      emitChains, emitRest, out);
  auto grow = [](auto& v, size_t extra) {
    using T = typename std::decay_t<decltype(v)>::value_type;
    const size_t want = v.size() + extra;
    if (v.capacity() >= want) return;
    std::decay_t<decltype(v)> fresh;
    fresh.reserve(want);
    AdviseHugePages(fresh.data(), want * sizeof(T));
    fresh.insert(fresh.end(), v.begin(), v.end());
    v.swap(fresh);
  };
  grow(out.positions, verts);
  grow(out.normals, verts);
  grow(out.uvs, verts);
  grow(out.indices, 3 * tris);
  grow(out.material, tris);
  const size_t vbase = out.positions.size(), tbase = out.material.size();
  out.positions.resize(vbase + verts);
  out.normals.resize(vbase + verts);
  out.uvs.resize(vbase + verts);
  out.indices.resize(3 * (tbase + tris));
  out.material.resize(tbase + tris);
  if (view && view->coverage) out.coverage.resize(vbase + verts, 1.0f);
  emitChains(0, nc, vbase, tbase, out);
  emitRest(out);
  if (!out.coverage.empty()) out.coverage.resize(out.positions.size(), 1.0f);
  return {};
}

Box TessellatedBounds(const PlantGeometry& g,
                      const std::unordered_map<std::string, TriangleMesh>* surfaces) {
  Box box;
  // A tube is the hull of its end discs: a disc of radius r across the
  // unit axis t reaches r sqrt(1 - t_k^2) along axis k. Radii in pixels
  // (widthInPixels) are nothing in world units: the axis alone.
  const float radiusUnit = g.widthInPixels ? 0.0f : 1.0f;
  for (const Segment& s : g.segments) {
    const Vec3 d = s.end - s.start;
    const double len = d.norm();
    if (!(len > 1e-12)) continue;
    const Vec3 t = d / len;
    const Vec3 reach = (Vec3::Ones() - t.cwiseProduct(t)).cwiseMax(0.0).cwiseSqrt();
    box.Add(s.start - reach * (s.radiusStart * radiusUnit));
    box.Add(s.start + reach * (s.radiusStart * radiusUnit));
    box.Add(s.end - reach * (s.radiusEnd * radiusUnit));
    box.Add(s.end + reach * (s.radiusEnd * radiusUnit));
  }
  for (const Sphere& s : g.spheres) {
    Box b;
    b.Add(s.center);
    b.Grow(s.radius);
    box.Add(b);
  }
  for (const Polygon& poly : g.polygons)
    for (const Vec3& v : poly.vertices) box.Add(v);
  for (const SurfaceInstance& si : g.surfaces) {
    auto it = surfaces ? surfaces->find(si.name) : decltype(surfaces->end()){};
    if (!surfaces || it == surfaces->end()) continue;
    for (const Vec3f& p : it->second.positions) {
      box.Add(SurfacePoint(si, p));
    }
  }
  for (const ContourTube& t : g.tubes)
    for (const Vec3& v : t.points) box.Add(v);
  return box;
}

}  // namespace sylva::mesh
