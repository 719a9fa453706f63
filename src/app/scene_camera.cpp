// The scene's camera: see scene_camera.h.
#include "app/scene_camera.h"

#include <algorithm>
#include <cmath>

namespace sylva::app {

// The scene's camera, or one framing everything drawn.
render::Camera SceneCamera(const scene::Scene& s, const scene::BuiltScene& built, double aspect) {
  if (!s.camera) {
    // Nothing built (only particles, cloth or boids): a box of zero size put
    // the eye 3 um from it, so that every particle filled the screen (200000
    // of them took 90 s on llvmpipe). Frame 10 m about the origin instead.
    Vec3 lo = built.lo, hi = built.hi;
    if (!((hi - lo).maxCoeff() > 1e-9)) {
      const Vec3 centre = (lo + hi) / 2;
      lo = centre - Vec3(5, 0, 5);
      hi = centre + Vec3(5, 5, 5);
    }
    render::Camera c = render::Camera::Frame(lo, hi, aspect, 30, 15, false);
    c.fovY = 40;
    return c;
  }
  const scene::CameraDef& d = *s.camera;
  render::Camera c;
  c.fovY = d.fovDegrees;
  c.target = d.target;
  if (d.orbit) {
    c.azimuth = d.orbit->x();
    c.elevation = std::clamp(d.orbit->y(), -89.0, 89.0);
    c.distance = d.orbit->z();
  } else {
    const Vec3 v = *d.position - d.target;
    c.distance = v.norm();
    c.elevation = std::asin(std::clamp(v.y() / c.distance, -1.0, 1.0)) * kRadToDeg;
    c.azimuth = std::atan2(v.x(), v.z()) * kRadToDeg;
  }
  // Clip planes that hold the whole scene unless the file sets them.
  const double reach = (c.Eye() - (built.lo + built.hi) / 2).norm() + (built.hi - built.lo).norm();
  c.nearPlane = d.near.value_or(std::max(1e-3, c.distance * 1e-3));
  c.farPlane = d.far.value_or(std::max(reach * 1.5, c.nearPlane * 2));
  return c;
}

}  // namespace sylva::app
