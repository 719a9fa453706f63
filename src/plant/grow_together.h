// Several plants grown in step in one shared Environment, so that they
// compete in it (a light grid: Palubicki et al. 2009, section 4.1). A scene
// grows its <plant>s whose grammars say `environment: light` this way.
//
// Every plant takes a derivation step in turn (a plant whose derivation is
// done stops stepping but keeps its queries); then the ?E queries of all of
// them, moved into world coordinates by each plant's Placement, are
// answered in one Environment::Answer() call, each tagged with the index of
// its plant. The axiom's queries are answered the same way before the first
// step.
#pragma once

#include <span>
#include <vector>

#include "core/math.h"
#include "plant/environment.h"
#include "plant/plant.h"

namespace sylva::plant {

// Where a plant stands: world = position + R_y(yawDegrees) (scale p), as
// draw::Transform places a mesh.
struct Placement {
  Vec3 position{0, 0, 0};
  double yawDegrees = 0;
  double scale = 1;  // > 0
};

// One result per spec (in order), as BuildPlant would give. Each spec's
// own `environment` is replaced by `shared` (and its grammar's
// `environment:` is not used). An error of `shared` fails every plant.
std::vector<PlantResult> GrowTogether(std::span<const PlantSpec> specs,
                                      std::span<const Placement> placements, Environment& shared);

}  // namespace sylva::plant
