#include "draw/draw_list.h"

#include <cmath>

namespace sylva::draw {
namespace {

Diagnostic Bad(std::string message) {
  Diagnostic d;
  d.message = "draw list: " + std::move(message);
  return d;
}

template <typename M>
bool Finite(const M& m) {
  for (int i = 0; i < m.size(); ++i)
    if (!std::isfinite(m.data()[i])) return false;
  return true;
}

void Grow(Vec3& lo, Vec3& hi, bool& any, const Vec3& p) {
  lo = any ? lo.cwiseMin(p) : p;
  hi = any ? hi.cwiseMax(p) : p;
  any = true;
}

}  // namespace

Light Light::Sun(const Vec3f& direction, const Vec3f& color, float intensity) {
  Light l;
  l.type = Type::kSun;
  l.direction = direction;
  l.color = color;
  l.intensity = intensity;
  return l;
}

Light Light::Ambient(const Vec3f& color, float intensity) {
  Light l;
  l.type = Type::kAmbient;
  l.color = color;
  l.intensity = intensity;
  return l;
}

Light Light::Point(const Vec3f& position, const Vec3f& color, float intensity) {
  Light l;
  l.type = Type::kPoint;
  l.position = position;
  l.color = color;
  l.intensity = intensity;
  return l;
}

std::vector<Light> DefaultLights() {
  return {Light::Sun({0.5f, -0.8f, -0.6f}, {1.0f, 0.95f, 0.85f}, 0.9f),
          Light::Sun({-0.7f, -0.2f, 0.4f}, {0.55f, 0.62f, 0.75f}, 0.35f),
          Light::Ambient({0.35f, 0.36f, 0.38f}, 1.0f)};
}

Status DrawList::Check() const {
  if (shadowBounds && (!Finite(shadowBounds->first) || !Finite(shadowBounds->second) ||
                       !(shadowBounds->first.array() <= shadowBounds->second.array()).all()))
    return Bad("the shadow bounds are not a box of finite numbers (lo <= hi)");
  if (lights.size() > kMaxLights)
    return Bad(std::to_string(lights.size()) + " lights; the renderer takes at most " +
               std::to_string(kMaxLights));
  for (size_t i = 0; i < lights.size(); ++i) {
    const Light& l = lights[i];
    if (!Finite(l.direction) || !Finite(l.position) || !Finite(l.color) ||
        !std::isfinite(l.intensity))
      return Bad("light " + std::to_string(i) + " has a number that is not finite");
    if (l.type == Light::Type::kSun && l.direction.norm() == 0)
      return Bad("sun light " + std::to_string(i) + " has a zero direction");
  }
  for (size_t i = 0; i < meshes.size(); ++i) {
    const MeshDraw& m = meshes[i];
    if (!m.mesh) return Bad("mesh draw " + std::to_string(i) + " has no mesh");
    const std::string bad = mesh::FindNonFinite(*m.mesh);
    if (!bad.empty()) return Bad("mesh draw " + std::to_string(i) + ": " + bad);
    for (size_t k = 0; k < m.instances.size(); ++k)
      if (!Finite(m.instances[k].transform) || !Finite(m.instances[k].tint))
        return Bad("mesh draw " + std::to_string(i) + ", instance " + std::to_string(k) +
                   " has a number that is not finite");
  }
  for (size_t i = 0; i < sprites.size(); ++i) {
    const Sprites& s = sprites[i];
    const size_t n = s.positions.size();
    if (s.sizes.size() != n || s.colors.size() != n || (!s.alphas.empty() && s.alphas.size() != n))
      return Bad("sprite batch " + std::to_string(i) + " has " + std::to_string(n) +
                 " positions, " + std::to_string(s.sizes.size()) + " sizes, " +
                 std::to_string(s.colors.size()) + " colours and " +
                 std::to_string(s.alphas.size()) + " alphas");
    for (size_t k = 0; k < n; ++k)
      if (!Finite(s.positions[k]) || !std::isfinite(s.sizes[k]) || !Finite(s.colors[k]))
        return Bad("sprite " + std::to_string(k) + " of batch " + std::to_string(i) +
                   " has a number that is not finite");
  }
  for (size_t i = 0; i < lines.size(); ++i) {
    if (lines[i].colors.size() != lines[i].points.size() || lines[i].points.size() % 2)
      return Bad("line batch " + std::to_string(i) + " has " +
                 std::to_string(lines[i].points.size()) + " points (an even count needed) and " +
                 std::to_string(lines[i].colors.size()) + " colours (one a point)");
    for (const Vec3f& p : lines[i].points)
      if (!Finite(p)) return Bad("line batch " + std::to_string(i) + " has a non-finite point");
  }
  if (sky && (!Finite(sky->top) || !Finite(sky->horizon))) return Bad("sky colour not finite");
  return {};
}

bool DrawList::Bounds(Vec3& lo, Vec3& hi) const {
  bool any = false;
  for (const MeshDraw& m : meshes) {
    if (!m.mesh || m.mesh->positions.empty()) continue;
    Vec3 mlo = m.mesh->positions[0].cast<double>(), mhi = mlo;
    for (const Vec3f& p : m.mesh->positions) {
      mlo = mlo.cwiseMin(p.cast<double>());
      mhi = mhi.cwiseMax(p.cast<double>());
    }
    for (const Instance& inst : m.instances) {
      const Eigen::Matrix4d t = inst.transform.cast<double>();
      for (int c = 0; c < 8; ++c) {
        const Vec3 corner((c & 1) ? mhi.x() : mlo.x(), (c & 2) ? mhi.y() : mlo.y(),
                          (c & 4) ? mhi.z() : mlo.z());
        Grow(lo, hi, any, (t * corner.homogeneous()).head<3>());
      }
    }
  }
  for (const Sprites& s : sprites)
    for (const Vec3f& p : s.positions) Grow(lo, hi, any, p.cast<double>());
  for (const Lines& l : lines)
    for (const Vec3f& p : l.points) Grow(lo, hi, any, p.cast<double>());
  return any;
}

Mat4f Transform(const Vec3& translation, double yawDegrees, double scale) {
  Eigen::Affine3d a = Eigen::Affine3d::Identity();
  a.translate(translation);
  a.rotate(Eigen::AngleAxisd(yawDegrees * kDegToRad, Vec3::UnitY()));
  a.scale(scale);
  return a.matrix().cast<float>();
}

}  // namespace sylva::draw
