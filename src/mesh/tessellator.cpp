#include "mesh/tessellator.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <type_traits>

#include "core/memory.h"

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

int ClampSides(int s) {
  return std::clamp(s, 3, 256);
}

// Builds chains: runs of segments of one branch where each starts where the
// previous ended.
std::vector<std::vector<uint32_t>> BuildChains(const PlantGeometry& g) {
  std::vector<std::vector<uint32_t>> chains;
  std::vector<int64_t> open(std::max<size_t>(g.branchCount, 1), -1);
  for (uint32_t k = 0; k < g.segments.size(); ++k) {
    const Segment& s = g.segments[k];
    const double len = (s.end - s.start).norm();
    if (!(len > 1e-12)) continue;
    if (s.branch >= open.size()) open.resize(s.branch + 1, -1);
    int64_t c = open[s.branch];
    if (c >= 0) {
      const Segment& last = g.segments[chains[size_t(c)].back()];
      if ((last.end - s.start).norm() <= 1e-9 * (1 + last.end.norm())) {
        chains[size_t(c)].push_back(k);
        continue;
      }
    }
    open[s.branch] = int64_t(chains.size());
    chains.push_back({k});
  }
  return chains;
}

void TessellateChain(const PlantGeometry& g, const std::vector<uint32_t>& chain, int sides,
                     TriangleMesh& out) {
  const size_t m = chain.size();
  std::vector<Vec3> P(m + 1), T(m + 1), N(m + 1);
  std::vector<double> R(m + 1), V(m + 1);
  P[0] = g.segments[chain[0]].start;
  for (size_t k = 0; k < m; ++k) P[k + 1] = g.segments[chain[k]].end;
  auto dir = [&](size_t k) { return (P[k + 1] - P[k]).normalized(); };
  T[0] = dir(0);
  T[m] = dir(m - 1);
  for (size_t k = 1; k < m; ++k) {
    Vec3 t = dir(k - 1) + dir(k);
    T[k] = t.norm() > 1e-9 ? t.normalized() : dir(k);
  }
  R[0] = g.segments[chain[0]].radiusStart;
  for (size_t k = 1; k < m; ++k) R[k] = g.segments[chain[k]].radiusStart;
  R[m] = g.segments[chain[m - 1]].radiusEnd;
  double rmax = *std::max_element(R.begin(), R.end());
  for (double& r : R) r = std::max(r, rmax * 1e-3);
  V[0] = 0;
  for (size_t k = 0; k < m; ++k) V[k + 1] = V[k] + (P[k + 1] - P[k]).norm();

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

  const int S = sides;
  std::vector<double> cs(S + 1), sn(S + 1);
  for (int j = 0; j < S; ++j) {
    cs[j] = std::cos(kTwoPi * j / S);
    sn[j] = std::sin(kTwoPi * j / S);
  }
  cs[S] = cs[0];  // the seam vertex repeats the first exactly (only u differs)
  sn[S] = sn[0];
  // Sizes are known: resize once and write through pointers.
  const uint32_t base = uint32_t(out.positions.size());
  const size_t ring = size_t(S + 1);
  const size_t nVerts = (m + 1) * ring + 2 * ring;
  const size_t nTris = TubeTriangles(m, S);
  const size_t triBase = out.material.size();
  out.positions.resize(base + nVerts);
  out.normals.resize(base + nVerts);
  out.uvs.resize(base + nVerts);
  out.indices.resize(3 * (triBase + nTris));
  out.material.resize(triBase + nTris);
  Vec3f* pos = out.positions.data() + base;
  Vec3f* nor = out.normals.data() + base;
  Vec2f* uv = out.uvs.data() + base;
  uint32_t* idx = out.indices.data() + 3 * triBase;
  uint16_t* mat = out.material.data() + triBase;
  // Tube rings: S + 1 vertices each (the seam is duplicated for u = 1).
  // N and B are orthonormal, so the radial direction is already unit.
  for (size_t k = 0; k <= m; ++k) {
    const Vec3 B = T[k].cross(N[k]);
    const float v = float(V[k]);
    for (int j = 0; j <= S; ++j) {
      const Vec3 radial = N[k] * cs[j] + B * sn[j];
      *pos++ = F(P[k] + radial * R[k]);
      *nor++ = F(radial);
      *uv++ = Vec2f(float(j) / float(S), v);
    }
  }
  for (size_t k = 0; k < m; ++k) {
    const uint16_t sm = g.segments[chain[k]].color;
    for (int j = 0; j < S; ++j) {
      const uint32_t a = base + uint32_t(k * ring) + uint32_t(j), b = a + 1, d = a + uint32_t(ring),
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
    const Vec3 B = T[k].cross(N[k]);
    const Vec3f normal = F(tip ? T[k] : Vec3(-T[k]));
    const uint32_t center = uint32_t(pos - out.positions.data());
    *pos++ = F(P[k]);
    *nor++ = normal;
    *uv++ = Vec2f(0.5f, 0.5f);
    for (int j = 0; j < S; ++j) {
      *pos++ = F(P[k] + (N[k] * cs[j] + B * sn[j]) * R[k]);
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
  cap(0, false);
  cap(m, true);
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

}  // namespace

Status Tessellate(const PlantGeometry& g, const TessellateOptions& options, TriangleMesh& out,
                  TessellateStats* stats) {
  auto detailFor = [&](const Vec3& c, double r) {
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
  // Choose every chain's detail first, so the arrays are sized exactly once.
  std::vector<int> chainSides(chains.size(), 0);
  size_t verts = 0, tris = 0;
  for (size_t c = 0; c < chains.size(); ++c) {
    const auto& chain = chains[c];
    Vec3 lo = g.segments[chain[0]].start, hi = lo;
    double rmax = 0;
    for (uint32_t k : chain) {
      lo = lo.cwiseMin(g.segments[k].end);
      hi = hi.cwiseMax(g.segments[k].end);
      rmax = std::max<double>(rmax, g.segments[k].radiusStart);
    }
    if (!(rmax > 0)) continue;  // zero width: nothing to draw
    const int S = detailFor((lo + hi) / 2, (hi - lo).norm() / 2 + rmax);
    chainSides[c] = S;
    verts += (chain.size() + 1) * size_t(S + 1) + 2 * size_t(S + 1);
    tris += TubeTriangles(chain.size(), S);
  }
  // Everything else counted too, before any memory is allocated: spheres
  // (S(2R - 2) triangles, R = max(2, S/2) rings), polygons (n - 2 at most),
  // surfaces (their mesh each).
  uint64_t total = tris;
  for (const Sphere& s : g.spheres) {
    if (!(s.radius > 0)) continue;
    const uint64_t S = uint64_t(detailFor(s.center, s.radius)), R = std::max<uint64_t>(2, S / 2);
    total += S * (2 * R - 2);
  }
  for (const Polygon& poly : g.polygons)
    total += poly.vertices.size() >= 3 ? poly.vertices.size() - 2 : 0;
  for (const SurfaceInstance& si : g.surfaces)
    total += options.surfaces->at(si.name).triangleCount();
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
  for (size_t c = 0; c < chains.size(); ++c) {
    if (chainSides[c]) TessellateChain(g, chains[c], chainSides[c], out);
  }
  for (const Sphere& s : g.spheres) {
    if (s.radius > 0) TessellateSphere(s, detailFor(s.center, s.radius), out);
  }
  for (const Polygon& poly : g.polygons) {
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
    const uint32_t base = uint32_t(out.positions.size());
    for (const Vec3& v : poly.vertices) {
      out.positions.push_back(F(v));
      out.normals.push_back(F(normal));
      Vec2 q((v.dot(e1) - lo.x()) / ext.x(), (v.dot(e2) - lo.y()) / ext.y());
      out.uvs.push_back(q.cast<float>());
    }
    for (size_t t = 0; t < polyTris.size(); t += 3) {
      out.indices.insert(out.indices.end(),
                         {base + polyTris[t], base + polyTris[t + 1], base + polyTris[t + 2]});
      out.material.push_back(poly.color);
    }
  }
  for (const SurfaceInstance& si : g.surfaces) {
    const TriangleMesh& s = options.surfaces->at(si.name);
    const uint32_t base = uint32_t(out.positions.size());
    // ~name(s) scales all axes alike (the common case, computed as it
    // always was); ~name(sx,sy,sz) each its own, normals by the inverse.
    const Vec3 sc = si.scale;
    const bool uniform = sc.x() == sc.y() && sc.y() == sc.z();
    std::optional<Vec3> inverseScale;
    if (!uniform && sc.x() != 0 && sc.y() != 0 && sc.z() != 0) inverseScale = sc.cwiseInverse();
    for (size_t i = 0; i < s.positions.size(); ++i) {
      const Vec3 p = s.positions[i].cast<double>(), n = s.normals[i].cast<double>();
      const Vec3 sp = uniform ? p : Vec3(p.cwiseProduct(sc));
      const Vec3 local = sp.x() * si.frame.left + sp.y() * si.frame.heading + sp.z() * si.frame.up;
      const Vec3 wp = si.position + (uniform ? sc.x() * local : local);
      const Vec3 sn = inverseScale ? Vec3(n.cwiseProduct(*inverseScale)) : n;
      const Vec3 wn = sn.x() * si.frame.left + sn.y() * si.frame.heading + sn.z() * si.frame.up;
      out.positions.push_back(F(wp));
      out.normals.push_back(F(wn.normalized()));
      out.uvs.push_back(s.uvs[i]);
    }
    for (uint32_t i : s.indices) out.indices.push_back(base + i);
    for (size_t t = 0; t < s.triangleCount(); ++t) out.material.push_back(si.color);
  }
  if (stats) stats->chains += chains.size();
  return {};
}

}  // namespace sylva::mesh
