// The default scene of a grammar rendered alone: the plant on a ground
// plane at its foot, wider than the plant, whose rim the default lights
// turn into the background colour (so the floor has no visible edge), and
// a shadow map fitted to the whole plant.
#include "scene/default_scene.h"

#include <gtest/gtest.h>

#include <cmath>

namespace sylva::scene {
namespace {

TEST(DefaultScene, PlantOnAGroundThatFadesIntoTheBackground) {
  auto plant = std::make_shared<mesh::TriangleMesh>();
  const Vec3 lo(-1, 2, -0.5), hi(1, 6, 0.5);
  const draw::DrawList list = DefaultScene(plant, {}, lo, hi);
  ASSERT_TRUE(list.Check().ok()) << list.Check().error().message;
  ASSERT_EQ(list.meshes.size(), 2u);
  EXPECT_EQ(list.meshes[0].mesh, plant);
  EXPECT_TRUE(list.meshes[0].castsShadow);
  const draw::MeshDraw& ground = list.meshes[1];
  EXPECT_FALSE(ground.castsShadow) << "the ground only receives";
  ASSERT_TRUE(list.shadowBounds);
  EXPECT_EQ(list.shadowBounds->first, lo);
  EXPECT_EQ(list.shadowBounds->second, hi);

  // Flat at the plant's foot, centred under it, 12 times its radius.
  const mesh::TriangleMesh& g = *ground.mesh;
  double reach = 0;
  for (const mesh::Vec3f& p : g.positions) {
    EXPECT_FLOAT_EQ(p.y(), 2.0f) << "a ground vertex off the plant's foot";
    reach = std::max(reach, std::hypot(double(p.x()), double(p.z())));
  }
  const double radius = 0.5 * (hi - lo).norm();
  EXPECT_NEAR(reach, 12 * radius, 1e-4 * radius);
  for (size_t t = 0; t < g.triangleCount(); ++t) {  // facing up: lit from above
    const mesh::Vec3f a = g.positions[g.indices[3 * t]], b = g.positions[g.indices[3 * t + 1]],
                      c = g.positions[g.indices[3 * t + 2]];
    ASSERT_GT((b - a).cross(c - a).y(), 0) << "triangle " << t << " faces down";
  }

  // The rim's colour, lit as shaders/scene.frag lights an upward face
  // (diffuse terms), is the background; the centre is the ground colour.
  mesh::Vec3f light(0, 0, 0);
  for (const draw::Light& l : list.lights) {
    const mesh::Vec3f c = l.color * l.intensity;
    if (l.type == draw::Light::Type::kAmbient) light += c;
    if (l.type == draw::Light::Type::kSun)
      light += c * std::max(0.0f, -l.direction.normalized().y());
  }
  const mesh::Vec3f rim = ground.palette.back().cwiseProduct(light);
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(rim[k], list.background[k], 0.01) << "channel " << k << " of the lit rim";
  EXPECT_EQ(ground.palette[1], kDefaultGroundColor) << "the ground near the plant";
}

}  // namespace
}  // namespace sylva::scene
