// Built-in environments (plant/environment.h): a shape for pruning and a
// light grid by shadow propagation, and how a grammar chooses one.
#include "plant/environment.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "plant/light_grid.h"
#include "plant/plant.h"
#include "plant/plant_test_util.h"
#include "plant/shape_environment.h"

namespace sylva::plant {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string Errors(const std::string& text) {
  PlantSpec spec;
  spec.path = "t.lsys";
  spec.text = text;
  spec.until = Stage::kGrammar;  // what `sylva check` runs
  PlantResult r = BuildPlant(spec);
  EXPECT_FALSE(r.plant) << text;
  return r.diagnostics.FormatAll();
}

TEST(ShapeEnvironment, ContainsEachShapeAndNoNaN) {
  const ShapeDef box{ShapeDef::Kind::kBox, Vec3(-1, 0, -2), Vec3(1, 3, 2)};
  const ShapeDef ball{ShapeDef::Kind::kSphere, Vec3(0, 2, 0), Vec3(1, 1, 1)};
  const ShapeDef egg{ShapeDef::Kind::kEllipsoid, Vec3(0, 2, 0), Vec3(1, 2, 3)};
  EXPECT_TRUE(Contains(box, Vec3(1, 3, 2)));  // a corner: the boundary is inside
  EXPECT_FALSE(Contains(box, Vec3(1.01, 1, 0)));
  EXPECT_FALSE(Contains(box, Vec3(0, -0.01, 0)));
  EXPECT_FALSE(Contains(box, Vec3(0, 1, 2.01)));
  EXPECT_TRUE(Contains(ball, Vec3(0, 2.99, 0)));
  EXPECT_FALSE(Contains(ball, Vec3(0.8, 2.8, 0)));  // 0.8^2 + 0.8^2 = 1.28
  EXPECT_TRUE(Contains(egg, Vec3(0, 3.9, 0)));
  EXPECT_TRUE(Contains(egg, Vec3(0, 2, 2.9)));
  EXPECT_FALSE(Contains(egg, Vec3(1.1, 2, 0)));
  for (const ShapeDef& s : {box, ball, egg}) {
    for (int c = 0; c < 3; ++c) {
      Vec3 p(0, 2, 0);
      EXPECT_TRUE(Contains(s, p));
      p[c] = kNaN;
      EXPECT_FALSE(Contains(s, p)) << "NaN in component " << c << ", shape " << int(s.kind);
    }
  }
}

TEST(ShapeEnvironment, HedgeTipsStopOutsideTheShape) {
  // A tip grows while its ?E reads 1: inside the box up to y = 2.5. The
  // side branches start at x = -0.75 and stop past x = -1 (after one F);
  // the third starts at y = 3, outside, and never grows.
  auto p = testing::PlantFromText(
      "environment: shape box(-1,0,-1, 1,2.5,1)\n"
      "axiom: A ?E(1)\n"
      "A > ?E(e) : e > 0 --> F(1) [ +(90) f(0.75) B ?E(1) ] A\n"
      "B > ?E(e) : e > 0 --> F(0.5) B\n",
      6, Stage::kWord);
  ASSERT_TRUE(p);
  EXPECT_EQ(lsys::FormatWord(p->word, p->grammar.symbols),
            "F(1)[+(90)f(0.75)F(0.5)B?E(0)]F(1)[+(90)f(0.75)F(0.5)B?E(0)]F(1)[+(90)f(0.75)B?E(0)]"
            "A?E(0)");
}

TEST(LightGrid, ALoneBudIsInFullLight) {
  LightGrid grid(LightDef{});
  const Vec3 bud(0.3, 2.2, -0.4);
  ASSERT_TRUE(grid.Update({&bud, 1}).ok());
  EXPECT_DOUBLE_EQ(grid.Exposure(bud), 1.0);
}

TEST(LightGrid, ShadowFallsOffByLayerInsideThePyramid) {
  LightDef def;
  def.cell = 1;
  def.depth = 3;
  def.shadow = 0.2;
  def.falloff = 2;
  LightGrid grid(def);
  // Voxels (cell 1): C (0,5,0), B1 (0,4,0), B2 (2,3,-2), B3 (3,3,0), B4 (0,1,0).
  const std::vector<Vec3> buds = {
      Vec3(0.5, 5.5, 0.5),   // C
      Vec3(0.5, 4.5, 0.5),   // B1: 1 under C: a/b = 0.1
      Vec3(2.5, 3.5, -1.5),  // B2: 2 under C, 2 aside on x and z (the pyramid's corner): a/b^2
      Vec3(3.5, 3.5, 0.5),   // B3: 2 under C but 3 aside: outside every pyramid
      Vec3(0.5, 1.5, 0.5),   // B4: 4 under C (past depth 3); 3 under B1, 2 under B2's corner
  };
  ASSERT_TRUE(grid.Update(buds).ok());
  const double want[] = {1.0, 0.9, 0.95, 1.0, 1.0 - 0.2 / 8 - 0.2 / 4};
  for (size_t i = 0; i < buds.size(); ++i) {
    EXPECT_NEAR(grid.Exposure(buds[i]), want[i], 1e-6)
        << "bud " << i << " measured " << grid.Exposure(buds[i]);
  }
  // Away from every bud: full light; a NaN position: outside the grid.
  EXPECT_DOUBLE_EQ(grid.Exposure(Vec3(-2.5, 0.5, 0.5)), 1.0);
  for (int c = 0; c < 3; ++c) {
    Vec3 q = buds[1];
    q[c] = kNaN;
    EXPECT_DOUBLE_EQ(grid.Exposure(q), 1.0) << "NaN in component " << c;
  }
}

TEST(LightGrid, AWallIsDarkInsideAndShadesItsSide) {
  LightDef def;
  def.cell = 1;
  def.depth = 5;
  def.shadow = 0.2;
  def.falloff = 2;
  def.walls.push_back(LightBox{Vec3(2, 0, -10), Vec3(2.9, 20, 10), 1.0});  // voxels x = 2
  LightGrid grid(def);
  const std::vector<Vec3> buds = {Vec3(-2.5, 5.5, 0.5), Vec3(-20.5, 5.5, 0.5)};
  ASSERT_TRUE(grid.Update(buds).ok());
  EXPECT_DOUBLE_EQ(grid.Exposure(Vec3(2.5, 5.5, 0.5)), 0.0) << "inside the wall";
  // 5 voxels from the wall: only the layer 5 above reaches it, 11 voxels
  // across z, each 1/2^5.
  EXPECT_NEAR(grid.Exposure(buds[0]), 1.0 - 11.0 / 32, 1e-6)
      << "measured " << grid.Exposure(buds[0]);
  EXPECT_NEAR(grid.Exposure(buds[1]), 1.0, 1e-6) << "far from the wall";
  // Nearer the wall it is darker: 4 voxels away, layers 4 and 5.
  const Vec3 nearer(-1.5, 5.5, 0.5);
  ASSERT_TRUE(grid.Update({&nearer, 1}).ok());
  EXPECT_NEAR(grid.Exposure(nearer), std::max(0.0, 1.0 - 9.0 / 16 - 11.0 / 32), 1e-6)
      << "measured " << grid.Exposure(nearer);
  // Without its own shadow a box casts the buds' (0.2 a voxel).
  def.walls[0].shadow = -1;
  LightGrid weaker(def);
  ASSERT_TRUE(weaker.Update({&nearer, 1}).ok());
  EXPECT_NEAR(weaker.Exposure(nearer), 1.0 - 0.2 * (9.0 / 16 + 11.0 / 32), 1e-6)
      << "measured " << weaker.Exposure(nearer);
}

TEST(LightGrid, TooManyVoxelsIsAnErrorNotAnAllocation) {
  LightDef def;
  def.cell = 0.001;
  LightGrid grid(def);
  const std::vector<Vec3> buds = {Vec3(0, 0, 0), Vec3(100, 100, 100)};
  Status s = grid.Update(buds);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("more than the limit"), std::string::npos) << s.error().message;
  EXPECT_EQ(grid.cellCount(), 0u);
  const std::vector<Vec3> bad = {Vec3(0, kNaN, 0)};
  EXPECT_FALSE(grid.Update(bad).ok());
  // A thin grid (one bud) beside a wall 10^6 voxels tall, at depth 64: its
  // voxels times the pyramid's 366,145 is far past the work limit, said
  // before any of it is done.
  LightDef deep;
  deep.cell = 1;
  deep.depth = 64;
  deep.walls.push_back(LightBox{Vec3(-50, -1e6, -50), Vec3(50, 1e6, 50)});
  LightGrid wall(deep);
  const Vec3 bud(0, 0, 0);
  Status w = wall.Update({&bud, 1});
  ASSERT_FALSE(w.ok());
  EXPECT_NE(w.error().message.find("voxel updates a step, more than the limit"), std::string::npos)
      << w.error().message;
}

TEST(LightEnvironment, TheUpperOfTwoPlantsTakesTheLight) {
  // Two plants sharing one environment: plant 1's bud under plant 0's.
  LightDef def;
  def.cell = 1;
  LightEnvironment env(def);
  double p0[1] = {-1}, p1[1] = {-1};
  std::vector<EnvQuery> q = {EnvQuery{Vec3(0.5, 3.5, 0.5), {}, {p0, 1}, 0},
                             EnvQuery{Vec3(0.5, 2.5, 0.5), {}, {p1, 1}, 1}};
  ASSERT_TRUE(env.Answer(q).ok());
  EXPECT_NEAR(p0[0], 1.0, 1e-6);
  EXPECT_NEAR(p1[0], 0.9, 1e-6) << "measured " << p1[0];
}

TEST(Environment, GrammarChoosesItAndErrorsHaveAPosition) {
  EXPECT_NE(Errors("environment: water level=3\naxiom: A ?E(1)\n")
                .find("t.lsys:1:14: error: unknown environment 'water': Sylva has 'shape', 'light' "
                      "and 'terrain'"),
            std::string::npos);
  EXPECT_NE(Errors("environment: shape cube(0,0,0,1)\naxiom: A\n")
                .find("t.lsys:1:20: error: unknown shape 'cube'"),
            std::string::npos);
  EXPECT_NE(Errors("environment: shape box(0,0,0,1)\naxiom: A\n")
                .find("t.lsys:1:20: error: 'box' takes 6 finite numbers; it has 4"),
            std::string::npos);
  EXPECT_NE(Errors("environment: shape sphere(0,0,0,-1)\naxiom: A\n")
                .find("t.lsys:1:20: error: the sphere's radius must be positive"),
            std::string::npos);
  EXPECT_NE(Errors("environment: shape ellipsoid(0,0,0,1,0,1)\naxiom: A\n")
                .find("radii must be positive"),
            std::string::npos);
  EXPECT_NE(Errors("environment: shape\naxiom: A\n").find("takes one shape"), std::string::npos);
  EXPECT_NE(Errors("environment: light cell=1 colour=2\naxiom: A\n")
                .find("t.lsys:1:27: error: unknown key 'colour'"),
            std::string::npos);
  EXPECT_NE(Errors("environment: light cell=0\naxiom: A\n").find("t.lsys:1:20: error: cell"),
            std::string::npos);
  EXPECT_NE(Errors("environment: light depth=2.5\naxiom: A\n").find("depth must be a whole"),
            std::string::npos);
  EXPECT_NE(Errors("environment: light falloff=0.5\naxiom: A\n").find("falloff must be"),
            std::string::npos);
  EXPECT_NE(Errors("environment: light sphere(0,0,0,1)\naxiom: A\n")
                .find("t.lsys:1:20: error: unknown obstacle 'sphere'"),
            std::string::npos);
  EXPECT_NE(Errors("environment: light sunny\naxiom: A\n").find("unknown word 'sunny'"),
            std::string::npos);
  EXPECT_NE(Errors("environment: terrain slope=2\naxiom: A\n")
                .find("t.lsys:1:22: error: 'environment: terrain' takes nothing after it"),
            std::string::npos);
}

TEST(Environment, LightGrammarDerivesWithItsAnswers) {
  // A tip under another tip's shadow reads less than 1.
  auto p = testing::PlantFromText(
      "environment: light cell=1 depth=3 shadow=0.2 falloff=2\n"
      "axiom: [ f(5.5) ?E(0) ] [ f(4.5) ?E(0) ]\n",
      0, Stage::kWord);
  ASSERT_TRUE(p);
  EXPECT_EQ(lsys::FormatWord(p->word, p->grammar.symbols), "[f(5.5)?E(1)][f(4.5)?E(0.9)]");
}

TEST(GroundEnvironment, AnswersHeightAndNormalUnderTheQuery) {
  // The ground y = 0.5 x, tilted: normal (-0.5, 1, 0) / |..|.
  PlantSpec spec;
  spec.path = "t.lsys";
  spec.text =
      "environment: terrain\n"
      "axiom: [ +(90) f(2) ?E(9,9,9,9) ] [ -(90) f(4) ?E(9) ] ?E(9,9)\n";
  spec.until = Stage::kWord;
  spec.steps = 0;
  const double k = 1 / std::sqrt(1.25);
  spec.ground = Ground{[](double x, double) { return 0.5 * x; },
                       [k](double, double) { return Vec3(-0.5 * k, k, 0); }};
  auto p = testing::BuildOrFail(spec);
  ASSERT_TRUE(p);
  // +(90) goes to x = -2: h = -1; -(90) to x = 4: h = 2; at the origin 0,
  // and with 2 parameters the second keeps its value.
  EXPECT_EQ(lsys::FormatWord(p->word, p->grammar.symbols),
            "[+(90)f(2)?E(-1,-0.447214,0.894427,0)][-(90)f(4)?E(2)]?E(0,9)");
  // Without a ground given: the plane y = 0.
  spec.ground.reset();
  auto flat = testing::BuildOrFail(spec);
  ASSERT_TRUE(flat);
  EXPECT_EQ(lsys::FormatWord(flat->word, flat->grammar.symbols),
            "[+(90)f(2)?E(0,0,1,0)][-(90)f(4)?E(0)]?E(0,9)");
}

// Mean x of the segments' ends, and the reach of the drawing on each side
// of the trunk at x0.
struct Spread {
  double meanX = 0, left = 0, right = 0;
};
Spread SpreadOf(const Plant& p, double x0, double lo, double hi) {
  Spread s;
  size_t n = 0;
  for (const mesh::Segment& seg : p.geometry.segments) {
    const double x = seg.end.x();
    if (x < lo || x > hi) continue;
    s.meanX += x;
    ++n;
    s.left = std::max(s.left, x0 - x);
    s.right = std::max(s.right, x - x0);
  }
  if (n) s.meanX /= double(n);
  return s;
}

std::optional<Plant> Example(const std::string& name, std::map<std::string, double> defines = {}) {
  PlantSpec spec;
  spec.path = std::string(SYLVA_SOURCE_DIR) + "/grammars/environment/" + name;
  spec.until = Stage::kGeometry;
  spec.defines = std::move(defines);
  return testing::BuildOrFail(spec);
}

TEST(Environment, TreeByTheWallGrowsAwayFromIt) {
  // The wall is at x = 2.4; moved 100 away, the same tree is about
  // symmetric.
  auto by = Example("tree_by_wall.lsys");
  auto free = Example("tree_by_wall.lsys", {{"WX", 100}});
  ASSERT_TRUE(by && free);
  const Spread b = SpreadOf(*by, 0, -50, 50), f = SpreadOf(*free, 0, -50, 50);
  RecordProperty("mean_x_by_wall", std::to_string(b.meanX));
  RecordProperty("mean_x_free", std::to_string(f.meanX));
  RecordProperty("reach_away", std::to_string(b.left));
  RecordProperty("reach_toward", std::to_string(b.right));
  EXPECT_LT(b.meanX, f.meanX - 0.3) << "mean x by the wall " << b.meanX << ", free " << f.meanX;
  EXPECT_LT(b.right, 2.4) << "reach toward the wall " << b.right;
  EXPECT_GT(b.left, b.right + 1.0) << "reach away " << b.left << ", toward " << b.right;
}

TEST(Environment, TwoTreesSharingLightGrowApart) {
  // Trunks at x = -2 and 2: each reaches farther away from the other than
  // toward it; 100 apart they are about symmetric.
  auto near = Example("two_trees_light.lsys");
  ASSERT_TRUE(near);
  const Spread l = SpreadOf(*near, -2, -50, -0.0001), r = SpreadOf(*near, 2, 0.0001, 50);
  RecordProperty("left_mean_x", std::to_string(l.meanX));
  RecordProperty("right_mean_x", std::to_string(r.meanX));
  EXPECT_LT(l.meanX, -2.2) << "left tree's mean x " << l.meanX;
  EXPECT_GT(r.meanX, 2.2) << "right tree's mean x " << r.meanX;
  auto apart = Example("two_trees_light.lsys", {{"D", 50}});
  ASSERT_TRUE(apart);
  const Spread la = SpreadOf(*apart, -50, -100, -0.0001);
  RecordProperty("lone_mean_x", std::to_string(la.meanX));
  EXPECT_NEAR(la.meanX, -50, 0.3) << "a lone tree's mean x " << la.meanX;
}

}  // namespace
}  // namespace sylva::plant
