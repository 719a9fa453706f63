// Plants grown in step in one shared environment (plant/grow_together.h).
#include "plant/grow_together.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "plant/light_grid.h"

namespace sylva::plant {
namespace {

PlantSpec Spec(const std::string& text, int steps) {
  PlantSpec s;
  s.path = "t.lsys";
  s.text = text;
  s.steps = steps;
  s.until = Stage::kWord;
  return s;
}

std::string Text(const PlantResult& r) {
  if (!r.plant) return "error: " + r.diagnostics.FormatAll();
  return lsys::FormatWord(r.plant->word, r.plant->grammar.symbols);
}

// A tip grows while it has nearly full light.
const char* kTip = "axiom: A ?E(0)\nA > ?E(e) : e > 0.9 --> F A\n";

TEST(GrowTogether, PlantsSideBySideShadeEachOtherAndApartDoNot) {
  LightDef def;
  def.cell = 1;
  def.depth = 3;
  def.shadow = 0.2;
  const std::vector<PlantSpec> specs = {Spec(kTip, 3), Spec(kTip, 3)};
  {
    // In one voxel column: each bud reads 1 - 0.2 (the other's shadow).
    LightEnvironment env(def);
    const std::vector<Placement> at = {{Vec3(0.3, 0, 0.5)}, {Vec3(0.7, 0, 0.5)}};
    const auto r = GrowTogether(specs, at, env);
    ASSERT_EQ(r.size(), 2u);
    EXPECT_EQ(Text(r[0]), "A?E(0.8)");
    EXPECT_EQ(Text(r[1]), "A?E(0.8)");
  }
  {
    // 10 voxels apart, past the pyramid's reach: both in full light.
    LightEnvironment env(def);
    const std::vector<Placement> at = {{Vec3(0.5, 0, 0.5)}, {Vec3(10.5, 0, 0.5)}};
    const auto r = GrowTogether(specs, at, env);
    EXPECT_EQ(Text(r[0]), "FFFA?E(1)");
    EXPECT_EQ(Text(r[1]), "FFFA?E(1)");
  }
}

// Keeps the world positions and plants it was asked about.
class Recorder final : public Environment {
 public:
  std::vector<EnvQuery> last;
  int rounds = 0;
  Status Answer(std::span<EnvQuery> q) override {
    last.assign(q.begin(), q.end());
    ++rounds;
    for (EnvQuery& e : q) e.params[0] = rounds;
    return {};
  }
};

TEST(GrowTogether, QueriesAreInWorldCoordinatesThroughEachPlacement) {
  const std::vector<PlantSpec> specs = {Spec("axiom: f(1) ?E(0)\n", 2),
                                        Spec("axiom: +(90) f(1) ?E(0)\n", 0)};
  // Plant 1 turned 90 degrees about Y: its local -x is world +z.
  const std::vector<Placement> at = {{Vec3(1, 0, 0), 0, 1}, {Vec3(10, 0, 0), 90, 2}};
  Recorder env;
  const auto r = GrowTogether(specs, at, env);
  EXPECT_EQ(env.rounds, 3) << "the axiom and 2 steps of the longer derivation";
  ASSERT_EQ(env.last.size(), 2u);
  EXPECT_EQ(env.last[0].plant, 0u);
  EXPECT_EQ(env.last[1].plant, 1u);
  EXPECT_TRUE(env.last[0].position.isApprox(Vec3(1, 1, 0), 1e-12))
      << env.last[0].position.transpose();
  EXPECT_TRUE(env.last[1].position.isApprox(Vec3(10, 0, 2), 1e-12))
      << env.last[1].position.transpose();
  EXPECT_TRUE(env.last[1].frame.heading.isApprox(Vec3(0, 0, 1), 1e-12))
      << env.last[1].frame.heading.transpose();
  // The plant done after 0 steps is still answered each round.
  EXPECT_EQ(Text(r[0]), "f(1)?E(3)");
  EXPECT_EQ(Text(r[1]), "+(90)f(1)?E(3)");
}

TEST(GrowTogether, AnErrorInOnePlantLeavesTheOthers) {
  const std::vector<PlantSpec> specs = {Spec("axiom: A ?E(0\n", 1), Spec(kTip, 1)};
  const std::vector<Placement> at(2);
  Recorder env;
  const auto r = GrowTogether(specs, at, env);
  EXPECT_FALSE(r[0].plant);
  EXPECT_TRUE(r[0].diagnostics.HasErrors());
  EXPECT_EQ(Text(r[1]), "FA?E(2)");
}

}  // namespace
}  // namespace sylva::plant
