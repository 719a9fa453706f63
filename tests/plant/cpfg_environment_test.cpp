// cpfg's environment programs built in (plant/density_environment.h) and
// how a cpfg folder's .e and specifications files select them
// (plant/cpfg_environment.h).
#include "plant/cpfg_environment.h"

#include <gtest/gtest.h>

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "lsys/word.h"
#include "plant/chiba_environment.h"
#include "plant/clover_environment.h"
#include "plant/density_environment.h"
#include "plant/plant.h"
#include "plant/plant_test_util.h"

namespace sylva::plant {
namespace {

std::vector<double> Honda(const Honda81Def& def, const std::vector<Vec3>& at,
                          const std::vector<std::vector<double>>& params) {
  std::vector<DensityQuery> q;
  for (size_t i = 0; i < at.size(); ++i) q.push_back(DensityQuery{at[i], params[i]});
  return Honda81Answers(def, q);
}

std::vector<double> Eco(const EcosystemDef& def, const std::vector<Vec3>& at,
                        const std::vector<std::vector<double>>& params) {
  std::vector<DensityQuery> q;
  for (size_t i = 0; i < at.size(); ++i) q.push_back(DensityQuery{at[i], params[i]});
  return EcosystemAnswers(def, q);
}

using Answers = std::vector<double>;

TEST(Honda81, EqualVigorsWithinTheRadiusBothStop) {
  const Honda81Def def{1.0, true};
  // 0 and 1 are 0.9 apart; 2 is 1.1 from 1 and 2.0 from 0.
  EXPECT_EQ(Honda(def, {Vec3(0, 0, 0), Vec3(0.9, 0, 0), Vec3(2, 0, 0)}, {{1}, {1}, {1}}),
            (Answers{0, 0, 1}));
  // Exactly at the radius collides (<=).
  EXPECT_EQ(Honda(def, {Vec3(0, 0, 0), Vec3(0, 1, 0)}, {{1}, {1}}), (Answers{0, 0}));
}

TEST(Honda81, TheHigherVigorGrowsAndGroupsDoNotMeet) {
  const Honda81Def def{1.0, true};
  EXPECT_EQ(Honda(def, {Vec3(0, 0, 0), Vec3(0.5, 0, 0)}, {{2}, {3}}), (Answers{0, 1}));
  // Groups (the whole part of the second parameter) never collide.
  EXPECT_EQ(Honda(def, {Vec3(0, 0, 0), Vec3(0.5, 0, 0)}, {{1, 1.7}, {1, 2.2}}), (Answers{1, 1}));
  EXPECT_EQ(Honda(def, {Vec3(0, 0, 0), Vec3(0.5, 0, 0)}, {{1, 2.7}, {1, 2.2}}), (Answers{0, 0}));
}

TEST(Honda81, TwoDimensionsMeasureXAndZ) {
  // 2D (the default) reads x and z: y, the height in cpfg, is left out.
  const Honda81Def flat{1.0, false};
  EXPECT_EQ(Honda(flat, {Vec3(0, 0, 0), Vec3(0, 50, 0.5)}, {{1}, {1}}), (Answers{0, 0}));
  EXPECT_EQ(Honda(flat, {Vec3(0, 0, 0), Vec3(0, 0, 1.5)}, {{1}, {1}}), (Answers{1, 1}));
  // Radius 0: only points in the same place collide.
  const Honda81Def zero{0.0, true};
  EXPECT_EQ(Honda(zero, {Vec3(1, 2, 3), Vec3(1, 2, 3), Vec3(1, 2, 3.001)}, {{1}, {1}, {1}}),
            (Answers{0, 0, 1}));
}

TEST(Honda81, SweepAgreesWithAllPairsOnARandomCloud) {
  // 400 points on a 20x20 grid jittered; the answer is checked against
  // the rule applied to every pair.
  std::vector<Vec3> at;
  std::vector<std::vector<double>> params;
  uint32_t s = 12345;
  auto next = [&] { return (s = s * 1664525u + 1013904223u) / 4294967296.0; };
  for (int i = 0; i < 400; ++i) {
    at.emplace_back(i % 20 + next() * 0.8, next() * 10, i / 20 + next() * 0.8);
    params.push_back({double(int(next() * 4)), double(int(next() * 2))});
  }
  const Honda81Def def{0.6, false};
  const Answers got = Honda(def, at, params);
  int zeros = 0;
  for (size_t i = 0; i < at.size(); ++i) {
    double expect = 1;
    for (size_t j = 0; j < at.size(); ++j) {
      const float dx = float(at[i].x()) - float(at[j].x());
      const float dz = float(at[i].z()) - float(at[j].z());
      if (i != j && params[i][1] == params[j][1] && params[i][0] <= params[j][0] &&
          dx * dx + dz * dz <= 0.6f * 0.6f)
        expect = 0;
    }
    EXPECT_EQ(got[i], expect) << "point " << i;
    zeros += expect == 0;
  }
  EXPECT_GT(zeros, 20) << "the cloud should have collisions to test";
}

TEST(Ecosystem, SmallerDiscsUnderLargerOnesDie) {
  const EcosystemDef def{};
  // Radii 0.3 and 0.1, centres 0.35 apart (overlap: 0.35 <= 0.4): the
  // small one reads 0. The third is alone.
  EXPECT_EQ(Eco(def, {Vec3(0, 0, 0), Vec3(0.35, 7, 0), Vec3(3, 0, 0)}, {{0.3}, {0.1}, {0.2}}),
            (Answers{1, 0, 1}));
  // Equal radii: both die. Apart by more than the sum: both live.
  EXPECT_EQ(Eco(def, {Vec3(0, 0, 0), Vec3(0, 0, 0.5)}, {{0.25}, {0.25}}), (Answers{0, 0}));
  EXPECT_EQ(Eco(def, {Vec3(0, 0, 0), Vec3(0, 0, 0.51)}, {{0.25}, {0.25}}), (Answers{1, 1}));
}

TEST(Ecosystem, WithVigorARemovedDiscNoLongerDominates) {
  // A chain a - b - c of overlapping discs (a and c apart): vigor 3, 2, 1.
  // b is removed by a; c, visited after b, is not dominated by the removed b.
  const EcosystemDef def{false, true};
  const std::vector<Vec3> at{Vec3(0, 0, 0), Vec3(0.5, 0, 0), Vec3(1.0, 0, 0)};
  EXPECT_EQ(Eco(def, at, {{0.3, 3}, {0.3, 2}, {0.3, 1}}), (Answers{1, 0, 1}));
  // In the other order c is visited first, while b still stands: c dies,
  // then b dies to a.
  EXPECT_EQ(Eco(def, {at[2], at[1], at[0]}, {{0.3, 1}, {0.3, 2}, {0.3, 3}}), (Answers{0, 0, 1}));
}

// A cpfg object folder in memory.
struct Folder {
  std::map<std::string, std::string> files;
  FileReader Reader() const {
    return [files = files](const std::string& path) -> std::optional<std::string> {
      auto it = files.find(path);
      if (it == files.end()) return std::nullopt;
      return it->second;
    };
  }
};

PlantResult Grow(const Folder& folder, const std::string& grammar, int steps) {
  PlantSpec spec;
  spec.path = "obj/t.l";
  spec.text = grammar;
  spec.readFile = folder.Reader();
  spec.steps = steps;
  spec.until = Stage::kWord;
  return BuildPlant(spec);
}

size_t Count(const std::string& s, const std::string& what) {
  size_t n = 0;
  for (size_t i = s.find(what); i != std::string::npos; i = s.find(what, i + 1)) ++n;
  return n;
}

std::string WordOf(const PlantResult& r) {
  if (!r.plant) return "error:\n" + r.diagnostics.FormatAll();
  return lsys::FormatWord(r.plant->word, r.plant->grammar.symbols);
}

// Two tips grow toward each other along y, each probing with ?E(1); they
// stop when they come within the radius.
const char* kTips =
    "axiom: [A ?E(1)] f(5) | A ?E(1)\n"
    "A > ?E(x) : x == 1 --> F(1) A\n"
    "?E(x) --> ?E(1)\n";

TEST(CpfgEnvironment, Honda81FromTheFoldersEFileStopsTipsThatMeet) {
  Folder f;
  f.files["obj/specifications"] = "t.l\nt.e\n*\nimage:\n\tgenerate:\n\t\tcpfg -e t.e t.l t.v\n";
  f.files["obj/t.e"] =
      "executable: honda81 -e t.e density.spec\n"
      "communication type: files\n"
      "turtle position:P:%f %f %f\n";
  f.files["obj/density.spec"] = "radius: 1.5\n3d case: on\n";
  // Tips at y = 0 and 5, then 1 and 4 (3 apart), then 2 and 3 (1 apart):
  // both read 0 and grow no further.
  PlantResult r = Grow(f, kTips, 4);
  EXPECT_EQ(WordOf(r), "[F(1)F(1)A?E(0)]f(5)|F(1)F(1)A?E(0)");
  EXPECT_EQ(r.diagnostics.FormatAll(), "");
  // In 2D (x and z) the two tips on the y axis are in the same place.
  f.files["obj/density.spec"] = "radius: 1.5\n";
  EXPECT_EQ(WordOf(Grow(f, kTips, 4)), "[A?E(0)]f(5)|A?E(0)");
}

TEST(CpfgEnvironment, PositionsGoThroughTheFilesFormat) {
  // Tips at x = 0.4 and -0.4, radius 0: through %.0f both are sent as 0
  // (and -0), the same place, and collide; through %f they do not.
  Folder f;
  f.files["obj/t.e"] = "executable: honda81 -e t.e d.spec\nturtle position:%.0f %.0f %.0f\n";
  f.files["obj/d.spec"] = "3d case: on\n";
  const char* g =
      "axiom: [@M(0.4,0,0) A ?E(1)] @M(-0.4,0,0) A ?E(1)\n"
      "A > ?E(x) : x == 1 --> F(1) A\n"
      "?E(x) --> ?E(1)\n";
  EXPECT_EQ(WordOf(Grow(f, g, 1)), "[@M(0.4,0,0)A?E(0)]@M(-0.4,0,0)A?E(0)");
  f.files["obj/t.e"] = "executable: honda81 -e t.e d.spec\nturtle position:%f %f %f\n";
  EXPECT_EQ(WordOf(Grow(f, g, 1)), "[@M(0.4,0,0)F(1)A?E(1)]@M(-0.4,0,0)F(1)A?E(1)");
}

TEST(CpfgEnvironment, EcosystemThinsOverlappingPlants) {
  Folder f;
  f.files["obj/t.e"] = "executable: ecosystem -e t.e density.spec\nturtle position:%g %g %g\n";
  f.files["obj/density.spec"] = "verbose: off\ngrid size: 128x128x1\n3d case: no\n";
  // Plants of radius 0.3, 0.1 and 0.2 along x at 0, 0.35 and 3: the
  // second overlaps the first, which is larger.
  const char* g = "axiom: [@M(0,0,0) P ?E(0.3)] [@M(0.35,0,0) P ?E(0.1)] [@M(3,0,0) P ?E(0.2)]\n";
  EXPECT_EQ(WordOf(Grow(f, g, 0)), "[@M(0,0,0)P?E(1)][@M(0.35,0,0)P?E(0)][@M(3,0,0)P?E(1)]");
}

// A 10 x 10 grid of unit cells from (0, 0), leaves letting half through.
CloverDef UnitGrid() {
  CloverDef def;
  def.size[0] = def.size[1] = 10;
  def.pos[0] = def.pos[1] = 0;
  def.range[0] = def.range[1] = 10;
  def.transmittance = 0.5f;
  return def;
}

TEST(CloverEnvironment, LeavesShadeTheCellsOfTheirDisc) {
  CloverEnvironment env(UnitGrid(), nullptr, 2);
  // A leaf of area 4 pi (radius 2: 3 cells) at (5.5, 5.5), node (5, 5).
  std::vector<double> leaf{1, 4 * M_PI}, under{1}, beside{1}, off{1}, two{0, 7};
  std::vector<EnvQuery> q{{Vec3(5.5, 5.5, 0), {}, leaf},
                          {Vec3(5.2, 5.9, 0), {}, under},
                          {Vec3(9.5, 5.5, 0), {}, beside},
                          {Vec3(-0.5, 5, 0), {}, off},
                          {Vec3(2.5, 5.5, 0), {}, two}};
  ASSERT_TRUE(env.Answer(q).ok());
  EXPECT_EQ(leaf, (std::vector<double>{1, 4 * M_PI})) << "a leaf is not answered";
  EXPECT_EQ(under[0], 0.5);
  EXPECT_EQ(beside[0], 1.0);  // 4 cells from the node: outside the disc
  EXPECT_EQ(off[0], 0.0);     // off the grid
  EXPECT_EQ(two[0], 0.5);     // (2, 5): 3 cells left of the node, on the ellipse
  EXPECT_EQ(two[1], 0.0);     // the ratio (no image: 0)
  // The disc: cells (dx, dy) in [-3, 3) with dx^2 + dy^2 <= 9.
  EXPECT_EQ(env.Leaves(5, 5), 1);
  EXPECT_EQ(env.Leaves(2, 5), 1);
  EXPECT_EQ(env.Leaves(7, 7), 1);  // (2, 2): 8 <= 9
  EXPECT_EQ(env.Leaves(8, 5), 0);  // dx = 3 is past the loop
  EXPECT_EQ(env.Leaves(2, 4), 0);  // (-3, -1): 10 > 9
  // Leaves stay from step to step: a second one doubles the shade; a
  // removal (first parameter 2) takes one away.
  std::vector<double> leaf2{1, 4 * M_PI}, q2{1};
  std::vector<EnvQuery> step2{{Vec3(5.5, 5.5, 0), {}, leaf2}, {Vec3(5.5, 5.5, 0), {}, q2}};
  ASSERT_TRUE(env.Answer(step2).ok());
  EXPECT_EQ(q2[0], 0.25);
  std::vector<double> gone{2, 4 * M_PI}, q3{1};
  std::vector<EnvQuery> step3{{Vec3(5.5, 5.5, 0), {}, gone}, {Vec3(5.5, 5.5, 0), {}, q3}};
  ASSERT_TRUE(env.Answer(step3).ok());
  EXPECT_EQ(q3[0], 0.5);
}

// An SGI image, 8 bits, 3 channels; `rle` stores each row as one literal run.
std::string Sgi(int w, int h, const std::vector<std::vector<uint8_t>>& rowsPerChannel, bool rle) {
  std::string out(512, '\0');
  auto put16 = [&](size_t at, uint32_t v) {
    out[at] = char(v >> 8);
    out[at + 1] = char(v & 255);
  };
  auto put32 = [&](size_t at, uint32_t v) {
    for (int i = 0; i < 4; ++i) out[at + size_t(i)] = char((v >> (24 - 8 * i)) & 255);
  };
  put16(0, 474);
  out[2] = char(rle ? 1 : 0);
  out[3] = 1;
  put16(4, 3);
  put16(6, uint32_t(w));
  put16(8, uint32_t(h));
  put16(10, 3);
  if (!rle) {
    for (const auto& ch : rowsPerChannel) out.append(ch.begin(), ch.end());
    return out;
  }
  const size_t rows = size_t(h) * 3, table = 512 + 8 * rows;
  out.resize(table);
  for (size_t k = 0; k < rows; ++k) {
    const auto& ch = rowsPerChannel[k / size_t(h)];
    const size_t y = k % size_t(h);
    put32(512 + 4 * k, uint32_t(out.size()));
    put32(512 + 4 * rows + 4 * k, uint32_t(w + 2));
    out.push_back(char(0x80 | w));
    out.append(ch.begin() + long(y) * w, ch.begin() + long(y + 1) * w);
    out.push_back('\0');
  }
  return out;
}

TEST(CloverEnvironment, ReadsSgiImagesVerbatimAndRunLength) {
  // 2 x 2; rows from the bottom. Red 10 20 / 30 40, green 50 60 / 70 80.
  const std::vector<std::vector<uint8_t>> ch{{10, 20, 30, 40}, {50, 60, 70, 80}, {0, 0, 0, 0}};
  for (bool rle : {false, true}) {
    auto img = ReadCloverImage(Sgi(2, 2, ch, rle), "light.rgb");
    ASSERT_TRUE(img) << img.error().message;
    EXPECT_EQ(img->red, ch[0]) << "rle " << rle;
    EXPECT_EQ(img->green, ch[1]) << "rle " << rle;
  }
  EXPECT_FALSE(ReadCloverImage(std::string(600, 'x'), "light.png"));
  EXPECT_FALSE(ReadCloverImage(Sgi(2, 2, ch, false).substr(0, 517), "cut.rgb"));
}

TEST(CpfgEnvironment, CloverReadsItsSpecAndImage) {
  Folder f;
  f.files["obj/t.e"] = "executable: clover -e t.e t.spec\nturtle position:P:%g %g\n";
  // A 2 x 2 grid over (0, 0)-(2, 2); the image's green is 255 on the left
  // column and 51 on the right, its red 64 everywhere (ratio 0.5). ?E(0, r)
  // asks for the light and the ratio. The leaf at (1.5, 1.5), of radius 0.4
  // (1 cell), shades its cell (1, 1) and those left of and below it.
  f.files["obj/t.spec"] =
      "grid position: 0 0\ngrid range: 2x2\ngrid size: 2x2\ninput image: l.rgb\n"
      "transmittance: 0.5\nverbose: off\n";
  f.files["obj/l.rgb"] = Sgi(2, 2, {{64, 64, 64, 64}, {255, 51, 255, 51}, {0, 0, 0, 0}}, true);
  const char* g =
      "axiom: [@M(0.5,0.5,0) ?E(0,0)] [@M(0.5,1.5,0) ?E(0,0)] [@M(1.5,0.5,0) ?E(0,0)] "
      "[@M(1.5,1.5,0) ?E(1,0.5)] [@M(1.5,1.5,0) ?E(0,0)]\n";
  PlantResult r = Grow(f, g, 0);
  EXPECT_EQ(WordOf(r),
            "[@M(0.5,0.5,0)?E(1,0.5)][@M(0.5,1.5,0)?E(0.5,0.5)][@M(1.5,0.5,0)?E(0.1,0.5)]"
            "[@M(1.5,1.5,0)?E(1,0.5)][@M(1.5,1.5,0)?E(0.1,0.5)]");
  EXPECT_EQ(r.diagnostics.FormatAll(), "");
  // Without the image: a warning at its name, and full light.
  f.files.erase("obj/l.rgb");
  r = Grow(f, g, 0);
  EXPECT_EQ(WordOf(r),
            "[@M(0.5,0.5,0)?E(1,0)][@M(0.5,1.5,0)?E(0.5,0)][@M(1.5,0.5,0)?E(0.5,0)]"
            "[@M(1.5,1.5,0)?E(1,0.5)][@M(1.5,1.5,0)?E(0.5,0)]");
  EXPECT_NE(r.diagnostics.FormatAll().find("obj/t.spec:4:14: warning: cannot read obj/l.rgb: "
                                           "clover's light is taken as full (255) everywhere"),
            std::string::npos)
      << r.diagnostics.FormatAll();
}

TEST(CpfgEnvironment, BundledHexCollideGrowsASymmetricSnowflake) {
  // grammars/cpfg/hex_collide.l names no environment; hex_collide.e beside
  // it names honda81. Three arms grow alike: each top-level branch holds the
  // same number of segments, which only holds if every collision is found.
  PlantSpec spec;
  spec.path = std::string(SYLVA_SOURCE_DIR) + "/grammars/cpfg/hex_collide.l";
  spec.until = Stage::kWord;
  PlantResult r = BuildPlant(spec);
  ASSERT_TRUE(r.plant) << r.diagnostics.FormatAll();
  EXPECT_EQ(r.diagnostics.FormatAll(), "");
  const std::string w = WordOf(r);
  std::vector<int> perArm;
  int depth = 0;
  for (size_t i = 0; i < w.size(); ++i) {
    if (w[i] == '[' && depth++ == 0) perArm.push_back(0);
    if (w[i] == ']') --depth;
    if (w.compare(i, 4, "F(1)") == 0 && !perArm.empty()) ++perArm.back();
  }
  EXPECT_EQ(perArm, (std::vector<int>{172, 172, 172}));
  // Without its .e file nothing answers the probes, every one grows, and
  // after n steps there are 3 + 9 + ... + 3^n = (3^(n+1) - 3) / 2 segments;
  // with it, fewer.
  spec.steps = 6;
  const size_t withEnv = Count(WordOf(BuildPlant(spec)), "F(1)");
  spec.readFile = [](const std::string& path) -> std::optional<std::string> {
    if (path.size() > 2 && path.compare(path.size() - 2, 2, ".e") == 0) return std::nullopt;
    auto text = ReadFile(path);
    if (!text) return std::nullopt;
    return std::move(*text);
  };
  EXPECT_EQ(Count(WordOf(BuildPlant(spec)), "F(1)"), (2187u - 3u) / 2u);
  EXPECT_LT(withEnv, (2187u - 3u) / 2u);
}

TEST(ChibaEnvironment, SourcesAreNormalizedAndSkySamplesWeighted) {
  ChibaDef def;
  def.sources = {{{0, 100, 0}, 4}, {{40, 100, 0}, 3}, {{0, 60, 80}, 1}};
  auto dirs = ChibaDirections(def);
  ASSERT_EQ(dirs.size(), 3u);
  EXPECT_FLOAT_EQ(dirs[0].intensity, 0.5f);
  EXPECT_FLOAT_EQ(dirs[2].intensity, 0.125f);
  EXPECT_FLOAT_EQ(dirs[2].dir[1], 0.6f);
  EXPECT_FLOAT_EQ(dirs[2].dir[2], 0.8f);
  // 20 samples: the next 8 * 4^k is 32, the octahedron subdivided once;
  // 16 look up, 16 down, weighted 1 : 0.7.
  ChibaDef sky;
  dirs = ChibaDirections(sky);
  ASSERT_EQ(dirs.size(), 32u);
  int up = 0;
  float total = 0;
  for (const auto& d : dirs) {
    EXPECT_NEAR(d.dir[0] * d.dir[0] + d.dir[1] * d.dir[1] + d.dir[2] * d.dir[2], 1.0f, 1e-6f);
    up += d.dir[1] > 0;
    total += d.intensity;
    EXPECT_FLOAT_EQ(d.intensity, d.dir[1] > 0 ? 1 / 16.0f / 1.7f : 0.7f / 16.0f / 1.7f);
  }
  EXPECT_EQ(up, 16);
  EXPECT_NEAR(total, 1.0f, 1e-6f);
}

TEST(ChibaEnvironment, ClustersTowardTheLightShadeByOverlappingArea) {
  ChibaDef def;
  def.sources = {{{0, 1, 0}, 1}};
  def.transmittance = 0.25f;
  def.estimateArea = true;
  ChibaEnvironment env(def, 3);
  // Unit clusters: one right above the first (full overlap), one above the
  // third but shifted by 1 (lens of area 2 pi/3 - sqrt(3)/2).
  std::vector<double> a{1, 0, 0, 0}, b{1}, c{1}, e{1};
  std::vector<EnvQuery> q{{Vec3(0, 0, 0), {}, a},
                          {Vec3(0, 2, 0), {}, b},
                          {Vec3(10, 0, 0), {}, c},
                          {Vec3(11, 2, 0), {}, e}};
  ASSERT_TRUE(env.Answer(q).ok());
  EXPECT_NEAR(a[0], 0.25, 1e-6);  // 1 - 0.75 * pi / pi
  EXPECT_NEAR(a[2], 1.0, 1e-6) << "the brightest direction is the one source";
  EXPECT_EQ(b[0], 1.0);  // nothing above it
  const double lens = 2 * M_PI / 3 - std::sqrt(3.0) / 2;
  EXPECT_NEAR(c[0], 1 - 0.75 * lens / M_PI, 1e-6);
  EXPECT_EQ(e[0], 1.0);
}

TEST(ChibaEnvironment, WithoutAreaABallLetsThroughByChordLength) {
  ChibaDef def;
  def.sources = {{{0, 1, 0}, 1}};  // transmittance 0.6, beam radius 0
  ChibaEnvironment env(def, 3);
  // The ray up from (0, 0, 0) crosses the ball of radius 0.5 at (0, 3, 0)
  // through its centre: a chord of 1 = its diameter, so 0.6^1. A ball off
  // to the side at distance 0.4 of the ray: chord 2 sqrt(0.25 - 0.16) = 0.6.
  std::vector<double> a{1}, b{0.5}, c{1}, d{0.5};
  std::vector<EnvQuery> q{{Vec3(0, 0, 0), {}, a},
                          {Vec3(0, 3, 0), {}, b},
                          {Vec3(5, 0, 0), {}, c},
                          {Vec3(5.4, 3, 0), {}, d}};
  ASSERT_TRUE(env.Answer(q).ok());
  EXPECT_NEAR(a[0], 0.6, 1e-6);
  EXPECT_NEAR(c[0], std::pow(0.6, 0.6), 1e-6);
  EXPECT_EQ(b[0], 1.0);
  // ?E with 2 or 3 parameters is not a cluster: not answered, casts nothing.
  std::vector<double> two{7, 7}, lone{1};
  std::vector<EnvQuery> q2{{Vec3(0, 0, 0), {}, lone}, {Vec3(0, 1, 0), {}, two}};
  ASSERT_TRUE(env.Answer(q2).ok());
  EXPECT_EQ(two, (std::vector<double>{7, 7}));
  EXPECT_EQ(lone[0], 1.0);
}

TEST(CpfgEnvironment, ChibaReadsItsSpecFile) {
  Folder f;
  f.files["obj/t.e"] = "executable: chiba -e t.e light.spec\nturtle position:P:%.4g %.4g %.4g\n";
  f.files["obj/light.spec"] =
      "grid size: 32x32x32\nverbose: off\ntransmittance: 0.25\nnumber of samples: 128\n"
      "estimate intersection area: on\nsource direction:    0 100    0   4\n";
  // Two clusters of radius 1 stacked 2 apart: the lower one gets a quarter.
  const char* g = "axiom: [?E(1)] f(2) ?E(1)\n";
  PlantResult r = Grow(f, g, 0);
  EXPECT_EQ(WordOf(r), "[?E(0.25)]f(2)?E(1)");
  EXPECT_EQ(r.diagnostics.FormatAll(), "");
}

TEST(CpfgEnvironment, TheCpfgLineNamingTheGrammarChoosesTheEFile) {
  // specifications' cpfg line for another grammar (a control panel) is
  // passed over; LSspecifications' line for this one names far.e.
  Folder f;
  f.files["obj/specifications"] = "image:\n\tcpfg -e panel.e panel.l\n";
  f.files["obj/LSspecifications"] = "cpfg -m t.map -e far.e t.l t.v t.a\nauto run: on\n";
  f.files["obj/panel.e"] = "executable: soil\n";
  f.files["obj/far.e"] = "executable: honda81 -e far.e d.spec\nturtle position:%f %f %f\n";
  f.files["obj/d.spec"] = "radius: 1.5\n3d case: on\n";
  EXPECT_EQ(WordOf(Grow(f, kTips, 4)), "[F(1)F(1)A?E(0)]f(5)|F(1)F(1)A?E(0)");
  // With neither naming it, NAME.e beside the grammar is used.
  f.files.erase("obj/LSspecifications");
  f.files["obj/t.e"] = f.files["obj/far.e"];
  EXPECT_EQ(WordOf(Grow(f, kTips, 4)), "[F(1)F(1)A?E(0)]f(5)|F(1)F(1)A?E(0)");
}

std::string Warnings(const Folder& f, const std::string& grammar) {
  PlantResult r = Grow(f, grammar, 1);
  EXPECT_TRUE(r.plant) << r.diagnostics.FormatAll();
  return r.diagnostics.FormatAll();
}

TEST(CpfgEnvironment, AProgramSylvaLacksIsNamedInAWarning) {
  Folder f;
  f.files["obj/t.e"] = "executable: soil -e t.e soil.spec\nturtle position:%g %g %g\n";
  const std::string w = Warnings(f, kTips);
  EXPECT_NE(w.find("obj/t.e:1:13: warning: the environment program 'soil' is not built into "
                   "Sylva"),
            std::string::npos)
      << w;
  EXPECT_EQ(w.find("'environment:' statement"), std::string::npos) << w;
}

TEST(CpfgEnvironment, AMissingEFileNamedBySpecificationsIsAWarningThere) {
  Folder f;
  f.files["obj/specifications"] = "t.l\n*\n\t\tcpfg -m t.map -e tree.e t.l t.v\n";
  const std::string w = Warnings(f, kTips);
  EXPECT_NE(w.find("obj/specifications:3:20: warning: the environment file obj/tree.e named "
                   "here cannot be read"),
            std::string::npos)
      << w;
}

TEST(CpfgEnvironment, SpecFileProblemsAreWarnedAndDefaultsKept) {
  Folder f;
  f.files["obj/t.e"] = "executable: honda81 -e t.e density.spec\nturtle position:%g %g\n";
  std::string w = Warnings(f, kTips);
  EXPECT_NE(w.find("cannot read honda81's specification file obj/density.spec"), std::string::npos)
      << w;
  EXPECT_NE(w.find("'turtle position:' sends 2 coordinates and honda81 needs 3"), std::string::npos)
      << w;
  f.files["obj/density.spec"] = "radius: 2\nspeed: 9\n";
  w = Warnings(f, kTips);
  EXPECT_NE(w.find("obj/density.spec:2:1: warning: unknown directive 'speed'"), std::string::npos)
      << w;
}

TEST(CpfgEnvironment, NoQueryNoEnvironment) {
  // A grammar without ?E reads nothing of the folder's .e file.
  Folder f;
  f.files["obj/t.e"] = "executable: chiba\n";
  PlantResult r = Grow(f, "axiom: F A\nA --> F A\n", 2);
  EXPECT_EQ(WordOf(r), "FFFA");
  EXPECT_EQ(r.diagnostics.FormatAll(), "");
}

}  // namespace
}  // namespace sylva::plant
