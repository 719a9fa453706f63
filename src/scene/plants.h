// Plants of a scene: the plant library's spec for a <plant> or a <forest>,
// and the grammar check that `sylva check scene.xml` runs.
#pragma once

#include "core/diagnostic.h"
#include "plant/plant.h"
#include "scene/scene.h"

namespace sylva::scene {

// The spec of a <plant> (its grammar, steps, seed, <define>s).
plant::PlantSpec SpecFor(const PlantDef& p);
// The spec of a forest's variant `variant` (its seed drawn from the
// forest's seed and the variant index).
plant::PlantSpec SpecFor(const ForestDef& f, int variant);

// Parses every grammar the scene names (each file once per set of defines).
// A grammar's diagnostics are followed by a note at the scene element that
// names it, so an error points at both the grammar's line and the scene's.
DiagnosticList CheckGrammars(const Scene& scene);

}  // namespace sylva::scene
