// The camera a scene file asks for (<camera>: position and target, or an
// orbit about the target), as the renderer's orbit camera; without one, a
// view that frames everything built (10 m about the origin when nothing
// is: a scene of particles, cloth or boids only). Used by render and view.
#pragma once

#include "render/camera.h"
#include "scene/build.h"
#include "scene/scene.h"

namespace sylva::app {

// `aspect` is width / height. Clip planes hold the whole scene unless the
// file sets `near` and `far`.
render::Camera SceneCamera(const scene::Scene& s, const scene::BuiltScene& built, double aspect);

}  // namespace sylva::app
