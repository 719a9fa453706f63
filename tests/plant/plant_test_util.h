// Plants for tests, built through the plant library: the same chain
// (parse, derive, interpretation rules, turtle, surfaces, tessellation) that
// users run, so no test exercises a shortcut users never take.
#pragma once

#include <gtest/gtest.h>

#include <optional>
#include <string>

#include "plant/plant.h"

namespace sylva::testing {

// Builds `spec`, failing the current test (with the diagnostics) on error.
inline std::optional<plant::Plant> BuildOrFail(const plant::PlantSpec& spec) {
  plant::PlantResult r = plant::BuildPlant(spec);
  if (!r.plant) ADD_FAILURE() << spec.path << ":\n" << r.diagnostics.FormatAll();
  return std::move(r.plant);
}

// A plant from grammar text; steps < 0: the grammar's derivation length.
inline std::optional<plant::Plant> PlantFromText(const std::string& text, int steps = -1,
                                                 plant::Stage until = plant::Stage::kGeometry,
                                                 turtle::DrawOptions draw = {}) {
  plant::PlantSpec spec;
  spec.path = "t.lsys";
  spec.text = text;
  if (steps >= 0) spec.steps = steps;
  spec.until = until;
  spec.draw = draw;
  return BuildOrFail(spec);
}

// A plant from a bundled grammar, named relative to grammars/.
inline std::optional<plant::Plant> PlantFromFile(const std::string& name, int steps = -1,
                                                 plant::Stage until = plant::Stage::kGeometry,
                                                 int sides = 8) {
  plant::PlantSpec spec;
  spec.path = std::string(SYLVA_SOURCE_DIR) + "/grammars/" + name;
  if (steps >= 0) spec.steps = steps;
  spec.until = until;
  spec.detail.sides = sides;
  return BuildOrFail(spec);
}

}  // namespace sylva::testing
