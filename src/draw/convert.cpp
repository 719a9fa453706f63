#include "draw/convert.h"

#include <string>

namespace sylva::draw {
namespace {

Diagnostic Bad(std::string message) {
  Diagnostic d;
  d.message = "draw conversion: " + std::move(message);
  return d;
}

// An optional per-point array has no entries or one per point.
Status Matches(const char* what, size_t n, size_t count, const char* of = "positions") {
  if (n == 0 || n == count) return {};
  return Bad(std::string(what) + " has " + std::to_string(n) + " entries for " +
             std::to_string(count) + " " + of + " (one each, or none)");
}

// The sprites' sizes, colours and alphas, once positions are filled.
Expected<Sprites> Styled(Sprites s, const PointStyle& style, std::span<const Vec3f> colors,
                         std::span<const float> radii) {
  const size_t n = s.positions.size();
  if (Status st = Matches("colors", colors.size(), n); !st.ok()) return st.error();
  if (Status st = Matches("radii", radii.size(), n); !st.ok()) return st.error();
  s.name = style.name;
  s.blend = style.blend;
  if (radii.empty()) {
    s.sizes.assign(n, style.size);
  } else {
    s.sizes.resize(n);
    for (size_t i = 0; i < n; ++i) s.sizes[i] = 2 * radii[i];
  }
  if (colors.empty()) {
    s.colors.assign(n, style.color);
  } else {
    s.colors.assign(colors.begin(), colors.end());
  }
  if (style.alpha != 1) s.alphas.assign(n, style.alpha);
  return s;
}

}  // namespace

Expected<Sprites> PointSprites(std::span<const Vec3> positions, const PointStyle& style,
                               std::span<const Vec3f> colors, std::span<const float> radii) {
  Sprites s;
  s.positions.resize(positions.size());
  for (size_t i = 0; i < positions.size(); ++i) s.positions[i] = positions[i].cast<float>();
  return Styled(std::move(s), style, colors, radii);
}

Expected<Sprites> PointSprites(std::span<const float> x, std::span<const float> y,
                               std::span<const float> z, const PointStyle& style,
                               std::span<const Vec3f> colors, std::span<const float> radii) {
  if (y.size() != x.size() || z.size() != x.size())
    return Bad("coordinate arrays of " + std::to_string(x.size()) + ", " +
               std::to_string(y.size()) + " and " + std::to_string(z.size()) +
               " entries (x, y, z must agree)");
  Sprites s;
  s.positions.resize(x.size());
  for (size_t i = 0; i < x.size(); ++i) s.positions[i] = Vec3f(x[i], y[i], z[i]);
  return Styled(std::move(s), style, colors, radii);
}

Mat4f Facing(const Vec3& at, const Vec3& forward, double scale) {
  Vec3 f = forward.norm() > 1e-9 ? forward.normalized() : Vec3::UnitZ();
  Vec3 side = Vec3::UnitY().cross(f);
  if (side.norm() < 1e-6) side = Vec3::UnitX();
  side.normalize();
  const Vec3 up = f.cross(side);
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.block<3, 1>(0, 0) = side * scale;
  m.block<3, 1>(0, 1) = up * scale;
  m.block<3, 1>(0, 2) = f * scale;
  m.block<3, 1>(0, 3) = at;
  return m.cast<float>();
}

Expected<std::vector<Instance>> FacingInstances(std::span<const Vec3> positions,
                                                std::span<const Vec3> velocities, double scale,
                                                const Vec3f& tint) {
  if (velocities.size() != positions.size())
    return Bad("velocities has " + std::to_string(velocities.size()) + " entries for " +
               std::to_string(positions.size()) + " positions");
  std::vector<Instance> out(positions.size());
  for (size_t i = 0; i < positions.size(); ++i)
    out[i] = {Facing(positions[i], velocities[i], scale), tint};
  return out;
}

Expected<Lines> Trails(std::span<const Vec3> positions, std::span<const Vec3> velocities,
                       double seconds, std::span<const Vec3f> colors, const Vec3f& color,
                       float tailShade, std::string name) {
  if (velocities.size() != positions.size())
    return Bad("velocities has " + std::to_string(velocities.size()) + " entries for " +
               std::to_string(positions.size()) + " positions");
  if (Status st = Matches("colors", colors.size(), positions.size()); !st.ok()) return st.error();
  Lines l;
  l.name = std::move(name);
  l.points.reserve(2 * positions.size());
  l.colors.reserve(2 * positions.size());
  for (size_t i = 0; i < positions.size(); ++i) {
    const Vec3f head = colors.empty() ? color : colors[i];
    l.points.push_back((positions[i] - seconds * velocities[i]).cast<float>());
    l.points.push_back(positions[i].cast<float>());
    l.colors.push_back(tailShade * head);
    l.colors.push_back(head);
  }
  return l;
}

Expected<mesh::TriangleMesh> SheetMesh(std::span<const Vec3> x,
                                       std::span<const std::array<uint32_t, 3>> triangles,
                                       std::span<const uint16_t> materials) {
  if (Status st = Matches("materials", materials.size(), triangles.size(), "triangles"); !st.ok())
    return st.error();
  mesh::TriangleMesh m;
  std::vector<Vec3> normals(x.size(), Vec3::Zero());
  m.indices.reserve(3 * triangles.size());
  for (size_t t = 0; t < triangles.size(); ++t) {
    const auto& tri = triangles[t];
    for (uint32_t k : tri)
      if (k >= x.size())
        return Bad("triangle " + std::to_string(t) + " has index " + std::to_string(k) +
                   ", but there are " + std::to_string(x.size()) + " positions");
    const Vec3 n = (x[tri[1]] - x[tri[0]]).cross(x[tri[2]] - x[tri[0]]);
    for (uint32_t k : tri) normals[k] += n;
    m.indices.insert(m.indices.end(), {tri[0], tri[1], tri[2]});
  }
  m.material.assign(materials.begin(), materials.end());
  if (materials.empty()) m.material.assign(triangles.size(), 0);
  m.positions.resize(x.size());
  m.normals.resize(x.size());
  m.uvs.assign(x.size(), mesh::Vec2f(0, 0));
  for (size_t i = 0; i < x.size(); ++i) {
    m.positions[i] = x[i].cast<float>();
    const double len = normals[i].norm();
    m.normals[i] = len > 0 ? (normals[i] / len).cast<float>() : Vec3f(0, 0, 1);
  }
  return m;
}

}  // namespace sylva::draw
