// Plants of a scene: the plant library's spec for a <plant> or a <forest>,
// and the grammar check that `sylva check scene.xml` runs.
#pragma once

#include "core/diagnostic.h"
#include "plant/plant.h"
#include "scene/scene.h"

namespace sylva::scene {

// The seed of an element that sets none: the scene's seed hashed with the
// element's id (or, without one, its kind and its index among its kind), so
// adding an element does not change another's randomness.
uint64_t ElementSeed(uint64_t sceneSeed, const std::string& id, const char* kind, size_t index);

// The spec of a <plant> (its grammar, steps, seed, <define>s).
plant::PlantSpec SpecFor(const PlantDef& p);
// The spec of a forest's variant `variant`: its grammar seed drawn from
// `forestSeed` (the forest's seed, or its ElementSeed) and the index.
plant::PlantSpec SpecFor(const ForestDef& f, uint64_t forestSeed, int variant);

// Parses every grammar the scene names (each file once per set of defines).
// A grammar's diagnostics are followed by a note at the scene element that
// names it, so an error points at both the grammar's line and the scene's.
DiagnosticList CheckGrammars(const Scene& scene);

}  // namespace sylva::scene
