#include "plant/chiba_environment.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "plant/point_grid.h"

namespace sylva::plant {
namespace {

using F3 = std::array<float, 3>;

void Normalize(float* v) {
  const float len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (len > 0)
    for (int i = 0; i < 3; ++i) v[i] /= len;
}

using DTri = std::array<std::array<double, 3>, 3>;

std::array<double, 3> Mid(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  std::array<double, 3> r{(a[0] + b[0]) * 0.5, (a[1] + b[1]) * 0.5, (a[2] + b[2]) * 0.5};
  const double mag = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
  if (mag != 0.0)
    for (double& x : r) x *= 1.0 / std::sqrt(mag);
  return r;
}

// The triangles of an octahedron subdivided (level - 1) times, each edge's
// midpoint pushed onto the unit sphere (J. Leech's `sphere`, which chiba
// uses).
std::vector<DTri> SubdividedOctahedron(int level) {
  const std::array<double, 3> xp{1, 0, 0}, xm{-1, 0, 0}, yp{0, 1, 0}, ym{0, -1, 0}, zp{0, 0, 1},
      zm{0, 0, -1};
  std::vector<DTri> tris = {{xp, zp, yp}, {yp, zp, xm}, {xm, zp, ym}, {ym, zp, xp},
                            {xp, yp, zm}, {yp, xm, zm}, {xm, ym, zm}, {ym, xp, zm}};
  for (DTri& t : tris) std::swap(t[0], t[2]);  // counter-clockwise, as the program
  for (int l = 1; l < level; ++l) {
    std::vector<DTri> next;
    next.reserve(tris.size() * 4);
    for (const DTri& t : tris) {
      const auto a = Mid(t[0], t[2]), b = Mid(t[0], t[1]), c = Mid(t[1], t[2]);
      next.push_back({t[0], b, a});
      next.push_back({b, t[1], c});
      next.push_back({a, b, c});
      next.push_back({a, c, t[2]});
    }
    tris = std::move(next);
  }
  return tris;
}

// The area where two discs of radii r1 >= r2, centres d apart, overlap.
float LensArea(float r1, float r2, float d) {
  if (d + r2 <= r1) return float(M_PI) * r2 * r2;
  const float x1 = (r1 * r1 + d * d - r2 * r2) / (2 * d);
  const float x2 = (r2 * r2 + d * d - r1 * r1) / (2 * d);
  const float y = std::sqrt(std::max(0.0f, r2 * r2 - x2 * x2));
  return r1 * r1 * std::acos(std::clamp(x1 / r1, -1.0f, 1.0f)) +
         r2 * r2 * std::acos(std::clamp(x2 / r2, -1.0f, 1.0f)) - y * d;
}

}  // namespace

std::vector<ChibaDef::Source> ChibaDirections(const ChibaDef& def) {
  std::vector<ChibaDef::Source> out;
  if (!def.sources.empty()) {
    float total = 0;
    for (const auto& s : def.sources) total += s.intensity;
    for (ChibaDef::Source s : def.sources) {
      s.intensity /= total;
      Normalize(s.dir);
      out.push_back(s);
    }
    return out;
  }
  // The closest higher 8 * 4^k samples; at least the octahedron's 8.
  const int level = std::max(
      1, int(std::ceil(std::log(double(std::max(def.samples, 1)) / 8.0) / std::log(4.0))) + 1);
  for (const DTri& t : SubdividedOctahedron(std::min(level, 8))) {
    ChibaDef::Source s;
    for (int c = 0; c < 3; ++c)
      s.dir[c] = (float(t[0][c]) + float(t[1][c]) + float(t[2][c])) / 3.0f;
    Normalize(s.dir);
    out.push_back(s);
  }
  if (def.cie) {
    // The CIE standard overcast sky, as chiba writes it: brighter toward the
    // zenith, nothing from below.
    float total = 0;
    for (auto& s : out) {
      if (s.dir[1] <= 0) {
        s.intensity = 0;
        continue;
      }
      const double c = s.dir[1] / std::sqrt(s.dir[0] * s.dir[0] + s.dir[1] * s.dir[1]);
      s.intensity = float((1 + c) / 3.0 * (8.6 * c + 0.123) / 0.203);
      total += s.intensity;
    }
    for (auto& s : out) s.intensity /= total;
    return out;
  }
  int up = 0;
  for (const auto& s : out) up += s.dir[1] >= 0;
  const int down = int(out.size()) - up;
  for (auto& s : out) {
    s.intensity = s.dir[1] >= 0 ? float(1.0 / up / (1.0 + def.lowerToUpper))
                                : float(def.lowerToUpper / down / (1.0 + def.lowerToUpper));
  }
  return out;
}

ChibaEnvironment::ChibaEnvironment(const ChibaDef& def, int coordinates)
    : def_(def), dirs_(ChibaDirections(def)), coordinates_(coordinates) {}

Status ChibaEnvironment::Answer(std::span<EnvQuery> queries) {
  if (coordinates_ < 3) return {};  // chiba: no position, no cluster
  struct Cluster {
    F3 pos;
    float radius, area;
    EnvQuery* q;
  };
  std::vector<Cluster> clusters;
  for (EnvQuery& q : queries) {
    if (q.params.size() != 1 && q.params.size() < 4) continue;  // 1 or 4 parameters
    Cluster c;
    for (int i = 0; i < 3; ++i) c.pos[size_t(i)] = float(q.position[i]);
    c.radius = float(q.params[0]) > 0 ? float(q.params[0]) : def_.radius;
    c.area = float(M_PI * c.radius * c.radius);
    c.q = &q;
    clusters.push_back(c);
  }
  const float red = def_.transmittance;
  const float beam = def_.estimateArea ? 1.0f : def_.beamRadius;
  const size_t n = clusters.size();
  float maxRadius = 0, maxCoord = 0;
  for (const Cluster& c : clusters) {
    maxRadius = std::max(maxRadius, std::abs(c.radius));
    for (float x : c.pos) maxCoord = std::max(maxCoord, std::abs(x));
  }
  // Farthest from a ray that a cluster can still shade it.
  const double reach = double(maxRadius) * (def_.estimateArea ? 2.0 : 1.0 + std::abs(beam)) +
                       1e-6 * double(maxCoord);
  std::vector<float> sum(n, 0.0f), bright(3 * n, 0.0f), across(3 * n, 0.0f);
  for (const ChibaDef::Source& s : dirs_) {
    if (s.intensity == 0) continue;
    // Only clusters near the ray across the light's direction can shade:
    // bucket the centres by their place in a plane across it.
    double u[3], v[3];
    const double d[3] = {s.dir[0], s.dir[1], s.dir[2]};
    const double a[3] = {std::abs(d[0]) < 0.9 ? 1.0 : 0.0, std::abs(d[0]) < 0.9 ? 0.0 : 1.0, 0.0};
    u[0] = a[1] * d[2] - a[2] * d[1];
    u[1] = a[2] * d[0] - a[0] * d[2];
    u[2] = a[0] * d[1] - a[1] * d[0];
    const double ul = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (double& x : u) x /= ul;
    v[0] = d[1] * u[2] - d[2] * u[1];
    v[1] = d[2] * u[0] - d[0] * u[2];
    v[2] = d[0] * u[1] - d[1] * u[0];
    for (size_t i = 0; i < n; ++i) {
      const auto& p = clusters[i].pos;
      across[3 * i] = float(u[0] * p[0] + u[1] * p[1] + u[2] * p[2]);
      across[3 * i + 1] = float(v[0] * p[0] + v[1] * p[1] + v[2] * p[2]);
    }
    const PointGrid grid(across, reach);
    for (uint32_t l = 0; l < n; ++l) {
      const Cluster& leaf = clusters[l];
      float reduction = 1;
      grid.ForNear(l, [&](uint32_t k) {
        const Cluster& other = clusters[k];
        float vec[3];
        for (int i = 0; i < 3; ++i) vec[i] = leaf.pos[size_t(i)] - other.pos[size_t(i)];
        const float aux = s.dir[0] * vec[0] + s.dir[1] * vec[1] + s.dir[2] * vec[2];
        const float vv = vec[0] * vec[0] + vec[1] * vec[1] + vec[2] * vec[2];
        if (def_.estimateArea) {
          if (aux > 0) return true;  // the other cluster is farther from the light
          const float d2 = vv - aux * aux;
          const float r = other.radius + leaf.radius;
          if (!(d2 < r * r)) return true;
          const float r1 = std::max(other.radius, leaf.radius);
          const float r2 = std::min(other.radius, leaf.radius);
          const float area = LensArea(r1, r2, std::sqrt(std::max(0.0f, d2)));
          if (area > 0) reduction *= 1 - (1 - red) * area / leaf.area;
          return true;
        }
        const float r = other.radius + leaf.radius * beam;
        float disc = aux * aux - vv + r * r;
        if (!(disc >= 0)) return true;
        disc = std::sqrt(disc);
        if (!(-aux + disc > 0)) return true;  // the ball is behind the start
        const float len = -aux - disc >= 0 ? 2 * disc : -aux + disc;
        if (len > 0)
          reduction *=
              float(std::pow(double(red), len / (2.0 * (other.radius + beam * leaf.radius))));
        return true;
      });
      const float got = s.intensity * reduction;
      sum[l] += got;
      for (int i = 0; i < 3; ++i) bright[3 * l + size_t(i)] += got * s.dir[i];
    }
  }
  for (size_t l = 0; l < n; ++l) {
    EnvQuery& q = *clusters[l].q;
    q.params[0] = sum[l];
    if (q.params.size() >= 4) {
      Normalize(&bright[3 * l]);
      for (int i = 0; i < 3; ++i) q.params[size_t(1 + i)] = bright[3 * l + size_t(i)];
    }
  }
  return {};
}

}  // namespace sylva::plant
