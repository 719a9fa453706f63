// The scene a grammar gets when it is rendered or viewed alone (`sylva
// render plant.lsys`, `sylva view plant.lsys`): the plant, a ground plane
// under it and the default light rig. The ground is a scene element like
// any other (not a disc glued under the mesh by the renderer): a round
// plane, 12 times the plant's radius, whose colour fades into the
// background toward its rim, so the picture has a floor and a shadow but
// no edge. 2D figures (drawn as lines) get no default scene.
//
//   draw::DrawList list = scene::DefaultScene(mesh, palette, lo, hi);
//   renderer.Draw(list, camera);
#pragma once

#include <memory>

#include "core/math.h"
#include "draw/draw_list.h"
#include "mesh/color.h"
#include "mesh/triangle_mesh.h"

namespace sylva::scene {

// `lo`..`hi`: the whole plant's box, before any culling; the ground lies at
// lo.y and the shadow map covers the box (draw::DrawList::shadowBounds), so
// every view of one plant gets the same shadows. `ground` false: no ground
// (a camera below it, such as a cpfg view file looking up into a crown,
// would see only its underside).
draw::DrawList DefaultScene(std::shared_ptr<const mesh::TriangleMesh> plant,
                            const mesh::Palette& palette, const Vec3& lo, const Vec3& hi,
                            bool ground = true);

// Whether a camera at `eye` sees the default ground of a plant whose box
// starts at lo.y from above (eye.y >= lo.y).
inline bool SeesGroundFromAbove(const Vec3& eye, const Vec3& lo) {
  return eye.y() >= lo.y();
}

// The ground's colour near the plant (linear); toward its rim it turns to
// what the default lights make of the background colour.
inline const mesh::Vec3f kDefaultGroundColor = mesh::Srgb(0.86f, 0.84f, 0.80f);

}  // namespace sylva::scene
