#include "scene/default_scene.h"

#include <algorithm>
#include <cmath>

namespace sylva::scene {
namespace {

constexpr int kRings = 24;    // rings of the ground, centre excluded
constexpr int kSectors = 64;  // sectors around it

// What the default rig's lights make of an upward-facing albedo of 1 (the
// diffuse terms of shaders/scene.frag; specular left out).
mesh::Vec3f LightOnTheGround(const std::vector<draw::Light>& lights) {
  mesh::Vec3f sum(0, 0, 0);
  for (const draw::Light& l : lights) {
    const mesh::Vec3f c = l.color * l.intensity;
    if (l.type == draw::Light::Type::kAmbient) sum += c;  // 0.55 + 0.45 n.y at n = +y
    if (l.type == draw::Light::Type::kSun) sum += c * std::max(0.0f, -l.direction.normalized().y());
  }
  return sum;
}

// A round plane of radius r at height y about (cx, cz), in rings: vertex
// colours from palette entries (one per ring; TriangleMesh colours a vertex
// by the material of the first triangle that uses it, so band b, between
// ring b and ring b + 1, has material b + 1: each vertex gets its ring's).
std::shared_ptr<mesh::TriangleMesh> GroundMesh(double cx, double y, double cz, double r) {
  auto m = std::make_shared<mesh::TriangleMesh>();
  auto vertex = [&](double x, double z) {
    m->positions.push_back(mesh::Vec3f(float(x), float(y), float(z)));
    m->normals.push_back(mesh::Vec3f(0, 1, 0));
    m->uvs.push_back(mesh::Vec2f(0, 0));
  };
  vertex(cx, cz);
  for (int k = 1; k <= kRings; ++k) {
    // Rings closer together near the plant, where its shadow falls.
    const double rk = r * std::pow(double(k) / kRings, 1.5);
    for (int s = 0; s < kSectors; ++s) {
      const double a = 2 * kPi * s / kSectors;
      vertex(cx + rk * std::cos(a), cz + rk * std::sin(a));
    }
  }
  auto ring = [](int k, int s) { return uint32_t(1 + (k - 1) * kSectors + s % kSectors); };
  for (int b = 0; b < kRings; ++b) {
    for (int s = 0; s < kSectors; ++s) {
      const uint32_t o0 = ring(b + 1, s), o1 = ring(b + 1, s + 1);
      if (b == 0) {  // counter-clockwise seen from above (+y)
        m->indices.insert(m->indices.end(), {0, o1, o0});
        m->material.push_back(uint16_t(b + 1));
        continue;
      }
      const uint32_t i0 = ring(b, s), i1 = ring(b, s + 1);
      m->indices.insert(m->indices.end(), {i0, i1, o1, i0, o1, o0});
      m->material.insert(m->material.end(), {uint16_t(b + 1), uint16_t(b + 1)});
    }
  }
  return m;
}

}  // namespace

draw::DrawList DefaultScene(std::shared_ptr<const mesh::TriangleMesh> plant,
                            const mesh::Palette& palette, const Vec3& lo, const Vec3& hi,
                            bool ground) {
  draw::DrawList list;
  list.lights = draw::DefaultLights();
  list.background = mesh::Srgb(0.94f, 0.95f, 0.96f);
  list.shadowBounds = std::make_pair(lo, hi);
  draw::MeshDraw& p = list.meshes.emplace_back();
  p.mesh = std::move(plant);
  p.palette = palette;
  p.instances.emplace_back();
  p.name = "plant";
  if (!ground) return list;

  const double radius = std::max(0.5 * (hi - lo).norm(), 1e-3);
  draw::MeshDraw& g = list.meshes.emplace_back();
  g.mesh = GroundMesh((lo.x() + hi.x()) / 2, lo.y(), (lo.z() + hi.z()) / 2, 12 * radius);
  g.castsShadow = false;
  g.name = "ground";
  g.instances.emplace_back();
  // Ring colours: the ground colour out to a third of the radius, then
  // smoothly to the albedo the lights turn into the background colour.
  const mesh::Vec3f light = LightOnTheGround(list.lights);
  const mesh::Vec3f rim = list.background.cwiseQuotient(light).cwiseMin(1.0f);
  g.palette.resize(kRings + 1);
  for (int k = 0; k <= kRings; ++k) {
    const double t = std::clamp((std::pow(double(k) / kRings, 1.5) - 0.25) / 0.75, 0.0, 1.0);
    const float w = float(t * t * (3 - 2 * t));
    g.palette[size_t(k)] = kDefaultGroundColor * (1 - w) + rim * w;
  }
  return list;
}

}  // namespace sylva::scene
