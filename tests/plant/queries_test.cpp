// Open L-systems: ?P ?H ?L ?U answered between steps with cpfg's semantics
// (plant/queries.h), and ?E through an Environment.
#include "plant/queries.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "lsys/word.h"
#include "plant/plant.h"
#include "plant/plant_test_util.h"

namespace sylva::plant {
namespace {

using testing::PlantFromText;

std::string Text(const Plant& p) {
  return lsys::FormatWord(p.word, p.grammar.symbols);
}

// Parameters of the n-th module named `name` in the plant's word.
std::vector<double> ParamsOf(const Plant& p, const std::string& name, int n = 0) {
  for (size_t i = 0; i < p.word.size(); ++i) {
    if (p.grammar.symbols.name(p.word.symbols[i]) != name || n-- > 0) continue;
    auto s = p.word.ParamsOf(i);
    return {s.begin(), s.end()};
  }
  ADD_FAILURE() << "no module " << name;
  return {};
}

void ExpectNear(const std::vector<double>& got, const std::vector<double>& want,
                const std::string& what) {
  ASSERT_EQ(got.size(), want.size()) << what;
  for (size_t i = 0; i < want.size(); ++i)
    EXPECT_NEAR(got[i], want[i], 1e-12) << what << " component " << i << " is " << got[i];
}

TEST(Queries, GrowthStopsWhereThePositionQuerySaysItIsHighEnough) {
  const std::string g =
      "#define h 3\n"
      "axiom: A ?P(0,0)\n"
      "A > ?P(x,y) : y < h --> F A\n";
  // Each step reads the position the previous word put the tip at.
  const char* want[] = {"A?P(0,0)",    "FA?P(0,1)",   "FFA?P(0,2)", "FFFA?P(0,3)",
                        "FFFA?P(0,3)", "FFFA?P(0,3)", "FFFA?P(0,3)"};
  for (int n = 0; n <= 6; ++n) {
    auto p = PlantFromText(g, n, Stage::kWord);
    ASSERT_TRUE(p);
    EXPECT_EQ(Text(*p), want[n]) << "after " << n << " steps";
  }
}

TEST(Queries, TwoParametersTakeXYAndThreeTakeXYZ) {
  // +(90) turns H to L = (-1,0,0) and L to -H; F moves to (-1,0,0); &(90)
  // pitches H toward U = (0,0,-1).
  auto p = PlantFromText(
      "axiom: +(90) F ?P(9,9) ?P(9,9,9) ?H(9,9) ?H(9,9,9) ?L(9,9,9) ?U(9,9) &(90) ?H(9,9,9)\n", 0,
      Stage::kWord);
  ASSERT_TRUE(p);
  ExpectNear(ParamsOf(*p, "?P", 0), {-1, 0}, "?P(x,y)");
  ExpectNear(ParamsOf(*p, "?P", 1), {-1, 0, 0}, "?P(x,y,z)");
  ExpectNear(ParamsOf(*p, "?H", 0), {-1, 0}, "?H(x,y)");
  ExpectNear(ParamsOf(*p, "?H", 1), {-1, 0, 0}, "?H(x,y,z)");
  ExpectNear(ParamsOf(*p, "?L", 0), {0, -1, 0}, "?L");
  ExpectNear(ParamsOf(*p, "?U", 0), {0, 0}, "?U(x,y)");
  ExpectNear(ParamsOf(*p, "?H", 2), {0, 0, -1}, "?H after &(90)");
}

TEST(Queries, WrongArityIsLeftAsWritten) {
  auto p = PlantFromText("axiom: F ?P(7) ?P(7,7,7,7)\n", 0, Stage::kWord);
  ASSERT_TRUE(p);
  EXPECT_EQ(Text(*p), "F?P(7)?P(7,7,7,7)");
}

TEST(Queries, InterpretationRulesApplyBeforeTheTurtle) {
  // B draws nothing itself; the interpretation rules make it F(2).
  auto p = PlantFromText(
      "axiom: A ?P(0,0)\n"
      "A --> B A\n"
      "interpretation:\n"
      "B --> F(2)\n",
      2, Stage::kWord);
  ASSERT_TRUE(p);
  EXPECT_EQ(Text(*p), "BBA?P(0,4)");
}

TEST(Queries, InterpretationProductionOnAQueryIsAnError) {
  PlantSpec spec;
  spec.path = "t.lsys";
  spec.text = "axiom: A ?P(0,0)\ninterpretation:\nA --> F ?P(0,0)\n";
  PlantResult r = BuildPlant(spec);
  ASSERT_FALSE(r.plant);
  const std::string all = r.diagnostics.FormatAll();
  EXPECT_NE(all.find("t.lsys:3:1: error: an interpretation production rewrites or writes a query"),
            std::string::npos)
      << all;
}

TEST(Queries, BranchesAnswerFromTheirOwnTurtleState) {
  // The query inside the branch sees the branch's position; after `]` the
  // trunk's.
  auto p = PlantFromText("axiom: F [ +(90) F ?P(0,0) ] F ?P(0,0)\n", 0, Stage::kWord);
  ASSERT_TRUE(p);
  ExpectNear(ParamsOf(*p, "?P", 0), {-1, 1}, "in the branch");
  ExpectNear(ParamsOf(*p, "?P", 1), {0, 2}, "on the trunk");
}

// Answers ?E with 10 y + the number of calls so far, so the test sees both
// the position and when it was asked.
class CountingEnvironment final : public Environment {
 public:
  int calls = 0;
  size_t lastQueries = 0;
  Status Answer(std::span<EnvQuery> queries) override {
    ++calls;
    lastQueries = queries.size();
    for (EnvQuery& q : queries) q.params[0] = 10 * q.position.y() + calls;
    return {};
  }
};

TEST(Queries, EnvironmentIsAskedOnTheAxiomAndAfterEveryStep) {
  CountingEnvironment env;
  PlantSpec spec;
  spec.path = "t.lsys";
  spec.text = "axiom: A ?E(0)\nA --> F A\n";
  spec.steps = 3;
  spec.until = Stage::kWord;
  spec.environment = &env;
  PlantResult r = BuildPlant(spec);
  ASSERT_TRUE(r.plant) << r.diagnostics.FormatAll();
  // The program answers ?E: no warning that the grammar has no environment.
  EXPECT_TRUE(r.diagnostics.items.empty()) << r.diagnostics.FormatAll();
  auto& p = r.plant;
  EXPECT_EQ(env.calls, 4) << "the axiom and 3 steps";
  EXPECT_EQ(env.lastQueries, 1u);
  EXPECT_EQ(Text(*p), "FFFA?E(34)");  // y = 3 at the 4th call
}

class FailingEnvironment final : public Environment {
 public:
  Status Answer(std::span<EnvQuery>) override {
    Diagnostic d;
    d.message = "no room";
    return d;
  }
};

TEST(Queries, AnEnvironmentErrorEndsTheGrowth) {
  FailingEnvironment env;
  PlantSpec spec;
  spec.path = "t.lsys";
  spec.text = "axiom: A ?E(0)\nA --> F A\n";
  spec.environment = &env;
  PlantResult r = BuildPlant(spec);
  ASSERT_FALSE(r.plant);
  EXPECT_NE(r.diagnostics.FormatAll().find("t.lsys: error: no room"), std::string::npos)
      << r.diagnostics.FormatAll();
}

}  // namespace
}  // namespace sylva::plant
