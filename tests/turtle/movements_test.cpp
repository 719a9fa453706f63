// cpfg's tropisms and torques (a view file's `tropism:` and `torque:` lines;
// vlab cpfg movements.c), against closed forms.
#include <gtest/gtest.h>

#include <cmath>

#include "plant/plant_test_util.h"
#include "turtle/interpreter.h"
#include "turtle/vec_expect.h"

namespace sylva::turtle {
namespace {

lsys::Movement Tropism(const Vec3& t, double e, double angle = 0, double step = 0) {
  lsys::Movement m;
  m.x = t.x();
  m.y = t.y();
  m.z = t.z();
  m.elasticity = e;
  m.angle = angle;
  m.elasticityStep = step;
  return m;
}

lsys::Movement Torque(const Vec3& t, double e) {
  lsys::Movement m = Tropism(t, e);
  m.torque = true;
  return m;
}

// Draws `axiom` with the movements, recording the frame after each module.
PlantGeometry DrawWith(const std::string& axiom, std::vector<lsys::Movement> movements) {
  auto p = testing::PlantFromText("axiom: " + axiom + "\n", 0, plant::Stage::kInterpreted);
  if (!p) return {};
  TurtleDef def = TurtleDefFrom(p->grammar);
  def.movements = std::move(movements);
  DrawOptions opt;
  opt.recordModules = true;
  auto g = Interpret(p->DrawnWord(), p->grammar.symbols, def, opt);
  EXPECT_TRUE(g.ok());
  return g.ok() ? std::move(*g) : PlantGeometry{};
}

TEST(Movements, OneSegmentBendsByTheElasticityTimesTheSineBeforeItMoves) {
  // H = (0,1,0), T = (1,0,0), e = 0.3: |H x eT| = 0.3, so H turns 0.3 rad
  // toward T before F moves (cpfg bends first): the segment ends on the
  // bent heading. U stays (0,0,-1) (no twist), L = H x U.
  PlantGeometry g = DrawWith("F", {Tropism(Vec3(1, 0, 0), 0.3)});
  ASSERT_EQ(g.segments.size(), 1u);
  const Vec3 h(std::sin(0.3), std::cos(0.3), 0);
  EXPECT_VEC_NEAR(g.segments[0].end, h, 1e-12);
  EXPECT_VEC_NEAR(g.moduleFrame.back().up, Vec3(0, 0, -1), 1e-12);
  EXPECT_VEC_NEAR(g.moduleFrame.back().left, Vec3(h.cross(Vec3(0, 0, -1))), 1e-12);
  // T at 45 degrees to H: the angle is e sin 45.
  g = DrawWith("F", {Tropism(Vec3(1, 1, 0).normalized(), 0.3)});
  const double a = 0.3 * std::sqrt(0.5);
  EXPECT_VEC_NEAR(g.segments[0].end, Vec3(std::sin(a), std::cos(a), 0), 1e-12);
  // At most 1 rad a step (cpfg clamps |H x V| to 1).
  g = DrawWith("F", {Tropism(Vec3(1, 0, 0), 3)});
  EXPECT_VEC_NEAR(g.segments[0].end, Vec3(std::sin(1.0), std::cos(1.0), 0), 1e-12);
  // f, G and g bend as F does.
  for (const char* move : {"f", "G", "g"}) {
    g = DrawWith(move, {Tropism(Vec3(1, 0, 0), 0.3)});
    EXPECT_VEC_NEAR(g.modulePosition.back(), h, 1e-12) << move;
  }
}

TEST(Movements, CpfgsOlderTropismTurnsByTheArcsineAfterTheMove) {
  // A cpfg file's `tropism direction:` and `initial elasticity:` (interpret.c,
  // bend): after F, H turns toward U by asin(e T.U), then toward L by
  // asin(e T.L). T = U = (0,0,-1), e = 0.4: the first segment is straight,
  // the turn is asin 0.4 (ABOP's formula turns by 0.4).
  auto p = testing::PlantFromText("axiom: F\n", 0, plant::Stage::kInterpreted);
  ASSERT_TRUE(p.has_value());
  TurtleDef def = TurtleDefFrom(p->grammar);
  def.tropism = Vec3(0, 0, -1);
  def.tropismGiven = true;
  def.susceptibility = 0.4;
  def.cpfgBend = true;
  DrawOptions opt;
  opt.recordModules = true;
  auto g = Interpret(p->DrawnWord(), p->grammar.symbols, def, opt);
  ASSERT_TRUE(g.ok());
  EXPECT_VEC_NEAR(g->segments[0].end, Vec3(0, 1, 0), 1e-12);
  EXPECT_VEC_NEAR(g->moduleFrame.back().heading, Vec3(0, std::sqrt(1 - 0.16), -0.4), 1e-12);
  def.cpfgBend = false;
  g = Interpret(p->DrawnWord(), p->grammar.symbols, def, opt);
  ASSERT_TRUE(g.ok());
  EXPECT_VEC_NEAR(g->moduleFrame.back().heading, Vec3(0, std::cos(0.4), -std::sin(0.4)), 1e-12);
  // T half along U, half along L: the two turns in turn.
  def.cpfgBend = true;
  def.tropism = Vec3(-1, 0, -1).normalized();
  g = Interpret(p->DrawnWord(), p->grammar.symbols, def, opt);
  ASSERT_TRUE(g.ok());
  const double c = 0.4 * std::sqrt(0.5), s = std::sqrt(1 - c * c);
  const Vec3 h1 = Vec3(0, 1, 0) * s + Vec3(0, 0, -1) * c;
  EXPECT_VEC_NEAR(g->moduleFrame.back().heading, Vec3(h1 * s + Vec3(-1, 0, 0) * c), 1e-12);
}

TEST(Movements, TwoTropismsAddAsElasticityWeightedVectors) {
  // cpfg sums e_k T_k into one V and turns H toward it by |H x V|:
  // T1 = (1,0,0) e 0.2 and T2 = (0,0,1) e 0.1 give V = (0.2, 0, 0.1).
  PlantGeometry g = DrawWith("F", {Tropism(Vec3(1, 0, 0), 0.2), Tropism(Vec3(0, 0, 1), 0.1)});
  const Vec3 v(0.2, 0, 0.1);
  const double a = v.norm();
  const Vec3 want = Vec3(0, 1, 0) * std::cos(a) + v.normalized() * std::sin(a);
  EXPECT_VEC_NEAR(g.segments[0].end, want, 1e-12);
  // Not the two turns one after the other.
  const Vec3 h1(std::sin(0.2), std::cos(0.2), 0);
  EXPECT_GT((g.segments[0].end - h1).norm(), 0.05);
  // A tropism whose elasticity is 0 adds nothing.
  g = DrawWith("F", {Tropism(Vec3(1, 0, 0), 0.2), Tropism(Vec3(0, 0, 1), 0)});
  EXPECT_VEC_NEAR(g.segments[0].end, h1, 1e-12);
}

TEST(Movements, AngleNinetyBendsTowardHorizontalNotDown) {
  // T = (0,1,0) with A = 90 (vlab's lily, two-trees, clover): H bends
  // toward P, the unit vector perpendicular to T on H's side. H 30 degrees
  // below horizontal, e = 0.5: P = (1,0,0) and |H x P| = sin 30, so H rises
  // 0.5 sin 30 = 0.25 rad toward horizontal.
  const double down = 30 * kDegToRad;
  PlantGeometry g = DrawWith("-(120) F", {Tropism(Vec3(0, 1, 0), 0.5, 90)});
  const double below = down - 0.5 * std::sin(down);
  EXPECT_VEC_NEAR(g.segments[0].end - g.segments[0].start,
                  Vec3(std::cos(below), -std::sin(below), 0), 1e-12);
  // Step after step H settles horizontal, where A = 0 (toward -Y) bends
  // it straight down; within 2e-6 rad, as cpfg stops turning when
  // |H x V| < 1e-6.
  std::string many = "-(120)";
  for (int i = 0; i < 80; ++i) many += " F";
  g = DrawWith(many, {Tropism(Vec3(0, 1, 0), 0.5, 90)});
  EXPECT_VEC_NEAR(g.moduleFrame.back().heading, Vec3(1, 0, 0), 4e-6);
  g = DrawWith(many, {Tropism(Vec3(0, -1, 0), 0.5)});
  EXPECT_VEC_NEAR(g.moduleFrame.back().heading, Vec3(0, -1, 0), 4e-6);
  // From above the plane too: H 40 degrees above horizontal comes down to it.
  many = "-(50)";
  for (int i = 0; i < 80; ++i) many += " F";
  g = DrawWith(many, {Tropism(Vec3(0, 1, 0), 0.5, 90)});
  EXPECT_VEC_NEAR(g.moduleFrame.back().heading, Vec3(1, 0, 0), 4e-6);
  // H along T: cpfg takes L for H x T, so H bends toward T x L = +Z.
  g = DrawWith("F", {Tropism(Vec3(0, 1, 0), 0.5, 90)});
  EXPECT_VEC_NEAR(g.segments[0].end, Vec3(0, std::cos(0.5), std::sin(0.5)), 1e-12);
}

TEST(Movements, TorqueTurnsUpAboutTheHeadingAwayFromItsDirection) {
  // H = (0,1,0), U = (0,0,-1), torque T = (1,0,0) e 0.3: D = 0.3 (1,0,0),
  // |U x D| = 0.3, and U turns 0.3 rad about H away from D (cpfg's
  // rot_by_quat turns by minus its quaternion's angle). H does not move.
  PlantGeometry g = DrawWith("F", {Torque(Vec3(1, 0, 0), 0.3)});
  const Frame& f = g.moduleFrame.back();
  EXPECT_VEC_NEAR(g.segments[0].end, Vec3(0, 1, 0), 1e-12);
  const Vec3 u(-std::sin(0.3), 0, -std::cos(0.3));
  EXPECT_VEC_NEAR(f.up, u, 1e-12);
  EXPECT_VEC_NEAR(f.left, Vec3(Vec3(0, 1, 0).cross(u)), 1e-12);
  // Step after step U settles opposite D; a torque along H does nothing.
  std::string many;
  for (int i = 0; i < 80; ++i) many += " F";
  g = DrawWith(many, {Torque(Vec3(1, 0, 0), 0.3)});
  EXPECT_VEC_NEAR(g.moduleFrame.back().up, Vec3(-1, 0, 0), 1e-6);
  g = DrawWith("F", {Torque(Vec3(0, 1, 0), 0.3)});
  EXPECT_VEC_NEAR(g.moduleFrame.back().up, Vec3(0, 0, -1), 1e-12);
}

TEST(Movements, ABendForgetsRollsSinceTheLastFUnlessTfKeepsThem) {
  // cpfg's no-twist rule: when a tropism turns H, U is the up vector after
  // the last F or G carried along; a roll since then is lost, unless @Tf
  // recorded the frame after it.
  const std::vector<lsys::Movement> t = {Tropism(Vec3(0, 0, 1), 0.1)};
  const Frame lost = DrawWith("F /(90) F", t).moduleFrame.back();
  const Frame kept = DrawWith("F /(90) @Tf F", t).moduleFrame.back();
  const Frame none = DrawWith("F F", t).moduleFrame.back();
  EXPECT_VEC_NEAR(lost.up, none.up, 1e-12);
  EXPECT_VEC_NEAR(lost.heading, none.heading, 1e-12);
  EXPECT_NEAR(std::abs(kept.up.dot(none.up)), 0, 1e-12) << Str(kept.up) << " " << Str(none.up);
  EXPECT_VEC_NEAR(kept.heading, none.heading, 1e-12);
}

TEST(Movements, TsTiTdChangeTheIthElasticityKeptByBrackets) {
  const std::vector<lsys::Movement> two = {Tropism(Vec3(1, 0, 0), 0, 0, 0.05),
                                           Tropism(Vec3(0, 0, 1), 0)};
  auto end = [&](const std::string& axiom) { return DrawWith(axiom, two).modulePosition.back(); };
  const Vec3 straight(0, 1, 0);
  const Vec3 first = DrawWith("F", {Tropism(Vec3(1, 0, 0), 0.2)}).modulePosition.back();
  const Vec3 second = DrawWith("F", {Tropism(Vec3(0, 0, 1), 0.2)}).modulePosition.back();
  EXPECT_VEC_NEAR(end("F"), straight, 1e-12);
  EXPECT_VEC_NEAR(end("@Ts(1,0.2) F"), first, 1e-12);
  EXPECT_VEC_NEAR(end("@Ts(2,0.2) F"), second, 1e-12);
  // @Ti(i) and @Td(i) add and subtract the tropism's step S (0.05).
  EXPECT_VEC_NEAR(end("@Ti(1) @Ti(1) @Ti(1) @Ti(1) @Td(1) @Ti(1) F"), first, 1e-12);
  EXPECT_VEC_NEAR(end("@Ti(2,0.3) @Td(2,0.1) F"), second, 1e-12);
  // @Ts(i) sets it to 0; @Ts without parameters changes nothing (cpfg).
  EXPECT_VEC_NEAR(end("@Ts(1,0.2) @Ts(1) F"), straight, 1e-12);
  EXPECT_VEC_NEAR(end("@Ts(1,0.2) @Ts F"), first, 1e-12);
  // The branch's change ends at its `]`.
  EXPECT_VEC_NEAR(end("@Ts(1,0.2) [@Ts(1,0) @Ts(2,0.5)] F"), first, 1e-12);
  // An index beyond them changes nothing; a warning once per name and index.
  PlantGeometry g = DrawWith("@Ts(3,0.2) @Ts(3,0.4) @Ti(3) @Ts(0,1) F", two);
  EXPECT_VEC_NEAR(g.modulePosition.back(), straight, 1e-12);
  ASSERT_EQ(g.moduleWarnings.size(), 3u);
  EXPECT_EQ(g.moduleWarnings[0].symbol, "@Ts");
  EXPECT_NE(g.moduleWarnings[0].message.find("names tropism 3, but the view file defines 2"),
            std::string::npos)
      << g.moduleWarnings[0].message;
  EXPECT_EQ(g.moduleWarnings[1].symbol, "@Ti");
  EXPECT_NE(g.moduleWarnings[2].message.find("names tropism 0"), std::string::npos)
      << g.moduleWarnings[2].message;
}

TEST(Movements, AnIndexBeyondThemIsWarnedAtTheModuleInTheGrammar) {
  plant::PlantSpec spec;
  spec.path = "t.lsys";
  spec.text = "axiom: A\nA --> F @Ts(4,0.2) F\n";
  spec.steps = 1;
  spec.until = plant::Stage::kGeometry;
  spec.amendGrammar = [](lsys::Grammar& g, DiagnosticList&) {
    g.movements = {Tropism(Vec3(0, -1, 0), 0), Torque(Vec3(0, 1, 0), 0)};
  };
  plant::PlantResult r = plant::BuildPlant(spec);
  ASSERT_TRUE(r.plant.has_value()) << r.diagnostics.FormatAll();
  const std::string all = r.diagnostics.FormatAll();
  EXPECT_NE(all.find("t.lsys:2:9: warning: '@Ts(4,0.2)' (module 2) names tropism 4, but the "
                     "view file defines 2"),
            std::string::npos)
      << all;
}

}  // namespace
}  // namespace sylva::turtle
