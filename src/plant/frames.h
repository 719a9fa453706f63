// cpfg's overlaid animation frames: an animation file (`.a`) with `clear
// between frames: off` makes cpfg draw each derivation step from its first
// frame to its last (every `step` steps) over the previous pictures, so
// what shows is the union of the frames. Reaction-diffusion patterns on
// shells (vlab's natica) are drawn this way: each step draws one row of
// cells, a little lower than the last. DrawFrames returns that union as one
// geometry; the derivation goes on past the grammar's derivation length, as
// cpfg's animation does.
#pragma once

#include "core/diagnostic.h"
#include "core/status.h"
#include "mesh/plant_geometry.h"
#include "plant/plant.h"

namespace sylva::plant {

struct FrameRange {
  int first = 0;  // derivation step of the first frame (0: the axiom)
  int last = 0;   // of the last frame, included; < 0: the derivation length
  int step = 1;   // steps between frames, >= 1
};

// The geometry of frames first, first + step, ... <= last of `spec`'s
// plant, branch ids renumbered so the frames never share a branch. Errors:
// a bad range (first < 0, last < first (after a negative last becomes the
// derivation length), step < 1, last beyond
// lsys::kMaxAnimationSteps), the grammar's errors, a step's
// error, and more drawn primitives in all than spec.limits allows (a
// quarter of maxTriangles). Warnings (the grammar's, the turtle's once
// each) go to `diagnostics`.
Expected<mesh::PlantGeometry> DrawFrames(const PlantSpec& spec, const FrameRange& frames,
                                         DiagnosticList& diagnostics);

}  // namespace sylva::plant
