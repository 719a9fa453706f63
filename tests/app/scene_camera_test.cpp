// The camera of a scene without a <camera> (app/scene_camera.h).
#ifdef SYLVA_TESTS_WITH_GRAPHICS
#include "app/scene_camera.h"

#include <gtest/gtest.h>

namespace sylva::app {
namespace {

TEST(SceneCamera, NothingBuiltFramesTenMetresNotAPoint) {
  // Particles only: the built bounds are a point. The eye was 3 um from it,
  // every particle filled the screen and 200000 of them took 90 s to draw.
  scene::Scene s;
  scene::BuiltScene built;
  const render::Camera c = SceneCamera(s, built, 16.0 / 9.0);
  EXPECT_GT(c.distance, 5.0) << "eye distance, metres";
  EXPECT_LT(c.distance, 100.0) << "eye distance, metres";
}

TEST(SceneCamera, BuiltBoundsAreFramedAsBefore) {
  scene::Scene s;
  scene::BuiltScene built;
  built.lo = Vec3(-0.1, 0, -0.1);
  built.hi = Vec3(0.1, 0.2, 0.1);
  const render::Camera c = SceneCamera(s, built, 1);
  EXPECT_LT(c.distance, 2.0) << "a 20 cm plant is framed close";
}

}  // namespace
}  // namespace sylva::app
#endif
