#include "turtle/interpreter.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <random>
#include <set>

#include "core/atomic_file.h"
#include "lsys/deriver.h"
#include "lsys/parser.h"
#include "plant/plant_test_util.h"
#include "turtle/vec_expect.h"

namespace sylva::turtle {
namespace {

struct Drawn {
  lsys::Grammar grammar;
  PlantGeometry geometry;
};

// Parses, derives (interpretation rules applied) and draws, through the
// plant library.
Drawn Draw(const std::string& text, int steps = -1, DrawOptions opt = {}) {
  Drawn d;
  auto p = testing::PlantFromText(text, steps, plant::Stage::kGeometry, opt);
  if (!p) return d;
  d.grammar = std::move(p->grammar);
  d.geometry = std::move(p->geometry);
  return d;
}

Frame FinalFrame(const std::string& axiom) {
  DrawOptions opt;
  opt.recordModules = true;
  Drawn d = Draw("axiom: " + axiom + "\n", 0, opt);
  return d.geometry.moduleFrame.back();
}

TEST(Turtle, ForwardThenTurnLeftEndsAtMinusOneOne) {
  Drawn d = Draw("axiom: F+F\n");
  ASSERT_EQ(d.geometry.segments.size(), 2u);
  EXPECT_VEC_NEAR(d.geometry.segments[0].end, Vec3(0, 1, 0), 1e-12);
  EXPECT_VEC_NEAR(d.geometry.segments[1].end, Vec3(-1, 1, 0), 1e-12);
}

TEST(Turtle, EachRotationMovesTowardItsVector) {
  // Initial frame: H = (0,1,0), L = (-1,0,0), U = (0,0,-1).
  EXPECT_VEC_NEAR(FinalFrame("-").heading, Vec3(1, 0, 0), 1e-12);
  EXPECT_VEC_NEAR(FinalFrame("&").heading, Vec3(0, 0, -1), 1e-12);
  EXPECT_VEC_NEAR(FinalFrame("&").up, Vec3(0, -1, 0), 1e-12);
  EXPECT_VEC_NEAR(FinalFrame("^").heading, Vec3(0, 0, 1), 1e-12);
  EXPECT_VEC_NEAR(FinalFrame("/").left, Vec3(0, 0, -1), 1e-12);
  EXPECT_VEC_NEAR(FinalFrame("/").up, Vec3(1, 0, 0), 1e-12);
  EXPECT_VEC_NEAR(FinalFrame("\\").left, Vec3(0, 0, 1), 1e-12);
  EXPECT_VEC_NEAR(FinalFrame("+(30)").heading, Vec3(-0.5, std::sqrt(3.0) / 2, 0), 1e-12);
}

TEST(Turtle, TurnAroundReversesHeadingAndLeft) {
  Frame f = FinalFrame("&(20)/(30)|");
  Frame g = FinalFrame("&(20)/(30)");
  EXPECT_VEC_NEAR(f.heading, Vec3(-g.heading), 1e-12);
  EXPECT_VEC_NEAR(f.left, Vec3(-g.left), 1e-12);
  EXPECT_VEC_NEAR(f.up, g.up, 1e-12);
}

TEST(Turtle, DollarMakesLeftHorizontal) {
  Frame before = FinalFrame("&(35)/(50)+(20)");
  Frame f = FinalFrame("&(35)/(50)+(20)$");
  EXPECT_VEC_NEAR(f.heading, before.heading, 1e-12);
  EXPECT_NEAR(f.left.y(), 0, 1e-12) << Str(f.left);
  EXPECT_NEAR(f.left.norm(), 1, 1e-12);
  EXPECT_VEC_NEAR(f.up, Vec3(f.left.cross(f.heading)), 1e-12);
  // Unchanged when H is vertical.
  Frame v = FinalFrame("/(30)$");
  EXPECT_VEC_NEAR(v.left, FinalFrame("/(30)").left, 1e-12);
}

TEST(Turtle, FrameStaysOrthonormalOverManyTurns) {
  std::string axiom;
  std::mt19937 rng(5);
  const char* turns = "+-&^/\\";
  for (int i = 0; i < 20000; ++i) {
    axiom += turns[rng() % 6];
    axiom += "(" + std::to_string(int(rng() % 170) + 3) + ".37)";
  }
  Frame f = FinalFrame(axiom);
  EXPECT_NEAR(f.heading.norm(), 1, 1e-12);
  EXPECT_NEAR(f.left.norm(), 1, 1e-12);
  EXPECT_NEAR(f.heading.dot(f.left), 0, 1e-12);
  EXPECT_VEC_NEAR(f.up, Vec3(f.left.cross(f.heading)), 1e-12);
}

TEST(Turtle, TropismBendsTowardTheVectorByTheAbopFormula) {
  // Heading (-1,0,0), T = (0,-1,0): |H x T| = 1, so H turns by e = 0.2 rad toward T.
  DrawOptions opt;
  opt.recordModules = true;
  Drawn d = Draw("tropism: 0 -1 0 0.2\naxiom: +F\n", 0, opt);
  Vec3 h = d.geometry.moduleFrame.back().heading;
  EXPECT_VEC_NEAR(h, Vec3(-std::cos(0.2), -std::sin(0.2), 0), 1e-12);
  // Parallel to T: no bend.
  Drawn up = Draw("tropism: 0 -1 0 0.2\naxiom: F\n", 0, opt);
  EXPECT_VEC_NEAR(up.geometry.moduleFrame.back().heading, Vec3(0, 1, 0), 1e-12);
}

TEST(Turtle, KochIslandClosesOnItself) {
  std::string text =
      *ReadFile(std::string(SYLVA_SOURCE_DIR) + "/grammars/abop/fig1_06_koch_island.lsys");
  DrawOptions opt;
  opt.recordModules = true;
  Drawn d = Draw(text, 2, opt);
  EXPECT_EQ(d.geometry.segments.size(), 4u * 64);
  EXPECT_VEC_NEAR(d.geometry.modulePosition.back(), Vec3(0, 0, 0), 1e-9);
  EXPECT_TRUE(d.geometry.planar);
}

TEST(Turtle, DragonCurveEndsAtDistanceTwoToTheHalfN) {
  std::string text =
      *ReadFile(std::string(SYLVA_SOURCE_DIR) + "/grammars/abop/fig1_10a_dragon_curve.lsys");
  DrawOptions opt;
  opt.recordModules = true;
  Drawn d = Draw(text, 10, opt);
  ASSERT_EQ(d.geometry.segments.size(), 1024u);
  // The end point is (1 + i)^10 = 32i times the first step, up to a reflection:
  // 32 units away, on a coordinate axis.
  Vec3 end = d.geometry.modulePosition.back();
  EXPECT_NEAR(end.norm(), 32, 1e-9) << Str(end);
  EXPECT_NEAR(std::min(std::abs(end.x()), std::abs(end.y())), 0, 1e-9) << Str(end);
}

TEST(Turtle, BranchesDepthsAndWidths) {
  Drawn d = Draw("width factor: 0.5\naxiom: !(2)F[!F[F]]'F\n");
  const auto& s = d.geometry.segments;
  ASSERT_EQ(s.size(), 4u);
  EXPECT_EQ(s[0].branch, 0u);
  EXPECT_EQ(s[1].branch, 1u);
  EXPECT_EQ(s[2].branch, 2u);
  EXPECT_EQ(s[3].branch, 0u);
  EXPECT_EQ(s[2].parent, 1u);
  EXPECT_EQ(s[1].parent, 0u);
  EXPECT_EQ(s[2].depth, 2);
  EXPECT_EQ(s[0].radiusStart, 1.0f);
  EXPECT_EQ(s[1].radiusStart, 0.5f);
  EXPECT_EQ(s[2].radiusStart, 0.5f);
  EXPECT_EQ(s[3].radiusStart, 1.0f);  // width restored by ]
  EXPECT_EQ(s[3].color, 1);
  EXPECT_VEC_NEAR(s[3].start, Vec3(0, 1, 0), 1e-12);
  EXPECT_EQ(d.geometry.branchCount, 3u);
}

TEST(Turtle, PolygonsCollectVerticesAndDrawNoSegments) {
  Drawn d = Draw("axiom: {.F+F+F+F}G\n");
  ASSERT_EQ(d.geometry.polygons.size(), 1u);
  const auto& v = d.geometry.polygons[0].vertices;
  ASSERT_EQ(v.size(), 4u);  // the closing vertex repeats the first and is dropped
  EXPECT_VEC_NEAR(v[1], Vec3(0, 1, 0), 1e-12);
  EXPECT_VEC_NEAR(v[2], Vec3(-1, 1, 0), 1e-12);
  EXPECT_EQ(d.geometry.segments.size(), 1u);  // only the G outside
}

TEST(Turtle, PolygonSpansBranchesAndGRecordsNoVertex) {
  Drawn d = Draw("axiom: {.[+G.]G.-G.}\n");
  ASSERT_EQ(d.geometry.polygons.size(), 1u);
  EXPECT_EQ(d.geometry.polygons[0].vertices.size(), 4u);
}

TEST(Turtle, DegeneratePolygonsAndStrayBracesAreWarnings) {
  Drawn d = Draw("axiom: {.F}}{F\n");
  EXPECT_EQ(d.geometry.polygons.size(), 0u);
  ASSERT_EQ(d.geometry.warnings.size(), 3u);
  EXPECT_EQ(d.geometry.warnings[0], "polygon at module 1 has 2 vertices; skipped");
  EXPECT_EQ(d.geometry.warnings[1], "unmatched '}' at module 5 ignored");
  EXPECT_EQ(d.geometry.warnings[2], "polygon opened at module 6 is never closed; skipped");
}

TEST(Turtle, UnmatchedCloseBracketIsIgnoredWithOneWarning) {
  // cpfg's interpret.c: "unmatched ] ignored". corpus3's dynamic4 writes
  // one `]` too many in a successor (a warning where the .l file has it).
  lsys::ParseResult r = lsys::ParseGrammarText("axiom: F]+F]F\n", "c.l");
  ASSERT_TRUE(r.grammar) << r.diagnostics.FormatAll();
  auto word = lsys::Derive(*r.grammar, lsys::DeriveOptions{.steps = 0});
  ASSERT_TRUE(word);
  auto g = Interpret(word->word, r.grammar->symbols, TurtleDefFrom(*r.grammar));
  ASSERT_TRUE(g) << g.error().message;
  ASSERT_EQ(g->segments.size(), 3u);
  EXPECT_VEC_NEAR(g->segments[2].end, Vec3(-2, 1, 0), 1e-12);  // the turn is kept
  ASSERT_EQ(g->warnings.size(), 1u);
  EXPECT_EQ(g->warnings[0],
            "module 2 (]): a ']' with no '[' open; ignored, as cpfg's turtle does (and 1 more "
            "like it)");
}

TEST(Turtle, SurfacesAndSpheres) {
  Drawn d = Draw("axiom: F~leaf(2)!(3)@O@O(1)\n");
  ASSERT_EQ(d.geometry.surfaces.size(), 1u);
  EXPECT_EQ(d.geometry.surfaces[0].name, "leaf");
  EXPECT_VEC_NEAR(d.geometry.surfaces[0].scale, Vec3(2, 2, 2), 1e-12);
  EXPECT_VEC_NEAR(d.geometry.surfaces[0].position, Vec3(0, 1, 0), 1e-12);
  ASSERT_EQ(d.geometry.spheres.size(), 2u);
  EXPECT_EQ(d.geometry.spheres[0].radius, 1.5);
  EXPECT_EQ(d.geometry.spheres[1].radius, 0.5);
}

TEST(Turtle, StepAngleAndBounds) {
  Drawn d = Draw("step: 2\nangle: 45\naxiom: F-F&F\n");
  EXPECT_VEC_NEAR(d.geometry.segments[1].end, Vec3(std::sqrt(2.0), 2 + std::sqrt(2.0), 0), 1e-12);
  EXPECT_FALSE(d.geometry.planar);
  EXPECT_NEAR(d.geometry.boundsMin.z(), -std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(d.geometry.boundsMax.y(), 2 + std::sqrt(2.0) + 1, 1e-12);
}

TEST(Turtle, MonopodialTreeIsThreeDimensionalAndBounded) {
  std::string text =
      *ReadFile(std::string(SYLVA_SOURCE_DIR) + "/grammars/abop/fig2_06a_monopodial.lsys");
  Drawn d = Draw(text);
  // 2^10 - 1 internodes of lengths r1^k..., all F's of the derived word.
  EXPECT_EQ(d.geometry.segments.size(), 1023u);
  EXPECT_FALSE(d.geometry.planar);
  // The trunk: 1 + 0.9 + ... + 0.9^9 = (1 - 0.9^10)/0.1 = 6.5132, straight up.
  double trunk = (1 - std::pow(0.9, 10)) / 0.1;
  EXPECT_NEAR(d.geometry.boundsMax.y(), trunk, 1e-9);
}

}  // namespace
}  // namespace sylva::turtle

namespace sylva::turtle {
namespace {

TEST(Turtle, RedrawingIntoAnExistingGeometryGivesTheSameResult) {
  auto p = testing::PlantFromText("axiom: F[+F{.F+F+F}]~a@O F\n", -1, plant::Stage::kInterpreted);
  ASSERT_TRUE(p);
  TurtleDef def = TurtleDefFrom(p->grammar);
  auto fresh = Interpret(p->DrawnWord(), p->grammar.symbols, def);
  PlantGeometry kept;
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(InterpretInto(p->DrawnWord(), p->grammar.symbols, def, {}, kept).ok());
    EXPECT_EQ(kept.segments.size(), fresh->segments.size());
    EXPECT_EQ(kept.polygons.size(), 1u);
    EXPECT_EQ(kept.surfaces.size(), 1u);
    EXPECT_EQ(kept.spheres.size(), 1u);
    EXPECT_EQ(kept.segments.back().end, fresh->segments.back().end);
  }
}

}  // namespace
}  // namespace sylva::turtle

namespace sylva::turtle {
namespace {

TEST(Turtle, TropismMatchesTheExactRotationOverManySteps) {
  // 200 steps bending toward -Y: the heading approaches T; compare with a
  // reference computed with libm's sin and cos through Eigen's AngleAxis.
  DrawOptions opt;
  opt.recordModules = true;
  std::string axiom = "+(70)";
  for (int i = 0; i < 200; ++i) axiom += "F";
  auto p = testing::PlantFromText("tropism: 0.3 -1 0.2 0.35\naxiom: " + axiom + "\n", -1,
                                  plant::Stage::kGeometry, opt);
  ASSERT_TRUE(p);
  const PlantGeometry* g = &p->geometry;
  Vec3 h(-std::sin(70 * kDegToRad), std::cos(70 * kDegToRad), 0);
  const Vec3 t(0.3, -1, 0.2);
  for (int i = 0; i < 200; ++i) {
    Vec3 axis = h.cross(t);
    double n = axis.norm();
    if (n > 1e-12) h = Eigen::AngleAxisd(0.35 * n, axis / n) * h;
  }
  EXPECT_LT((g->moduleFrame.back().heading - h).norm(), 1e-12)
      << "got " << Str(g->moduleFrame.back().heading) << " want " << Str(h);
}

}  // namespace
}  // namespace sylva::turtle

namespace sylva::turtle {
namespace {

// `!(1e300)F` and friends were written to glTF with exit 0 (109 validator
// errors). Every number that reaches the mesh is checked, and the error
// names the module.
TEST(Turtle, OutOfRangeGeometryIsAnErrorNamingTheModule) {
  struct Case {
    const char* axiom;
    const char* want;
  };
  const Case cases[] = {
      {"!(1e300)F", "module 2 (F) gives a segment width"},
      {"F(1e308)F(1e308)", "module 1 (F(1e+308)) gives a segment end"},
      {"F(1)+(90)F(1e16)", "module 3 (F(1e+16)) gives a segment end"},
      {"~leaf(1e300)", "module 1 (~leaf(1e+300)) gives a surface placement"},
      {"@O(1e300)", "module 1 (@O(1e+300)) gives a sphere"},
      {"F(1e10){.F(1e16).F(1)}", "module 2 ({) gives a polygon vertex"},
      {"&(90)F(1e16)", "module 2 (F(1e+16)) gives a segment end"},  // the bad component is z
  };
  for (const Case& c : cases) {
    auto p = testing::PlantFromText(std::string("axiom: ") + c.axiom + "\n", -1,
                                    plant::Stage::kInterpreted);
    ASSERT_TRUE(p);
    auto g = Interpret(p->DrawnWord(), p->grammar.symbols, TurtleDefFrom(p->grammar));
    ASSERT_FALSE(g.ok()) << c.axiom << " was accepted";
    EXPECT_NE(g.error().message.find(c.want), std::string::npos)
        << c.axiom << ": " << g.error().message;
  }
  // Large but representable is fine.
  auto p = testing::PlantFromText("axiom: F(1e14)!(1e10)F\n", -1, plant::Stage::kGeometry);
  EXPECT_TRUE(p);
  // The error is located where the grammar first writes the module's name.
  auto q = testing::PlantFromText("axiom: A\nA --> B F(1e308) F(1e308)\n", 1,
                                  plant::Stage::kInterpreted);
  ASSERT_TRUE(q);
  auto g = Interpret(q->DrawnWord(), q->grammar.symbols, TurtleDefFrom(q->grammar));
  ASSERT_FALSE(g.ok());
  EXPECT_EQ(std::to_string(g.error().loc.line) + ":" + std::to_string(g.error().loc.column), "2:9")
      << g.error().Format();
  EXPECT_NE(g.error().message.find("module 2 (F(1e+308)) gives a segment end"), std::string::npos)
      << g.error().message;
  EXPECT_NE(g.error().Format().find("2 | A --> B F(1e308) F(1e308)"), std::string::npos)
      << g.error().Format();
}

TEST(Turtle, SurfaceWithThreeScalesScalesEachAxis) {
  Drawn d = Draw("axiom: ~leaf(1,2,3) ~leaf(4) ~leaf(5,6) ~leaf\n");
  ASSERT_EQ(d.geometry.surfaces.size(), 4u);
  EXPECT_VEC_NEAR(d.geometry.surfaces[0].scale, Vec3(1, 2, 3), 1e-12);
  EXPECT_VEC_NEAR(d.geometry.surfaces[1].scale, Vec3(4, 4, 4), 1e-12);
  EXPECT_VEC_NEAR(d.geometry.surfaces[2].scale, Vec3(5, 5, 5), 1e-12);  // warned: first only
  EXPECT_VEC_NEAR(d.geometry.surfaces[3].scale, Vec3(1, 1, 1), 1e-12);
}

TEST(Turtle, SurfaceWithThreeScalesMeshesStretchedAlongHeading) {
  // The bundled leaf is 1 long along its y (the heading): (1, 3, 1) makes
  // it 3 long, and no wider.
  auto flat = testing::PlantFromText("axiom: ~leaf(1)\n", -1, plant::Stage::kMesh);
  auto tall = testing::PlantFromText("axiom: ~leaf(1,3,1)\n", -1, plant::Stage::kMesh);
  ASSERT_TRUE(flat && tall);
  auto extent = [](const mesh::TriangleMesh& m) {
    mesh::Vec3f lo = m.positions[0], hi = m.positions[0];
    for (const auto& p : m.positions) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    return (hi - lo).cast<double>().eval();
  };
  const Vec3 a = extent(flat->mesh), b = extent(tall->mesh);
  EXPECT_NEAR(b.y(), 3 * a.y(), 1e-5) << Str(a) << " " << Str(b);
  EXPECT_NEAR(b.x(), a.x(), 1e-6) << Str(a) << " " << Str(b);
  EXPECT_NEAR(b.z(), a.z(), 1e-6) << Str(a) << " " << Str(b);
}

TEST(Turtle, MoveToSetsThePositionWithoutDrawing) {
  Drawn d = Draw("axiom: F @M(3,4,5) F\n");
  ASSERT_EQ(d.geometry.segments.size(), 2u);
  EXPECT_VEC_NEAR(d.geometry.segments[1].start, Vec3(3, 4, 5), 1e-12);
  EXPECT_VEC_NEAR(d.geometry.segments[1].end, Vec3(3, 5, 5), 1e-12);
}

TEST(Turtle, CpfgColourIndexUpDownAndSet) {
  // ; up, , down (never below 0), ;(n) and ,(n) set; ' is ; as before.
  Drawn d = Draw("axiom: ;F;(5)F,F,(2)F,,,F'F\n");
  ASSERT_EQ(d.geometry.segments.size(), 6u);
  const int want[] = {1, 5, 4, 2, 0, 1};
  for (size_t i = 0; i < 6; ++i)
    EXPECT_EQ(d.geometry.segments[i].color, want[i]) << "segment " << i;
}

TEST(Turtle, WidthDownAndUpByTheFactor) {
  // Without `width increment:`, ! multiplies by the width factor and #
  // divides by it; !(w) and #(w) set.
  Drawn d = Draw("width: 2\nwidth factor: 0.5\naxiom: !F#F#F#(3)F!(4)F\n");
  ASSERT_EQ(d.geometry.segments.size(), 5u);
  const double want[] = {1, 2, 4, 3, 4};
  for (size_t i = 0; i < 5; ++i)
    EXPECT_NEAR(d.geometry.segments[i].radiusStart, want[i] / 2, 1e-6) << "segment " << i;
}

TEST(Turtle, WidthDownAndUpByTheIncrementAsCpfg) {
  Drawn d = Draw("width: 1\nwidth increment: 0.25\naxiom: !F#F#F!(0.1)F!F#(2)F\n");
  ASSERT_EQ(d.geometry.segments.size(), 6u);
  const double want[] = {0.75, 1, 1.25, 0.1, 0, 2};  // never below 0
  for (size_t i = 0; i < 6; ++i)
    EXPECT_NEAR(d.geometry.segments[i].radiusStart, want[i] / 2, 1e-6) << "segment " << i;
}

// Newell's normal of a polygon, unit length.
Vec3 NewellNormal(const std::vector<Vec3>& v) {
  Vec3 n(0, 0, 0);
  for (size_t i = 0; i < v.size(); ++i) n += v[i].cross(v[(i + 1) % v.size()]);
  return n.normalized();
}

TEST(Turtle, DiscLiesInTheHeadingLeftPlaneFacingMinusUp) {
  Drawn d = Draw("axiom: F @o(2)\n");
  ASSERT_EQ(d.geometry.polygons.size(), 1u);
  const auto& v = d.geometry.polygons[0].vertices;
  ASSERT_EQ(v.size(), 24u);
  for (const Vec3& p : v) {
    EXPECT_NEAR((p - Vec3(0, 1, 0)).norm(), 1.0, 1e-12) << Str(p);
    EXPECT_NEAR(p.z(), 0.0, 1e-12) << Str(p);  // the plane of H and L
  }
  EXPECT_VEC_NEAR(NewellNormal(v), Vec3(0, 0, 1), 1e-12);  // -U
  EXPECT_TRUE(d.geometry.segments.size() == 1u);
}

TEST(Turtle, DiscFacesTheScreenWhateverTheTurtlesFrame) {
  // cpfg's @o is a 2D circle (irisGL.c iGlCircle2D): in the world's xy
  // plane even after the turtle pitched and rolled.
  Drawn d = Draw("axiom: F &(60) /(35) F @o(2)\n");
  ASSERT_EQ(d.geometry.polygons.size(), 1u);
  const auto& v = d.geometry.polygons[0].vertices;
  const Vec3 centre = d.geometry.segments.back().end;
  for (const Vec3& p : v) {
    EXPECT_NEAR((p - centre).norm(), 1.0, 1e-12) << Str(p);
    EXPECT_NEAR(p.z(), centre.z(), 1e-12) << Str(p);
  }
  EXPECT_VEC_NEAR(NewellNormal(v), Vec3(0, 0, 1), 1e-12);
}

TEST(Turtle, CircleLiesInTheHeadingLeftPlaneWithTheWidthAsDefaultDiameter) {
  // cpfg's @c (irisGL.c iGlCircle3D) maps its circle's x, y, z to the
  // turtle's L, H, U: it lies in the plane of H and L, facing U. After
  // &(90) H = (0,0,-1), L = (-1,0,0), U = (0,-1,0): the plane y = 1.
  Drawn d = Draw("width: 0.4\naxiom: F &(90) @c\n");
  ASSERT_EQ(d.geometry.polygons.size(), 1u);
  const auto& v = d.geometry.polygons[0].vertices;
  ASSERT_EQ(v.size(), 24u);
  for (const Vec3& p : v) {
    EXPECT_NEAR((p - Vec3(0, 1, 0)).norm(), 0.2, 1e-12) << Str(p);
    EXPECT_NEAR(p.y(), 1.0, 1e-12) << Str(p);
  }
  EXPECT_VEC_NEAR(NewellNormal(v), Vec3(0, -1, 0), 1e-12);  // U
}

TEST(Turtle, RollToVerticalIsDollar) {
  const Frame a = FinalFrame("&(30)/(40)+(20)@v");
  const Frame b = FinalFrame("&(30)/(40)+(20)$");
  EXPECT_VEC_NEAR(a.heading, b.heading, 1e-15);
  EXPECT_VEC_NEAR(a.left, b.left, 1e-15);
  EXPECT_VEC_NEAR(a.up, b.up, 1e-15);
  EXPECT_NEAR(a.left.y(), 0.0, 1e-15);  // L horizontal
  EXPECT_NEAR(a.left.dot(a.heading), 0.0, 1e-15);
}

TEST(Turtle, GeneralizedCylinderAlongALineIsEvenlyCutAndTapers) {
  // @Gt(1): tangents as long as the chord, so a straight piece is cut evenly.
  Drawn d = Draw("axiom: !(1) @Gt(1) @Gs f(3) !(2) @Ge(6)\n");
  ASSERT_EQ(d.geometry.segments.size(), 6u);
  for (size_t k = 0; k < 6; ++k) {
    const Segment& s = d.geometry.segments[k];
    EXPECT_VEC_NEAR(s.end, Vec3(0, 0.5 * double(k + 1), 0), 1e-12);
    EXPECT_NEAR(s.radiusEnd, (1 + double(k + 1) / 6) / 2, 1e-6) << "segment " << k;
    EXPECT_EQ(s.branch, d.geometry.segments[0].branch);
  }
}

TEST(Turtle, ForwardInsideAGeneralizedCylinderDrawsItsSegmentAsCpfgDoes) {
  // cpfg's interpret.c draws every F (StartNode, EndNode) whatever @Gs
  // says; start_spline only keeps F and f from adding control points. So
  // `@Gs F @Gc F @Ge` is the tube through the control points and the two F
  // segments beside it, each with the width the turtle has at its F; f and
  // the turns draw nothing of their own. Word: 0 !(0.4), 1 @Gs, 2 F,
  // 3 @Gc(2), 4 !(0.8), 5 -(90), 6 F(2), 7 f, 8 @Ge(2).
  Drawn d = Draw("axiom: !(0.4) @Gs F @Gc(2) !(0.8) -(90) F(2) f @Ge(2)\n");
  const auto& s = d.geometry.segments;
  ASSERT_EQ(s.size(), 1u + 2u + 1u + 2u) << "two F segments and two pieces of 2 rings";
  std::vector<const Segment*> forward, tube;
  for (const Segment& x : s) (x.module == 2 || x.module == 6 ? forward : tube).push_back(&x);
  ASSERT_EQ(forward.size(), 2u);
  ASSERT_EQ(tube.size(), 4u);
  // The first F: from the origin up one step, radius 0.4 / 2.
  EXPECT_VEC_NEAR(forward[0]->start, Vec3(0, 0, 0), 1e-12);
  EXPECT_VEC_NEAR(forward[0]->end, Vec3(0, 1, 0), 1e-12);
  EXPECT_NEAR(forward[0]->radiusStart, 0.2, 1e-6) << forward[0]->radiusStart;
  EXPECT_NEAR(forward[0]->radiusEnd, 0.2, 1e-6) << forward[0]->radiusEnd;
  // The second, after the turn: along +x for 2, with the new width.
  EXPECT_VEC_NEAR(forward[1]->start, Vec3(0, 1, 0), 1e-12);
  EXPECT_VEC_NEAR(forward[1]->end, Vec3(2, 1, 0), 1e-12);
  EXPECT_NEAR((forward[1]->end - forward[1]->start).norm(), 2.0, 1e-12);
  EXPECT_NEAR(forward[1]->radiusStart, 0.4, 1e-6) << forward[1]->radiusStart;
  // The tube goes through the control points only (@Gs, @Gc, @Ge: f moved
  // the last one to x = 3), its radius from 0.2 to 0.4 on the last piece.
  EXPECT_VEC_NEAR(tube[1]->end, Vec3(0, 1, 0), 1e-12);
  EXPECT_NEAR(tube[1]->radiusEnd, 0.2, 1e-6) << tube[1]->radiusEnd;
  EXPECT_VEC_NEAR(tube[3]->end, Vec3(3, 1, 0), 1e-12);
  EXPECT_NEAR(tube[3]->radiusEnd, 0.4, 1e-6) << tube[3]->radiusEnd;
  // The same F outside a cylinder draws the same segment.
  Drawn plain = Draw("axiom: !(0.4) F\n");
  ASSERT_EQ(plain.geometry.segments.size(), 1u);
  EXPECT_EQ(plain.geometry.segments[0].radiusEnd, forward[0]->radiusEnd);
}

TEST(Turtle, GeneralizedCylinderFollowsTheHermiteCurveOfTheHeadings) {
  // From (0,0,0) heading +y to (1,1,0) heading +x: at t = 1/2 the cubic
  // Hermite curve with tangents 1.2 H |p1 - p0| (cpfg's default @Gt) is
  // (p0 + p1)/2 + 1.2 |p1 - p0| (H0 - H1)/8.
  Drawn d = Draw("axiom: @Gs f -(90) f @Gc(2) f @Ge\n");
  ASSERT_EQ(d.geometry.segments.size(), 2u + 8u);
  const double c = 1.2 * std::sqrt(2.0) / 8;
  EXPECT_VEC_NEAR(d.geometry.segments[0].end, Vec3(0.5 - c, 0.5 + c, 0), 1e-12);
  EXPECT_VEC_NEAR(d.geometry.segments[1].end, Vec3(1, 1, 0), 1e-12);
  EXPECT_VEC_NEAR(d.geometry.segments[9].end, Vec3(2, 1, 0), 1e-12);  // default: 8 pieces
}

TEST(Turtle, GeneralizedCylinderTangentFactorsOfGt) {
  // @Gt(a, b): b scales the tangent leaving a control point, a the one
  // arriving. Same curve as above with factors 2 (leaving the start) and
  // 0.5 (arriving at the end): midpoint offset |p1 - p0| (2 H0 - 0.5 H1)/8.
  Drawn d = Draw("axiom: @Gt(0.5,2) @Gs f -(90) f @Gc(2)\n");
  ASSERT_EQ(d.geometry.segments.size(), 2u);
  const double q = std::sqrt(2.0) / 8;
  EXPECT_VEC_NEAR(d.geometry.segments[0].end, Vec3(0.5 - 0.5 * q, 0.5 + 2 * q, 0), 1e-12);
  // One factor: both.
  Drawn e = Draw("axiom: @Gt(1) @Gs f -(90) f @Gc(2)\n");
  EXPECT_VEC_NEAR(e.geometry.segments[0].end, Vec3(0.5 - q, 0.5 + q, 0), 1e-12);
}

TEST(Turtle, GeneralizedCylinderRadiusTangentsOfGr) {
  // A straight piece of length 4 from width 2 (radius 1) to width 4
  // (radius 2), 2 rings. @Gr(90, 3, 0, 1): in the (t, radius) plane the
  // tangent leaving the start is (1, 0) and the one arriving at the end
  // (0, 3). Hermite from (0, 1) to (1, 2) at r = 1/2:
  // t = r + (3 - 2 - 0) r^2 + (-2 + 1 + 0) r^3 = 0.625,
  // radius = 1 + 0 r + (3 - 0 - 3) r^2 + (-2 + 0 + 3) r^3 = 1.125;
  // the ring sits where the position curve (tangents 1.2 x 4 along H) is
  // at t.
  auto along = [](double t) {
    const double t2 = t * t, t3 = t2 * t;
    return 4 * (3 * t2 - 2 * t3) + 4.8 * (t3 - 2 * t2 + t) + 4.8 * (t3 - t2);
  };
  Drawn d = Draw("axiom: !(2) @Gr(90, 3, 0, 1) @Gs f(4) !(4) @Ge(2)\n");
  ASSERT_EQ(d.geometry.segments.size(), 2u);
  EXPECT_VEC_NEAR(d.geometry.segments[0].end, Vec3(0, along(0.625), 0), 1e-12);
  EXPECT_NEAR(d.geometry.segments[0].radiusEnd, 1.125, 1e-6);
  EXPECT_NEAR(d.geometry.segments[1].radiusEnd, 2.0, 1e-6);
  // Without @Gr: t = r and the radius runs linearly.
  Drawn plain = Draw("axiom: !(2) @Gs f(4) !(4) @Ge(2)\n");
  EXPECT_VEC_NEAR(plain.geometry.segments[0].end, Vec3(0, along(0.5), 0), 1e-12);
  EXPECT_NEAR(plain.geometry.segments[0].radiusEnd, 1.5, 1e-6);
  // @Gr(1) multiplies the radius parts by the chord (4): (1, 0) and (0, 12):
  // radius = 1 + (3 - 12) / 4 + (-2 + 12) / 8 = 0; t is unchanged.
  Drawn s = Draw("axiom: !(2) @Gr(90, 3, 0, 1) @Gr(1) @Gs f(4) !(4) @Ge(2)\n");
  EXPECT_NEAR(s.geometry.segments[0].radiusEnd, 0.0, 1e-6);
  EXPECT_VEC_NEAR(s.geometry.segments[0].end, Vec3(0, along(0.625), 0), 1e-12);
}

TEST(Turtle, GeneralizedCylinderIsOneTubeAndBranchesDrawOnTheirOwn) {
  Drawn d = Draw("axiom: @Gs f [+F] f @Ge(4)\n");
  ASSERT_EQ(d.geometry.segments.size(), 5u);
  EXPECT_VEC_NEAR(d.geometry.segments[0].start, Vec3(0, 1, 0), 1e-12);  // the branch
  EXPECT_VEC_NEAR(d.geometry.segments[0].end, Vec3(-1, 1, 0), 1e-12);
  EXPECT_VEC_NEAR(d.geometry.segments[4].end, Vec3(0, 2, 0), 1e-12);
  // Tessellated as one tube: the same triangles as four steps of F.
  auto tube = testing::PlantFromText("axiom: @Gs f(2) @Ge(4)\n", -1, plant::Stage::kMesh);
  auto steps = testing::PlantFromText("axiom: F(.5)F(.5)F(.5)F(.5)\n", -1, plant::Stage::kMesh);
  ASSERT_TRUE(tube && steps);
  EXPECT_EQ(tube->mesh.triangleCount(), steps->mesh.triangleCount());
}

TEST(Turtle, BranchOfAGeneralizedCylinderContinuesItFromItsLastControlPoint) {
  // cpfg's `[` pushes the turtle with its open cylinder: the branch's first
  // @Gc draws the piece from the last control point before the `[` (here
  // @Gs at the origin), as vlab's cooksonia and horneophyton branch. Its
  // f only moves; `]` resumes the parent, whose @Ge ends at (0, 1, 0).
  Drawn d = Draw("axiom: @Gs [-(90) f(2) @Gc(4)] f @Ge(2)\n");
  ASSERT_EQ(d.geometry.segments.size(), 6u);
  EXPECT_VEC_NEAR(d.geometry.segments[0].start, Vec3(0, 0, 0), 1e-12);
  EXPECT_VEC_NEAR(d.geometry.segments[3].end, Vec3(2, 0, 0), 1e-12);  // the branch's @Gc
  EXPECT_NE(d.geometry.segments[0].branch, d.geometry.segments[4].branch);
  EXPECT_VEC_NEAR(d.geometry.segments[5].end, Vec3(0, 1, 0), 1e-12);
  // Nested branches inherit the start; a branch without @Gc draws its F.
  Drawn n = Draw("axiom: @Gs [[+ f @Ge(1)]] [-F] f @Ge(1)\n");
  ASSERT_EQ(n.geometry.segments.size(), 3u);
  EXPECT_VEC_NEAR(n.geometry.segments[0].start, Vec3(0, 0, 0), 1e-12);
  EXPECT_VEC_NEAR(n.geometry.segments[0].end, Vec3(-1, 0, 0), 1e-12);
  EXPECT_VEC_NEAR(n.geometry.segments[1].end, Vec3(1, 0, 0), 1e-12);  // [-F] as before
  EXPECT_VEC_NEAR(n.geometry.segments[2].end, Vec3(0, 1, 0), 1e-12);
}

TEST(Turtle, GeneralizedCylinderLeftOpenWarnsAndHugeRingCountsStopEarly) {
  Drawn d = Draw("axiom: @Gs f @Gc(2) f\n");
  EXPECT_EQ(d.geometry.segments.size(), 2u);
  ASSERT_EQ(d.geometry.warnings.size(), 1u);
  EXPECT_NE(d.geometry.warnings[0].find("never ended"), std::string::npos)
      << d.geometry.warnings[0];
  plant::PlantSpec spec;
  spec.path = "t.lsys";
  spec.text = "axiom: @Gs F @Ge(1e300)\n";
  spec.until = plant::Stage::kGeometry;
  plant::PlantResult r = plant::BuildPlant(spec);
  EXPECT_FALSE(r.plant.has_value());
  EXPECT_NE(r.diagnostics.FormatAll().find("more than the limit"), std::string::npos)
      << r.diagnostics.FormatAll();
}

TEST(Turtle, TropismElasticitySetRaisedAndLoweredPerBranch) {
  DrawOptions opt;
  opt.recordModules = true;
  auto end = [&](const std::string& text) {
    Drawn d = Draw(text, 0, opt);
    return d.geometry.modulePosition.empty() ? Vec3(1e9, 0, 0) : d.geometry.modulePosition.back();
  };
  const Vec3 want = end("tropism: 0 -1 0 0.2\naxiom: +(60) F F F\n");
  EXPECT_VEC_NEAR(end("tropism: 0 -1 0 0\naxiom: @Ts(1,0.2) +(60) F F F\n"), want, 1e-12);
  EXPECT_VEC_NEAR(end("tropism: 0 -1 0 0\naxiom: @Ti(1,0.1) @Ti(1,0.15) @Td(1,0.05) +(60) F F F\n"),
                  want, 1e-12);
  // The branch's change ends at its `]`.
  EXPECT_VEC_NEAR(end("tropism: 0 -1 0 0.2\naxiom: [@Ts(1)] +(60) F F F\n"), want, 1e-12);
  const Vec3 straight = end("axiom: +(60) F F F\n");
  EXPECT_VEC_NEAR(end("tropism: 0 -1 0 0.2\naxiom: @Ts(1) +(60) F F F\n"), straight, 1e-12);
  Drawn other = Draw("axiom: @Ts(2,1) F\n");
  ASSERT_EQ(other.geometry.warnings.size(), 1u);
  EXPECT_NE(other.geometry.warnings[0].find("tropism other than 1"), std::string::npos);
}

TEST(Turtle, UnderscoreSetsOrAddsTheElasticityAsCpfgDoes) {
  // cpfg interpret.c, '_': `_(e)` sets the elasticity to e, `_` adds the
  // view file's elasticity increment; the change ends at the branch's `]`.
  DrawOptions opt;
  opt.recordModules = true;
  auto end = [&](const std::string& text) {
    Drawn d = Draw(text, 0, opt);
    return d.geometry.modulePosition.empty() ? Vec3(1e9, 0, 0) : d.geometry.modulePosition.back();
  };
  const Vec3 want = end("tropism: 0 -1 0 0.2\naxiom: +(60) F F F\n");
  const Vec3 straight = end("axiom: +(60) F F F\n");
  EXPECT_GT((want - straight).norm(), 0.1) << Str(want);
  EXPECT_VEC_NEAR(end("tropism: 0 -1 0 0\naxiom: _(0.2) +(60) F F F\n"), want, 1e-12);
  EXPECT_VEC_NEAR(end("tropism: 0 -1 0 0.2\naxiom: [_(0)] +(60) F F F\n"), want, 1e-12);
  EXPECT_VEC_NEAR(end("tropism: 0 -1 0 0.2\naxiom: _(0) +(60) F F F\n"), straight, 1e-12);

  // `_` without a parameter: the increment, twice.
  auto p = testing::PlantFromText("tropism: 0 -1 0 0\naxiom: _ _ +(60) F F F\n", 0,
                                  plant::Stage::kInterpreted);
  ASSERT_TRUE(p.has_value());
  TurtleDef def = TurtleDefFrom(p->grammar);
  def.elasticityIncrement = 0.1;
  auto g = Interpret(p->DrawnWord(), p->grammar.symbols, def, opt);
  ASSERT_TRUE(g.ok());
  EXPECT_VEC_NEAR(g->modulePosition.back(), want, 1e-12);

  // With no tropism direction, cpfg's old tropism points up (0, 1, 0):
  // `_(0.2)` bends a turtle heading left-and-up toward +Y, as `tropism:
  // 0 1 0 0.2` does.
  EXPECT_VEC_NEAR(end("axiom: _(0.2) +(60) F F F\n"),
                  end("tropism: 0 1 0 0.2\naxiom: +(60) F F F\n"), 1e-12);
}

TEST(Turtle, TwistForceChangesNothing) {
  const Frame a = FinalFrame("&(30)/(40)F@Tf F");
  const Frame b = FinalFrame("&(30)/(40)F F");
  EXPECT_VEC_NEAR(a.heading, b.heading, 1e-300);
  EXPECT_VEC_NEAR(a.up, b.up, 1e-300);
}

}  // namespace
}  // namespace sylva::turtle

namespace sylva::turtle {
namespace {

// cpfg's sub-L-systems: ?(id, s) multiplies the step and the width by s
// until its `$` (interpret.c UpdateCurrentLsystem), and `$` does not roll.
TEST(Turtle, SubLsystemScalesStepAndWidthUntilItsEnd) {
  Drawn d = Draw(
      "lsystem: 1\naxiom: F?(2,0.5)F!(2)F?(2,0.5)F$$F\nendlsystem\n"
      "lsystem: 2\naxiom: F\nendlsystem\n",
      0);
  const auto& s = d.geometry.segments;
  ASSERT_EQ(s.size(), 5u);
  const double ends[5] = {1, 1.5, 2, 2.25, 3.25};
  // Width 1; at ?(2,0.5) 0.5; !(2) sets 2 x 0.5 = 1; at the nested
  // ?(2,0.5) 0.5 (scale 0.25); each $ divides by what its ?(..) multiplied.
  const double radii[5] = {0.5, 0.25, 0.5, 0.25, 1.0};
  for (int k = 0; k < 5; ++k) {
    EXPECT_VEC_NEAR(s[size_t(k)].end, Vec3(0, ends[k], 0), 1e-12);
    EXPECT_NEAR(s[size_t(k)].radiusStart, radii[k], 1e-7) << "segment " << k;
  }
}

TEST(Turtle, DollarEndsASubLsystemWithoutRolling) {
  DrawOptions opt;
  opt.recordModules = true;
  Drawn d = Draw(
      "lsystem: 1\naxiom: &(35)/(50)?(2)$F\nendlsystem\nlsystem: 2\naxiom: F\n"
      "endlsystem\n",
      0, opt);
  Drawn roll = Draw("axiom: &(35)/(50)$F\n", 0, opt);
  Drawn none = Draw("axiom: &(35)/(50)F\n", 0, opt);
  ASSERT_EQ(d.geometry.moduleFrame.size(), 5u);
  const Frame& f = d.geometry.moduleFrame.back();
  EXPECT_VEC_NEAR(f.left, none.geometry.moduleFrame.back().left, 1e-12);
  EXPECT_GT((f.left - roll.geometry.moduleFrame.back().left).norm(), 0.1);
}

}  // namespace
}  // namespace sylva::turtle

namespace sylva::turtle {
namespace {

// cpfg's `{(type, rings)` ... `}(type)` splines (vlab cpfg general.c): the
// turtle's position after each F and f is a control point.

TEST(TurtleSpline, OpenHermiteCurvePassesThroughThePositionsAfterEachF) {
  // Control points (0,1,0) heading +y, (-1,1,0) heading -x, (-1,0,0):
  // the `{` itself is not one. F still draws its own segment (cpfg).
  Drawn d = Draw("axiom: {(1) F +(90) F +(90) F }(1)\n");
  const auto& s = d.geometry.segments;
  ASSERT_EQ(s.size(), 3u + 2u * 4u);  // 3 F, 2 pieces of cpfg's default 4 rings
  // Order: F, F, piece 1 (2..5), F, piece 2 (7..10).
  EXPECT_VEC_NEAR(s[2].start, Vec3(0, 1, 0), 1e-12);
  EXPECT_VEC_NEAR(s[5].end, Vec3(-1, 1, 0), 1e-12);
  EXPECT_VEC_NEAR(s[10].end, Vec3(-1, 0, 0), 1e-12);
  // At t = 1/2 the Hermite curve with tangents 1.2 H |p1 - p0| is
  // (p0 + p1)/2 + 1.2 |p1 - p0| (H0 - H1)/8 = (-0.35, 1.15, 0).
  EXPECT_VEC_NEAR(s[3].end, Vec3(-0.35, 1.15, 0), 1e-12);
  EXPECT_EQ(s[2].branch, s[10].branch);
  EXPECT_NE(s[2].branch, s[0].branch);  // one tube of its own
  EXPECT_TRUE(d.geometry.warnings.empty()) << d.geometry.warnings[0];
  // With f only the spline is all that is drawn, and it becomes a tube
  // mesh within the turtle's bounds.
  auto mesh =
      testing::PlantFromText("axiom: {(1) f +(90) f +(90) f }(1)\n", -1, plant::Stage::kMesh);
  ASSERT_TRUE(mesh.has_value());
  EXPECT_EQ(mesh->geometry.segments.size(), 8u);
  EXPECT_GT(mesh->mesh.triangleCount(), 8u * 3u) << mesh->mesh.triangleCount();
  // Every vertex of the tube lies at its radius (0.5) from the curve.
  double worst = 0;
  for (const Vec3f& v : mesh->mesh.positions) {
    double nearest = 1e9;
    for (const Segment& sg : mesh->geometry.segments) {
      const Vec3 d = sg.end - sg.start, q = v.cast<double>() - sg.start;
      const double u = std::clamp(q.dot(d) / d.squaredNorm(), 0.0, 1.0);
      nearest = std::min(nearest, (q - d * u).norm());
    }
    worst = std::max(worst, nearest);
  }
  EXPECT_LT(worst, 0.5 + 1e-4) << "farthest vertex from the curve";
}

TEST(TurtleSpline, ClosedHermiteCurveReturnsToItsFirstPoint) {
  Drawn d = Draw("axiom: {(2) f +(90) f +(90) f +(90) f }(2)\n");
  const auto& s = d.geometry.segments;
  ASSERT_EQ(s.size(), 4u * 4u);  // 3 pieces, and the one that closes it
  EXPECT_VEC_NEAR(s[0].start, Vec3(0, 1, 0), 1e-12);
  EXPECT_VEC_NEAR(s[11].end, Vec3(0, 0, 0), 1e-12);
  EXPECT_VEC_NEAR(s[15].end, Vec3(0, 1, 0), 1e-12);
  // The closing piece leaves (0,0,0) with the heading of the last f, +x,
  // and arrives at (0,1,0) with the first point's, +y: at t = 1/2 it is
  // (0, 0.5, 0) + 1.2 (+x - +y)/8.
  const double c = 1.2 / 8.0;
  EXPECT_VEC_NEAR(s[13].end, Vec3(0 + c, 0.5 - c, 0), 1e-12);
}

TEST(TurtleSpline, ClosedSplineTubeIsJoinedEndToStartNotCapped) {
  // A closed spline's tube ends where it began: the tessellator joins the
  // two (the last ring is the first, bit for bit, normals too), so the
  // surface is a torus, Euler characteristic V - E + F = 0 once coincident
  // vertices are merged; capped ends would make it a sphere's 2. An open
  // spline keeps its caps.
  auto euler = [](const mesh::TriangleMesh& m) {
    std::map<std::array<float, 3>, uint32_t> id;
    std::vector<uint32_t> merged(m.positions.size());
    for (size_t i = 0; i < m.positions.size(); ++i) {
      const Vec3f& p = m.positions[i];
      merged[i] =
          id.emplace(std::array<float, 3>{p.x(), p.y(), p.z()}, uint32_t(id.size())).first->second;
    }
    std::set<std::pair<uint32_t, uint32_t>> edges;
    for (size_t t = 0; t + 2 < m.indices.size(); t += 3)
      for (int e = 0; e < 3; ++e) {
        const uint32_t a = merged[m.indices[t + e]], b = merged[m.indices[t + (e + 1) % 3]];
        edges.insert({std::min(a, b), std::max(a, b)});
      }
    return int64_t(id.size()) - int64_t(edges.size()) + int64_t(m.triangleCount());
  };
  for (const char* type : {"2", "4"}) {
    const std::string text =
        std::string("axiom: {(") + type + ") f +(90) f +(90) f +(90) f }(" + type + ")\n";
    auto p = testing::PlantFromText(text, -1, plant::Stage::kMesh);
    ASSERT_TRUE(p.has_value()) << text;
    ASSERT_EQ(p->geometry.loops.size(), 1u) << text;
    const mesh::TriangleMesh& m = p->mesh;
    const size_t segments = p->geometry.segments.size();  // 16: 4 pieces of 4 rings
    ASSERT_EQ(segments, 16u) << text;
    const size_t sides = m.triangleCount() / (2 * segments);
    ASSERT_GE(sides, 3u) << text;
    EXPECT_EQ(m.triangleCount(), 2 * sides * segments) << text << ": no cap triangles";
    const size_t ring = sides + 1;
    ASSERT_EQ(m.positions.size(), (segments + 1) * ring) << text;
    for (size_t j = 0; j < ring; ++j) {
      EXPECT_EQ(m.positions[j], m.positions[segments * ring + j]) << text << " vertex " << j;
      EXPECT_EQ(m.normals[j], m.normals[segments * ring + j]) << text << " vertex " << j;
    }
    EXPECT_EQ(euler(m), 0) << text;
  }
  auto open = testing::PlantFromText("axiom: {(1) f +(90) f +(90) f +(90) f }(1)\n", -1,
                                     plant::Stage::kMesh);
  ASSERT_TRUE(open.has_value());
  EXPECT_TRUE(open->geometry.loops.empty());
  EXPECT_EQ(euler(open->mesh), 2) << "an open spline's tube is capped at both ends";
}

TEST(TurtleSpline, BSplinesFollowTheUniformCubicBasis) {
  // Q0 (0,1,0), Q1 (-1,1,0), Q2 (-1,0,0), Q3 (0,0,0): an open B-spline
  // draws one piece, from (Q0 + 4 Q1 + Q2)/6 to (Q1 + 4 Q2 + Q3)/6, with
  // (Q0 + 23 Q1 + 23 Q2 + Q3)/48 at t = 1/2.
  Drawn d = Draw("axiom: {(3) f +(90) f +(90) f +(90) f }(3)\n");
  const auto& s = d.geometry.segments;
  ASSERT_EQ(s.size(), 4u);
  EXPECT_VEC_NEAR(s[0].start, Vec3(-5.0 / 6, 5.0 / 6, 0), 1e-12);
  EXPECT_VEC_NEAR(s[1].end, Vec3(-46.0 / 48, 24.0 / 48, 0), 1e-12);
  EXPECT_VEC_NEAR(s[3].end, Vec3(-5.0 / 6, 1.0 / 6, 0), 1e-12);
  // Closed (type 4): the 4 points make a loop of 4 pieces, symmetric about
  // the square's centre, each from (Q[i-1] + 4 Q[i] + Q[i+1])/6.
  Drawn c = Draw("axiom: {(4) f +(90) f +(90) f +(90) f }(4)\n");
  const auto& r = c.geometry.segments;
  ASSERT_EQ(r.size(), 16u);
  EXPECT_VEC_NEAR(r[15].end, r[0].start, 1e-12);
  EXPECT_VEC_NEAR(r[0].start, Vec3(-5.0 / 6, 5.0 / 6, 0), 1e-12);
  EXPECT_VEC_NEAR(r[12].start, Vec3(-1.0 / 6, 5.0 / 6, 0), 1e-12);
  for (const Segment& sg : r) {
    const double d2 = (sg.end - Vec3(-0.5, 0.5, 0)).norm();
    EXPECT_GT(d2, 0.45) << Str(sg.end);  // a rounded square inside the points
    EXPECT_LT(d2, 0.5 * std::sqrt(2.0)) << Str(sg.end);
  }
}

TEST(TurtleSpline, RingsOfTheSplineAndOfADot) {
  // {(1, 2): 2 segments a piece; `.(6)` adds a control point whose piece
  // has 6; G and g add none.
  Drawn d = Draw("axiom: {(1,2) f f g .(6) f }(1)\n");
  ASSERT_EQ(d.geometry.segments.size(), 2u + 6u + 2u);
  EXPECT_VEC_NEAR(d.geometry.segments[1].end, Vec3(0, 2, 0), 1e-12);
  EXPECT_VEC_NEAR(d.geometry.segments[7].end, Vec3(0, 3, 0), 1e-12);
  EXPECT_VEC_NEAR(d.geometry.segments[9].end, Vec3(0, 4, 0), 1e-12);
  // Widths and colours are the control points'.
  Drawn w = Draw("axiom: !(2) ;(3) {(1) f !(4) f }(1)\n");
  ASSERT_EQ(w.geometry.segments.size(), 4u);
  EXPECT_NEAR(w.geometry.segments[0].radiusStart, 1.0, 1e-6);
  EXPECT_NEAR(w.geometry.segments[3].radiusEnd, 2.0, 1e-6);
  EXPECT_EQ(w.geometry.segments[0].color, 3);
}

TEST(TurtleSpline, ABranchContinuesItsParentsSplineOnItsOwnCopy) {
  // cpfg's `[` pushes the open spline: the branch's first piece starts at
  // the parent's last control point (0,1,0); `]` resumes the parent there.
  Drawn d = Draw("axiom: {(1,1) f [-(90) f] f }(1)\n");
  const auto& s = d.geometry.segments;
  ASSERT_EQ(s.size(), 2u);
  EXPECT_VEC_NEAR(s[0].start, Vec3(0, 1, 0), 1e-12);
  EXPECT_VEC_NEAR(s[0].end, Vec3(1, 1, 0), 1e-12);
  EXPECT_VEC_NEAR(s[1].start, Vec3(0, 1, 0), 1e-12);
  EXPECT_VEC_NEAR(s[1].end, Vec3(0, 2, 0), 1e-12);
  EXPECT_NE(s[0].branch, s[1].branch);
  // `}(n)` inside a branch ends only the branch's spline.
  Drawn e = Draw("axiom: {(1,1) f [f }(1) f] f }(1)\n");
  EXPECT_EQ(e.geometry.segments.size(), 2u);
  EXPECT_TRUE(e.geometry.warnings.empty()) << e.geometry.warnings[0];
}

TEST(TurtleSpline, BadTypesStrayEndsFewPointsAndOpenSplinesAreWarnings) {
  auto warned = [](const std::string& axiom, const std::string& what) {
    Drawn d = Draw("axiom: " + axiom + "\n");
    for (const std::string& w : d.geometry.warnings)
      if (w.find(what) != std::string::npos) return d.geometry.segments.size();
    ADD_FAILURE() << axiom << ": no warning with '" << what << "'";
    return size_t(1000);
  };
  EXPECT_EQ(warned("{(5) f f f f", "type is 1 to 4"), 0u);
  EXPECT_EQ(warned("f }(1)", "ends no spline"), 0u);
  EXPECT_EQ(warned("{(3) f f f }(3)", "too few control points"), 0u);
  EXPECT_EQ(warned("{(1,1) f f f", "never ended"), 2u);
  EXPECT_EQ(warned("[{(1,1) f f] f", "never ended"), 1u);
  // {(0) and }(0) are a polygon.
  Drawn p = Draw("axiom: {(0) f +(90) f +(90) f }(0)\n");
  EXPECT_EQ(p.geometry.polygons.size(), 1u);
  EXPECT_TRUE(p.geometry.segments.empty());
}

TEST(TurtleSpline, HugeRingCountsStopBeforeAllocating) {
  plant::PlantSpec spec;
  spec.path = "t.lsys";
  spec.text = "axiom: {(1,1e300) f f }(1)\n";
  spec.until = plant::Stage::kGeometry;
  plant::PlantResult r = plant::BuildPlant(spec);
  EXPECT_FALSE(r.plant.has_value());
  EXPECT_NE(r.diagnostics.FormatAll().find("more than the limit"), std::string::npos)
      << r.diagnostics.FormatAll();
}

// cpfg's @R (blackbox.c, 'R'): set the heading, and the up vector.

TEST(TurtleSetHeading, HeadingIsNormalisedAndFMovesAlongIt) {
  DrawOptions opt;
  opt.recordModules = true;
  Drawn d = Draw("axiom: @R(1,0,0) F @R(3,4) F @R(0,0,0) F\n", 0, opt);
  const auto& pos = d.geometry.modulePosition;
  ASSERT_EQ(pos.size(), 6u);
  EXPECT_VEC_NEAR(pos[1], Vec3(1, 0, 0), 1e-12);
  EXPECT_VEC_NEAR(pos[3], Vec3(1.6, 0.8, 0), 1e-12);  // (3, 4, 0) / 5
  EXPECT_VEC_NEAR(pos[5], Vec3(1.6, 1.8, 0), 1e-12);  // all zero: (0, 1, 0)
  for (const Frame& f : d.geometry.moduleFrame) {
    EXPECT_NEAR(f.heading.norm(), 1, 1e-12);
    EXPECT_NEAR(f.up.norm(), 1, 1e-12);
    EXPECT_NEAR(f.heading.dot(f.up), 0, 1e-12);
    EXPECT_VEC_NEAR(f.left, f.heading.cross(f.up), 1e-12);
  }
}

// Components past 1e154 (their squares overflow) or below 1e-154 (they
// underflow) still give a unit heading: before, @R(1e200,0,0) made it 0
// (F moved nowhere) and @R(1e-200,0,0) made it +Y.
TEST(TurtleSetHeading, HugeAndTinyHeadingsAreNormalised) {
  const Frame big = FinalFrame("@R(1e200,0,0)");
  EXPECT_VEC_NEAR(big.heading, Vec3(1, 0, 0), 1e-12);
  const Frame huge = FinalFrame("@R(1e308,1e308,0)");
  EXPECT_VEC_NEAR(huge.heading, Vec3(std::sqrt(0.5), std::sqrt(0.5), 0), 1e-12);
  const Frame tiny = FinalFrame("@R(1e-200,0,0)");
  EXPECT_VEC_NEAR(tiny.heading, Vec3(1, 0, 0), 1e-12);
  // A huge up vector perpendicular to the heading is used.
  const Frame up = FinalFrame("@R(0,0,1,1e200,0,0)");
  EXPECT_VEC_NEAR(up.up, Vec3(1, 0, 0), 1e-12);
  for (const Frame& f : {big, huge, tiny, up}) {
    EXPECT_NEAR(f.heading.norm(), 1, 1e-12) << f.heading.transpose();
    EXPECT_NEAR(f.up.norm(), 1, 1e-12) << f.up.transpose();
    EXPECT_NEAR(f.heading.dot(f.up), 0, 1e-12) << f.up.transpose();
  }
}

TEST(TurtleSetHeading, UpFollowsTheNoTwistRuleFromTheLastF) {
  // From the start frame (H +y, U -z) to H +z the rotation about x takes
  // U to +y, and L = H x U = -x; the explicit up vector says the same.
  const Frame a = FinalFrame("@R(0,0,1)");
  EXPECT_VEC_NEAR(a.heading, Vec3(0, 0, 1), 1e-12);
  EXPECT_VEC_NEAR(a.up, Vec3(0, 1, 0), 1e-12);
  EXPECT_VEC_NEAR(a.left, Vec3(-1, 0, 0), 1e-12);
  const Frame b = FinalFrame("@R(0,0,1,0,1,0)");
  EXPECT_VEC_NEAR(b.up, Vec3(0, 1, 0), 1e-12);
  EXPECT_VEC_NEAR(b.left, Vec3(-1, 0, 0), 1e-12);
  // An up vector not perpendicular to the heading is not used.
  const Frame c = FinalFrame("@R(0,0,1,0,1,1)");
  EXPECT_VEC_NEAR(c.up, Vec3(0, 1, 0), 1e-12);
  const Frame e = FinalFrame("@R(0,0,1,1,0,0)");
  EXPECT_VEC_NEAR(e.up, Vec3(1, 0, 0), 1e-12);
  EXPECT_VEC_NEAR(e.left, Vec3(0, 1, 0), 1e-12);
  // The rule turns the frame after the last F, not the current one: a
  // roll since then is undone...
  const Frame r = FinalFrame("F /(90) @R(0,0,1)");
  EXPECT_VEC_NEAR(r.up, Vec3(0, 1, 0), 1e-12);
  // ...unless @Tf recorded it (U +x after the roll, kept by the turn about x).
  const Frame t = FinalFrame("F /(90) @Tf @R(0,0,1)");
  EXPECT_VEC_NEAR(t.up, Vec3(1, 0, 0), 1e-12);
  EXPECT_VEC_NEAR(t.left, Vec3(0, 1, 0), 1e-12);
}

TEST(TurtleLabel, AtLRecordsItsTextFormattedAtTheTurtle) {
  // cpfg's @L (blackbox.c 'L', MakeLabel): the file's text number p0, its
  // conversions filled from the other parameters, at the turtle's position
  // in its colour (vlab's simple-alpha writes each internode's flux).
  plant::PlantSpec spec;
  spec.path = "lab.l";
  spec.text =
      "axiom: F(2) @L(\" flux %.0f of %d%%\", 41.6, 7.9) [+(90) F(1) ;(3) @L(\"tip %s %g\")] "
      "@L(9)\n";
  spec.until = plant::Stage::kGeometry;
  plant::PlantResult r = plant::BuildPlant(spec);
  ASSERT_TRUE(r.plant) << r.diagnostics.FormatAll();
  const auto& labels = r.plant->geometry.labels;
  ASSERT_EQ(labels.size(), 3u);
  EXPECT_EQ(labels[0].text, " flux 42 of 7%");
  EXPECT_VEC_NEAR(labels[0].position, Vec3(0, 2, 0), 1e-12);
  // Conversions with no number left, and %s, stay text.
  EXPECT_EQ(labels[1].text, "tip %s %g");
  EXPECT_VEC_NEAR(labels[1].position, Vec3(-1, 2, 0), 1e-12);
  EXPECT_EQ(labels[1].color, 3);
  // A number that is no text of the file shows the last text, as cpfg.
  EXPECT_EQ(labels[2].text, "tip %s %g");
  const std::string all = r.diagnostics.FormatAll();
  EXPECT_NE(all.find("shows the file's last text, as cpfg does"), std::string::npos) << all;
  // Not drawn unless the caller says it draws them (sylva render does).
  EXPECT_NE(all.find("3 labels ('@L') not drawn: only 'sylva render' of the grammar draws text"),
            std::string::npos)
      << all;
  spec.draw.drawsLabels = true;
  r = plant::BuildPlant(spec);
  ASSERT_TRUE(r.plant);
  EXPECT_EQ(r.diagnostics.FormatAll().find("not drawn"), std::string::npos)
      << r.diagnostics.FormatAll();
}

TEST(TurtleLabel, FormatKeepsWidthsAndPrecisionsInBounds) {
  const double v[] = {3.14159, -2.5, 65};
  EXPECT_EQ(FormatCpfgLabel("%6.2f|%-4d|%c|%x", v, 3), "  3.14|-2  |A|%x");
  // A width or precision past 99 is cut to 99 (no huge buffers).
  EXPECT_EQ(FormatCpfgLabel("%1000000.3f", v, 1).size(), 99u);
  EXPECT_EQ(FormatCpfgLabel("%.500f", v, 1).size(), 1u + 1u + 99u);
  EXPECT_EQ(FormatCpfgLabel("100%% %", v, 0), "100% %");
  EXPECT_EQ(FormatCpfgLabel(std::string(5000, 'a'), v, 0).size(), 1000u);
}

}  // namespace
}  // namespace sylva::turtle
