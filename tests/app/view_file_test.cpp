#include "app/view_file.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "app/cli_test_util.h"
#include "mesh/color.h"

namespace sylva::app {
namespace {

using testing::RunSylva;
using testing::Scratch;
using testing::WriteFile;

std::string Messages(const DiagnosticList& list) {
  std::string s;
  for (const Diagnostic& d : list.items) {
    s += std::to_string(d.loc.line) + ":" + std::to_string(d.loc.column) +
         (d.severity == Severity::kError ? " error: " : " warning: ") + d.message + "\n";
  }
  return s;
}

TEST(ViewFile, ReadsWhatTheTurtleUses) {
  ViewFile v = ParseViewFile(
      "/* cpfg */\n"
      "angle increment: 22.5\n"
      "initial color: 3\n"
      "color increment : 2\n"
      "initial line width: 0.4 polygons // pixels in cpfg's old files\n"
      "line width increment: 0.05\n"
      "viewpoint: 1,0,0\n"
      "view reference point: 0, 0, 0\n"
      "scale factor: 0.8\n"
      "tropism: T 0,-2,0 A 0 E 0.3 I 0.5 S 0.01\n",
      "p.v");
  EXPECT_TRUE(v.diagnostics.items.empty()) << Messages(v.diagnostics);
  EXPECT_EQ(v.angle.value_or(-1), 22.5);
  EXPECT_EQ(v.initialColor.value_or(-1), 3);
  EXPECT_EQ(v.colorIncrement.value_or(-1), 2);
  EXPECT_EQ(v.width.value_or(-1), 0.4);
  EXPECT_EQ(v.widthIncrement.value_or(-1), 0.05);
  EXPECT_EQ(v.scale.value_or(-1), 0.8);
  ASSERT_EQ(v.movements.size(), 1u);
  // T normalised times I (cpfg scales by I / |T|).
  EXPECT_EQ(Vec3(v.movements[0].x, v.movements[0].y, v.movements[0].z), Vec3(0, -0.5, 0));
  EXPECT_EQ(v.movements[0].elasticity, 0.3);
  EXPECT_EQ(v.movements[0].elasticityStep, 0.01);
  EXPECT_FALSE(v.tropism || v.elasticity || v.elasticityIncrement);  // cpfg's older tropism
  auto dir = ViewDirection(v);
  ASSERT_TRUE(dir.has_value());
  EXPECT_NEAR((*dir)[0], 90, 1e-12);  // from +X
  EXPECT_NEAR((*dir)[1], 0, 1e-12);
  EXPECT_EQ(ParseViewFile("angle factor: 16\n", "p.v").angle.value_or(-1), 22.5);
}

TEST(ViewFile, BoxIsTheViewVolumeAParallelViewFrames) {
  // vlab's insect-realistic: `box: x: -10,10 y: -57,70 z: -1,1` (cpfg's
  // fixed view volume); was warned as not acted on.
  ViewFile v = ParseViewFile("box: x: -10,10 y: 70,-57 z: -1,1\n", "p.v");
  EXPECT_TRUE(v.diagnostics.items.empty()) << Messages(v.diagnostics);
  ASSERT_TRUE(v.box.has_value());
  EXPECT_EQ((*v.box)[0], Vec3(-10, -57, -1));
  EXPECT_EQ((*v.box)[1], Vec3(10, 70, 1));
  // vlab's topiary writes `z:-4,4`: cpfg's scanf reads it.
  ViewFile tight = ParseViewFile("box: x: -4,4 y: -2,7 z:-4,4\n", "p.v");
  EXPECT_TRUE(tight.diagnostics.items.empty()) << Messages(tight.diagnostics);
  ASSERT_TRUE(tight.box.has_value());
  EXPECT_EQ((*tight.box)[0], Vec3(-4, -2, -4));
  ViewFile bad = ParseViewFile("box: x: -10,10 y: -57,70\n", "p.v");
  EXPECT_FALSE(bad.box.has_value());
  EXPECT_NE(Messages(bad.diagnostics).find("'box:' needs the ranges"), std::string::npos)
      << Messages(bad.diagnostics);
}

TEST(ViewFile, LineStyleAndProjectionAsCpfgReadsThem) {
  // cpfg (interpret.c ReadViewData, InitializeParameters): widths are
  // pixels unless the width line says otherwise, 1 by default; the
  // projection is parallel unless it says perspective.
  ViewFile none = ParseViewFile("angle increment: 30\n", "p.v");
  EXPECT_TRUE(none.widthInPixels);
  EXPECT_EQ(none.width.value_or(-1), 1);
  EXPECT_TRUE(none.parallel);
  ViewFile px = ParseViewFile("initial line width: 2 pixels\nprojection: parallel\n", "p.v");
  EXPECT_TRUE(px.diagnostics.items.empty()) << Messages(px.diagnostics);
  EXPECT_TRUE(px.widthInPixels);
  EXPECT_EQ(px.width.value_or(-1), 2);
  EXPECT_TRUE(px.parallel);
  for (const char* world : {"initial line width: 0.1\n", "initial line width: 0.1 s\n",
                            "initial line width: 0.3 polygons\n",
                            "initial line width: 3 pixels\nline style: cylinder\n"}) {
    ViewFile w = ParseViewFile(world, "p.v");
    EXPECT_TRUE(w.diagnostics.items.empty()) << world << Messages(w.diagnostics);
    EXPECT_FALSE(w.widthInPixels) << world;
  }
  ViewFile persp = ParseViewFile("projection: perspective\nline style: pixel\n", "p.v");
  EXPECT_TRUE(persp.diagnostics.items.empty()) << Messages(persp.diagnostics);
  EXPECT_FALSE(persp.parallel);
  EXPECT_TRUE(persp.widthInPixels);
  ViewFile odd = ParseViewFile("projection: fisheye\nline style: wavy\n", "p.v");
  const std::string all = Messages(odd.diagnostics);
  EXPECT_NE(all.find("1:13 warning: unknown projection 'fisheye': parallel"), std::string::npos)
      << all;
  EXPECT_NE(all.find("2:13 warning: 'line style:' is 'pixel', 'polygon' or 'cylinder', not 'wavy'"),
            std::string::npos)
      << all;
  EXPECT_TRUE(odd.parallel);
}

TEST(ViewFile, LightsGiveTheKeyLightItsDirection) {
  // cpfg's OpenGL renderer (irisGL.c read_light, set_gl_lights): the
  // `light:` lines, else a directional light toward `light direction:`.
  ViewFile dir = ParseViewFile("light direction: 0,2,0\n", "p.v");
  EXPECT_TRUE(dir.diagnostics.items.empty()) << Messages(dir.diagnostics);
  ASSERT_TRUE(dir.lightToward.has_value());
  EXPECT_LT((*dir.lightToward - Vec3(0, 1, 0)).norm(), 1e-15);
  ViewFile first = ParseViewFile(
      "light direction: 1,0,0\nlight: O:400 500 300\nlight: V: 0 0 1 D: 1 1 1\n", "p.v");
  ASSERT_TRUE(first.lightToward.has_value());
  EXPECT_LT((*first.lightToward - Vec3(400, 500, 300).normalized()).norm(), 1e-12);
  const std::string all = Messages(first.diagnostics);
  ASSERT_EQ(first.diagnostics.items.size(), 1u) << all;
  EXPECT_NE(all.find("3:1 warning: a second 'light:'"), std::string::npos) << all;
  ViewFile colours = ParseViewFile("light: V:1 1 0 A: 0.2 0.2 0.2 D:1 1 1\n", "p.v");
  const std::string c = Messages(colours.diagnostics);
  EXPECT_NE(c.find("1:1 warning: 'light:': Sylva uses the light's direction"), std::string::npos)
      << c;
  EXPECT_NE(c.find("A, D (colours"), std::string::npos) << c;
  ASSERT_TRUE(colours.lightToward.has_value());
  EXPECT_NEAR(colours.lightToward->x(), std::sqrt(0.5), 1e-12);
  ViewFile bad = ParseViewFile("light: Q 1 2 3\nlight direction: 0,0,0\n", "p.v");
  const std::string b = Messages(bad.diagnostics);
  EXPECT_NE(b.find("1:8 error: expected A, D, S, O, V, P or T in 'light:', not 'Q'"),
            std::string::npos)
      << b;
  EXPECT_NE(b.find("2:18 error: the light direction must not be 0,0,0"), std::string::npos) << b;
  EXPECT_FALSE(ParseViewFile("angle factor: 8\n", "p.v").lightToward.has_value());
}

TEST(ViewFile, AnimationFilesOverlayFramesOnlyWithoutClearingOrDoubleBuffering) {
  ViewFile natica;
  ParseAnimationFile(
      "double buffer: off\nclear between frames: off\nfirst frame: 0\nlast frame: 1500\n"
      "step: 1\nframe numbers: consecutive\n",
      "rd.a", natica);
  EXPECT_TRUE(natica.diagnostics.items.empty()) << Messages(natica.diagnostics);
  ASSERT_TRUE(natica.overlay.has_value());
  EXPECT_EQ(natica.overlay->first, 0);
  EXPECT_EQ(natica.overlay->last, 1500);
  EXPECT_EQ(natica.overlay->step, 1);
  ViewFile toEnd;
  ParseAnimationFile("double buffer: off\nclear between frames: off\nlast frame: -1\n", "a.a",
                     toEnd);
  ASSERT_TRUE(toEnd.overlay.has_value());
  EXPECT_EQ(toEnd.overlay->last, -1);
  for (const char* still :
       {"double buffer: on\nclear between frames: off\nlast frame: -1\n",
        "double buffer: off\nclear between frames: on\nlast frame: x\n", "last frame: 5\n"}) {
    ViewFile v;
    ParseAnimationFile(still, "a.a", v);
    EXPECT_FALSE(v.overlay.has_value()) << still;
    EXPECT_TRUE(v.diagnostics.items.empty()) << still << Messages(v.diagnostics);
  }
  ViewFile bad;
  ParseAnimationFile("double buffer: off\nclear between frames: off\nstep: 0\n", "a.a", bad);
  EXPECT_FALSE(bad.overlay.has_value());
  const std::string all = Messages(bad.diagnostics);
  EXPECT_NE(all.find("3:7 error: 'step:' expects a whole number from 1"), std::string::npos) << all;
}

TEST(ViewFile, TropismLettersMayCarryAColonAndAnAttachedValue) {
  // As vlab's published view files write them.
  ViewFile v = ParseViewFile("tropism: T: 0.0 -1.0 0.0  A:0 E: 0.3\n", "p.v");
  EXPECT_TRUE(v.diagnostics.items.empty()) << Messages(v.diagnostics);
  ASSERT_EQ(v.movements.size(), 1u);
  EXPECT_EQ(Vec3(v.movements[0].x, v.movements[0].y, v.movements[0].z), Vec3(0, -1, 0));
  EXPECT_EQ(v.movements[0].elasticity, 0.3);
  ViewFile angled = ParseViewFile("tropism: T: 0 1 0  A:90\n", "p.v");
  EXPECT_TRUE(angled.diagnostics.items.empty()) << Messages(angled.diagnostics);
  ASSERT_EQ(angled.movements.size(), 1u);
  EXPECT_EQ(angled.movements[0].angle, 90);
  // A zero tropism direction bends nothing, as in cpfg: a zero vector, no error.
  ViewFile none = ParseViewFile("tropism direction: 0.0,0.0,0.0\ninitial elasticity: 0.2\n", "p.v");
  EXPECT_TRUE(none.diagnostics.items.empty()) << Messages(none.diagnostics);
  EXPECT_EQ(none.tropism.value_or(Vec3(1, 1, 1)), Vec3(0, 0, 0));
}

TEST(ViewFile, TropismAndTorqueLinesAreMovementsInTheirOrder) {
  // As vlab's lily, two-trees and clover write them (cpfg movements.c).
  ViewFile v = ParseViewFile(
      "tropism: T: 0.0 -1.0 0.0\n"
      "tropism: T: 0.0  1.0 0.0  A:90 E: 0.2 S 0.05\n"
      "torque:  T: 0.0  1.0 0.0 E 0.4\n"
      "tropism: T 0,0,2 I 0.5\n",
      "p.v");
  EXPECT_TRUE(v.diagnostics.items.empty()) << Messages(v.diagnostics);
  ASSERT_EQ(v.movements.size(), 4u);
  auto dir = [&](size_t k) { return Vec3(v.movements[k].x, v.movements[k].y, v.movements[k].z); };
  EXPECT_EQ(dir(0), Vec3(0, -1, 0));
  EXPECT_FALSE(v.movements[0].torque);
  EXPECT_EQ(v.movements[0].elasticity, 0);
  EXPECT_EQ(v.movements[1].angle, 90);
  EXPECT_EQ(v.movements[1].elasticity, 0.2);
  EXPECT_EQ(v.movements[1].elasticityStep, 0.05);
  EXPECT_TRUE(v.movements[2].torque);
  EXPECT_EQ(dir(2), Vec3(0, 1, 0));
  EXPECT_EQ(v.movements[2].elasticity, 0.4);
  EXPECT_EQ(dir(3), Vec3(0, 0, 0.5));
  // cpfg clamps I / |T| to [-1, 1]: a short T with I 1 keeps its length.
  ViewFile shortT = ParseViewFile("tropism: T 0,0,0.5 I 1\n", "p.v");
  ASSERT_EQ(shortT.movements.size(), 1u);
  EXPECT_EQ(shortT.movements[0].z, 0.5);
  // An intensity of 0, or I before T, drops the line as cpfg does; a torque
  // does not use A; an 11th line is more than cpfg keeps.
  auto first = [](const std::string& text) {
    ViewFile w = ParseViewFile(text, "p.v");
    return w.diagnostics.items.empty() ? std::string() : w.diagnostics.items[0].Format();
  };
  EXPECT_EQ(first("tropism: T 0,1,0 I 0\n").rfind("p.v:1:18: warning: an intensity of 0", 0), 0u);
  EXPECT_TRUE(ParseViewFile("tropism: T 0,1,0 I 0\n", "p.v").movements.empty());
  EXPECT_EQ(first("tropism: I 1 T 0,1,0\n").rfind("p.v:1:10: warning: 'I' before 'T'", 0), 0u);
  EXPECT_EQ(first("torque: T 0,1,0 A 30\n").rfind("p.v:1:17: warning: 'torque:' does not use", 0),
            0u);
  std::string eleven;
  for (int i = 0; i < 11; ++i) eleven += "tropism: T 0,1,0\n";
  ViewFile many = ParseViewFile(eleven, "p.v");
  EXPECT_EQ(many.movements.size(), 10u);
  EXPECT_EQ(first(eleven).rfind("p.v:11:1: warning: cpfg keeps at most 10", 0), 0u)
      << first(eleven);
}

TEST(ViewFile, ApplyGivesTheGrammarItsMovementsAndCpfgsDefaultTropismDirection) {
  lsys::Grammar g;
  ApplyViewFile(ParseViewFile("initial elasticity: 0.3\ntorque: T 1,0,0\n", "p.v"), g);
  ASSERT_TRUE(g.tropism.has_value());
  // cpfg's `tropism direction:` is up when the file does not say it.
  EXPECT_EQ(Vec3(g.tropism->x, g.tropism->y, g.tropism->z), Vec3(0, 1, 0));
  EXPECT_EQ(g.tropism->susceptibility, 0.3);
  ASSERT_EQ(g.movements.size(), 1u);
  EXPECT_TRUE(g.movements[0].torque);
}

// cpfg's camera looks from the viewpoint toward the view reference point:
// where they coincide, or lie too far apart for a double (or a perspective
// scale puts the eye there), Sylva frames the plant itself, and says so at
// the camera's line; a 'box:' beyond the +-1e30 the camera frames is
// ignored with a warning (both were silent: the first framed the plant,
// the second the unit cube).
TEST(ViewFile, ACameraWithoutADirectionOrAnUnframableBoxIsWarned) {
  struct Case {
    const char* text;
    const char* expected;  // "" for no diagnostic
  } cases[] = {
      {"projection: perspective\nview reference point: 0,1,0\nviewpoint: 0,1,0\n",
       "3:1 warning: the viewpoint is the view reference point"},
      {"view reference point: 0,0,0\n", ""},  // the default viewpoint 0,0,1
      {"view reference point: 0,0,1\n", "1:1 warning: the viewpoint is the view reference point"},
      {"viewpoint: 0,1e300,0\n", "1:1 warning: the eye's distance from the view reference point"},
      {"viewpoint: 0,0,1e-300\nview reference point: 0,0,0\n", "1:1 warning: the eye's distance"},
      {"projection: perspective\nviewpoint: 0,0,1e10\nscale factor: 1e-300\n",
       "2:1 warning: the eye's distance"},
      {"projection: parallel\nviewpoint: 0,0,1e10\nscale factor: 1e-300\n", ""},
      {"projection: perspective\nviewpoint: 0,1,10\nview reference point: 0,1,0\n", ""},
      {"box: x: -1e300,1e300 y: 0,2 z: -1,1\n", "1:1 warning: 'box:' reaches beyond +-1e30"},
  };
  for (const Case& c : cases) {
    const ViewFile v = ParseViewFile(c.text, "p.v");
    const std::string all = Messages(v.diagnostics);
    if (*c.expected == 0) {
      EXPECT_TRUE(v.diagnostics.items.empty()) << c.text << all;
    } else {
      EXPECT_NE(all.find(c.expected), std::string::npos) << c.text << all;
      EXPECT_FALSE(v.diagnostics.HasErrors()) << c.text << all;
    }
  }
  EXPECT_FALSE(ParseViewFile("box: x: -1e300,1e300 y: 0,2 z: -1,1\n", "p.v").box.has_value());
}

TEST(ViewFile, WarnsOncePerLabelItDoesNotActOnWithItsLocation) {
  ViewFile v = ParseViewFile(
      "twist: 0\nz buffer: on\nprojection: perspective\n"  // acted on or as Sylva draws: silent
      "shade mode: 3\n"
      "  tsurface: l leaf.s 1\n"
      "tsurface: k flower.s 1\n"
      "#include \"more.v\"\n"
      "blorp: 2\n"
      "initial color: 1 5\n",
      "p.v");
  const std::string all = Messages(v.diagnostics);
  ASSERT_EQ(v.diagnostics.items.size(), 5u) << all;
  EXPECT_EQ(v.diagnostics.HasErrors(), false) << all;
  EXPECT_EQ(v.diagnostics.items[0].loc.line, 4) << all;
  EXPECT_NE(all.find("4:1 warning: 'shade mode:' is read but not acted on"), std::string::npos)
      << all;
  EXPECT_NE(all.find("5:3 warning: 'tsurface:' is read but not acted on"), std::string::npos)
      << all;
  EXPECT_EQ(all.find("6:1"), std::string::npos) << all;  // once per label
  EXPECT_NE(all.find("7:1 warning: preprocessor lines"), std::string::npos) << all;
  EXPECT_NE(all.find("8:1 warning: 'blorp:' is not a cpfg view file setting"), std::string::npos)
      << all;
  EXPECT_NE(all.find("9:18 warning: 'initial color:': the back-side colour"), std::string::npos)
      << all;
}

TEST(ViewFile, SurfaceLinesNameCpfgSurfacesBesideTheViewFile) {
  ViewFile v = ParseViewFile("surface: l leaf.s 800 3 5\nsurface: b sub/bud.s 2\n", "/x/y/p.v");
  ASSERT_EQ(v.diagnostics.items.size(), 0u) << Messages(v.diagnostics);
  ASSERT_EQ(v.surfaces.size(), 2u);
  EXPECT_EQ(v.surfaces[0].name, "l");
  EXPECT_EQ(v.surfaces[0].file, "/x/y/leaf.s");
  EXPECT_EQ(v.surfaces[0].size, 800);
  EXPECT_EQ(v.surfaces[0].sPrecision, 3);
  EXPECT_EQ(v.surfaces[0].tPrecision, 5);
  EXPECT_EQ(v.surfaces[0].line, 1);
  EXPECT_EQ(v.surfaces[1].file, "/x/y/sub/bud.s");
  EXPECT_EQ(v.surfaces[1].size, 2);
  EXPECT_EQ(v.surfaces[1].sPrecision, 0);

  ViewFile bad = ParseViewFile(
      "surface: lf leaf.s 1\nsurface: l leaf.s -2\nsurface: l leaf.s 1 0\nsurface: l\n", "p.v");
  const std::string all = Messages(bad.diagnostics);
  EXPECT_NE(all.find("1:10 error: a cpfg surface is named by one letter, not 'lf'"),
            std::string::npos)
      << all;
  EXPECT_NE(all.find("2:19 error: a surface's size must be positive"), std::string::npos) << all;
  EXPECT_NE(all.find("3:21 error: a precision is a whole number from 1 to 64"), std::string::npos)
      << all;
  EXPECT_NE(all.find("4:11 error: expected 'surface: LETTER FILE.s size [s t]'"), std::string::npos)
      << all;
  EXPECT_TRUE(bad.surfaces.empty());
}

TEST(ViewFile, BadValuesAreErrorsAtTheirColumn) {
  auto first = [](const std::string& text) {
    ViewFile v = ParseViewFile(text, "p.v");
    return v.diagnostics.items.empty() ? std::string("none") : Messages(v.diagnostics);
  };
  EXPECT_EQ(first("angle increment: nan\n"),
            "1:18 error: expected an angle in degrees, not 'nan'\n");
  EXPECT_EQ(first("angle increment: 1e999\n").rfind("1:18 error", 0), 0u);
  EXPECT_EQ(first("viewpoint: 1,2\n").rfind("1:15 error: expected x,y,z after 'viewpoint:'", 0),
            0u);
  EXPECT_EQ(first("initial color: 2.5\n").rfind("1:16 error: expected a whole number", 0), 0u);
  EXPECT_EQ(first("angle factor: 0\n").rfind("1:15 warning: 'angle factor: 0' gives no angle", 0),
            0u);
  EXPECT_FALSE(ParseViewFile("angle factor: 0\n", "p.v").angle.has_value());
  EXPECT_EQ(first("tropism: E 0.2\n").rfind("1:1 error: 'tropism:' needs its vector", 0), 0u);
  EXPECT_EQ(first("tropism: T 0,0,0 E 1\n").rfind("1:12 error", 0), 0u);
  EXPECT_EQ(first("torque: E 0.2\n").rfind("1:1 error: 'torque:' needs its vector", 0), 0u);
  EXPECT_EQ(first("just words\n").rfind("1:1 error: expected 'label: values'", 0), 0u);
}

TEST(ViewFile, ColourMapIs256RgbTriples) {
  std::string bytes(768, '\0');
  for (int i = 0; i < 256; ++i) {
    bytes[size_t(3 * i)] = char(i);
    bytes[size_t(3 * i + 1)] = char(255 - i);
    bytes[size_t(3 * i + 2)] = char(7);
  }
  DiagnosticList warnings;
  auto map = ParseColormap(bytes, "p.map", warnings);
  ASSERT_TRUE(map.ok());
  ASSERT_EQ(map->size(), 256u);
  EXPECT_FLOAT_EQ((*map)[5][0], 5 / 255.0f);
  EXPECT_FLOAT_EQ((*map)[5][1], 250 / 255.0f);
  EXPECT_FLOAT_EQ((*map)[5][2], 7 / 255.0f);
  EXPECT_TRUE(warnings.items.empty());
  auto truncated = ParseColormap(bytes.substr(0, 767), "p.map", warnings);
  ASSERT_FALSE(truncated.ok());
  EXPECT_NE(truncated.error().message.find("767 bytes (truncated?)"), std::string::npos)
      << truncated.error().message;
  ASSERT_TRUE(ParseColormap(bytes + "xyz", "p.map", warnings).ok());
  ASSERT_EQ(warnings.items.size(), 1u);
  EXPECT_NE(warnings.items[0].message.find("3 bytes after them are ignored"), std::string::npos);
}

TEST(ViewFile, MaterialsGiveTheirDiffuseColourToTheirIndex) {
  // index 4: transparency 0, ambient 1 2 3, diffuse 10 20 30, emissive,
  // specular, shininess.
  const std::string record("\x04\x00\x01\x02\x03\x0a\x14\x1e\x00\x00\x00\x00\x00\x00\x05", 15);
  auto mat = ParseMaterials(record, "p.mat");
  ASSERT_TRUE(mat.ok());
  EXPECT_FLOAT_EQ((*mat)[4][0], 10 / 255.0f);
  EXPECT_FLOAT_EQ((*mat)[4][1], 20 / 255.0f);
  EXPECT_FLOAT_EQ((*mat)[4][2], 30 / 255.0f);
  EXPECT_FLOAT_EQ((*mat)[3][0], 200 / 255.0f);  // no material: cpfg's grey
  EXPECT_FALSE(ParseMaterials(record.substr(0, 14), "p.mat").ok());
  EXPECT_FALSE(ParseMaterials("", "p.mat").ok());
}

TEST(ViewFile, HostileFilesAreClearErrors) {
  const std::string grammar = WriteFile("hostile.l", "axiom: F\n");
  auto errorOf = [&](const std::string& view) {
    auto v = LoadViewFiles(grammar, view);
    if (!v || !v->diagnostics.HasErrors()) return std::string("no error");
    return v->diagnostics.items.back().Format();
  };
  EXPECT_NE(errorOf("/dev/zero").find("is not a regular file"), std::string::npos);
  EXPECT_NE(errorOf(Scratch().string()).find("is a directory"), std::string::npos);
  EXPECT_NE(errorOf((Scratch() / "missing.v").string()).find("cannot read file"),
            std::string::npos);
  const std::string huge = WriteFile("huge.v", std::string(size_t(2) << 20, ' '));
  EXPECT_NE(errorOf(huge).find("larger than the limit"), std::string::npos);
  // Binary garbage: a bounded number of errors, then a stop.
  std::string garbage;
  uint32_t state = 12345;
  for (int i = 0; i < 500000; ++i) {
    state = state * 1664525u + 1013904223u;
    garbage += char(state >> 24);
  }
  auto noise = LoadViewFiles(grammar, WriteFile("noise.v", garbage));
  ASSERT_TRUE(noise != nullptr);
  EXPECT_LE(noise->diagnostics.items.size(), 200u);
  EXPECT_NE(noise->diagnostics.items.back().message.find("too many errors"), std::string::npos)
      << noise->diagnostics.items.back().message;
  std::string labels;
  for (int i = 0; i < 100000; ++i) labels += "x" + std::to_string(i) + ": 1\n";
  auto many = LoadViewFiles(grammar, WriteFile("labels.v", labels));
  ASSERT_TRUE(many != nullptr);
  EXPECT_LE(many->diagnostics.items.size(), 201u);
  EXPECT_TRUE(many->diagnostics.HasErrors());  // the stop is an error
  // A truncated colour map beside the grammar.
  WriteFile("hostile.map", std::string(100, '\1'));
  auto v = LoadViewFiles(grammar, "");
  ASSERT_TRUE(v != nullptr);
  EXPECT_NE(Messages(v->diagnostics).find("100 bytes (truncated?)"), std::string::npos);
  std::filesystem::remove(Scratch() / "hostile.map");
  // A directory where NAME.v would be.
  std::filesystem::create_directories(Scratch() / "hostile.v");
  auto dir = LoadViewFiles(grammar, "");
  ASSERT_TRUE(dir != nullptr);
  EXPECT_NE(Messages(dir->diagnostics).find("is a directory"), std::string::npos);
  std::filesystem::remove(Scratch() / "hostile.v");
  // No hostile.v: the scratch folder's several other .v files are not used
  // either (L-studio's one-.v rule, AnLStudioObjectUsesItsFoldersOnlyViewFile).
  auto none = LoadViewFiles(grammar, "");
  EXPECT_TRUE(!none || none->path.empty()) << none->path;
}

TEST(ViewFile, FunctionLinesGiveFuncItsFilesInOrder) {
  ViewFile v = ParseViewFile("function: a.func 100\nfunction: sub/b.func\n", "/x/p.v");
  EXPECT_TRUE(v.diagnostics.items.empty()) << Messages(v.diagnostics);
  ASSERT_EQ(v.functions.size(), 2u);
  EXPECT_EQ(v.functions[0].file, "/x/a.func");
  EXPECT_EQ(v.functions[0].line, 1);
  EXPECT_EQ(v.functions[0].column, 11);
  EXPECT_EQ(v.functions[1].file, "/x/sub/b.func");
  EXPECT_NE(Messages(ParseViewFile("function: a.func many\n", "p.v").diagnostics)
                .find("1:18 error: expected a number of samples, not 'many'"),
            std::string::npos);

  // Through the plant: func(1, x) reads the view file's first function.
  const std::string grammar = WriteFile("vf.l", "axiom: A(func(1, 0.25))\n");
  WriteFile("vf.v", "function: vf.func 100\n");
  WriteFile("vf.func",
            "range: 0.0 1.0\npoints: 4\n0 0\n0.333333 0.666667\n"
            "0.666667 1.333333\n1 2\n");
  plant::PlantSpec spec;
  spec.path = grammar;
  spec.until = plant::Stage::kWord;
  AttachViewFile(LoadViewFiles(grammar, ""), spec);
  plant::PlantResult r = plant::BuildPlant(spec);
  ASSERT_TRUE(r.plant.has_value()) << r.diagnostics.FormatAll();
  ASSERT_EQ(r.plant->word.params.size(), 1u);
  EXPECT_NEAR(r.plant->word.params[0], 0.5, 0.003) << r.plant->word.params[0];  // y = 2x
}

TEST(ViewFile, CurveLinesGiveCurveXTheirFilesAndSamples) {
  ViewFile v = ParseViewFile("curve: profile.con\ncurve: sub/b.con 40\n", "/x/p.v");
  EXPECT_TRUE(v.diagnostics.items.empty()) << Messages(v.diagnostics);
  ASSERT_EQ(v.curves.size(), 2u);
  EXPECT_EQ(v.curves[0].file, "/x/profile.con");
  EXPECT_EQ(v.curves[0].samples, 100);  // cpfg's default
  EXPECT_EQ(v.curves[0].line, 1);
  EXPECT_EQ(v.curves[0].column, 8);
  EXPECT_EQ(v.curves[1].file, "/x/sub/b.con");
  EXPECT_EQ(v.curves[1].samples, 40);
  EXPECT_NE(Messages(ParseViewFile("curve: a.con 1\n", "p.v").diagnostics)
                .find("1:14 error: a curve's samples must be a whole number from 2 to 1000000"),
            std::string::npos)
      << Messages(ParseViewFile("curve: a.con 1\n", "p.v").diagnostics);

  // Through the plant: curveGAL(1) is the length of the view file's curve.
  const std::string grammar = WriteFile("vc.l", "axiom: A(curveGAL(1), curveY(1, 0.5))\n");
  WriteFile("vc.v", "curve: vc.con\n");
  WriteFile("vc.con", "points: 4\ndimension: 4\n0 0 0 3\n0 1 0 1\n0 2 0 1\n0 3 0 3\n");
  plant::PlantSpec spec;
  spec.path = grammar;
  spec.until = plant::Stage::kWord;
  AttachViewFile(LoadViewFiles(grammar, ""), spec);
  plant::PlantResult r = plant::BuildPlant(spec);
  ASSERT_TRUE(r.plant.has_value()) << r.diagnostics.FormatAll();
  ASSERT_EQ(r.plant->word.params.size(), 2u);
  EXPECT_NEAR(r.plant->word.params[0], 3.0, 1e-5) << r.plant->word.params[0];
  EXPECT_NEAR(r.plant->word.params[1], 1.5, 1e-3) << r.plant->word.params[1];
}

// A curve: line with a bad number of samples is an error at that number,
// and the curve is still counted: before, the line was dropped and the
// grammar's curveX(1, t) failed with "the view file has no 'curve:' line",
// the only error shown.
TEST(ViewFile, BadCurveSamplesIsTheErrorShownNotAMissingCurve) {
  const std::string grammar = WriteFile("vcs.l", "axiom: A(curveX(1, 0.5))\n");
  WriteFile("vcs.v", "curve: vc.con 1000000000000\n");
  WriteFile("vc.con", "points: 4\ndimension: 4\n0 0 0 3\n0 1 0 1\n0 2 0 1\n0 3 0 3\n");
  auto view = LoadViewFiles(grammar, "");
  ASSERT_TRUE(view != nullptr);
  EXPECT_EQ(view->curves.size(), 1u) << Messages(view->diagnostics);
  plant::PlantSpec spec;
  spec.path = grammar;
  spec.until = plant::Stage::kWord;
  AttachViewFile(view, spec);
  plant::PlantResult r = plant::BuildPlant(spec);
  EXPECT_FALSE(r.plant.has_value());
  const std::string all = r.diagnostics.FormatAll();
  EXPECT_NE(all.find("vcs.v:1:15: error: a curve's samples must be a whole number"),
            std::string::npos)
      << all;
  EXPECT_EQ(all.find("no 'curve:' line"), std::string::npos) << all;
}

// An L-studio object (no NAME.v, no vlab `specifications`) finds its view
// file and colours by extension: the folder's one `.v` (view.v beside
// lsystem.l; RebeccaKuo's cloud objects were drawn without theirs, no
// word said). Several `.v` files: none is used, with a warning.
TEST(ViewFile, AnLStudioObjectUsesItsFoldersOnlyViewFile) {
  const std::filesystem::path dir = Scratch() / "lstudio";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "lsystem.l") << "axiom: F\n";
  std::ofstream(dir / "view.v") << "angle increment: 30\n";
  const std::string grammar = (dir / "lsystem.l").string();
  auto view = LoadViewFiles(grammar, "");
  ASSERT_NE(view, nullptr);
  EXPECT_EQ(view->path, (dir / "view.v").string()) << Messages(view->diagnostics);
  EXPECT_FALSE(view->diagnostics.HasErrors()) << Messages(view->diagnostics);
  std::ofstream(dir / "other.v") << "angle increment: 45\n";
  view = LoadViewFiles(grammar, "");
  ASSERT_NE(view, nullptr);
  EXPECT_TRUE(view->path.empty()) << view->path;
  EXPECT_NE(Messages(view->diagnostics).find("2 view files in its folder (other.v, view.v)"),
            std::string::npos)
      << Messages(view->diagnostics);
}

TEST(ViewFile, AFolderOfSeveralGrammarsIsNoLStudioObject) {
  // grammars/cpfg holds flower.l with flower.v beside sub_lsystem.l: the
  // one .v is flower's, not the folder's (sub_lsystem.l was drawn with it).
  const std::filesystem::path dir = Scratch() / "several_grammars";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "flower.l") << "axiom: F\n";
  std::ofstream(dir / "flower.v") << "angle increment: 30\n";
  std::ofstream(dir / "other.l") << "axiom: F\n";
  auto view = LoadViewFiles((dir / "other.l").string(), "");
  EXPECT_TRUE(!view || view->path.empty()) << view->path;
  view = LoadViewFiles((dir / "flower.l").string(), "");
  ASSERT_NE(view, nullptr);
  EXPECT_EQ(view->path, (dir / "flower.v").string()) << Messages(view->diagnostics);
}

TEST(ViewFile, BackgroundSceneIsDrawnWithThePlant) {
  const std::string grammar = WriteFile("bgs.l", "axiom: F(3)\n");
  WriteFile("bgs.v", "background scene: bgs.dat\n");
  WriteFile("bgs.dat", "material 0 0 0 1  0 0.5 0 1\npolygon -4 0 -4  -4 0 4  4 0 4  4 0 -4\n");
  plant::PlantSpec spec;
  spec.path = grammar;
  spec.until = plant::Stage::kGeometry;
  auto view = LoadViewFiles(grammar, "");
  ASSERT_NE(view, nullptr);
  EXPECT_FALSE(view->diagnostics.HasErrors()) << Messages(view->diagnostics);
  AttachViewFile(view, spec);
  plant::PlantResult r = plant::BuildPlant(spec);
  ASSERT_TRUE(r.plant.has_value()) << r.diagnostics.FormatAll();
  ASSERT_EQ(r.plant->geometry.polygons.size(), 1u);
  EXPECT_EQ(r.plant->geometry.segments.size(), 1u);
  EXPECT_NEAR(r.plant->geometry.boundsMin.x(), -4, 1e-12)
      << r.plant->geometry.boundsMin.transpose();
  const uint16_t c = r.plant->geometry.polygons[0].color;
  ASSERT_LT(c, r.plant->palette.size());
  EXPECT_NEAR(r.plant->palette[c].y(), mesh::SrgbToLinear(0.5f), 1e-6) << c;
  // A scene file that is not there (vlab's soil3d names one its environment
  // program writes): a warning at the view file's line, nothing drawn.
  WriteFile("bgs.v", "\nbackground scene: gone.dat\n");
  view = LoadViewFiles(grammar, "");
  ASSERT_NE(view, nullptr);
  EXPECT_NE(Messages(view->diagnostics).find("2:19 warning: background scene "), std::string::npos)
      << Messages(view->diagnostics);
  EXPECT_FALSE(view->diagnostics.HasErrors()) << Messages(view->diagnostics);
  EXPECT_TRUE(view->backgrounds.empty());
  // One that cannot be read (a directory): an error there.
  std::filesystem::create_directories(Scratch() / "bgdir.dat");
  WriteFile("bgs.v", "\nbackground scene: bgdir.dat\n");
  view = LoadViewFiles(grammar, "");
  ASSERT_NE(view, nullptr);
  EXPECT_NE(Messages(view->diagnostics).find("2:19 error: background scene:"), std::string::npos)
      << Messages(view->diagnostics);
}

// The background scenes of a view file have at most 4,194,304 vertices in
// all: a scene of 20,000 cylinders (2.88M vertices) named twice is an
// error at the second name (before: both read; 200 names of a 29,000
// cylinder scene ran out of memory).
TEST(ViewFile, BackgroundScenesHaveALimitOnVerticesInAll) {
  const std::string grammar = WriteFile("bgm.l", "axiom: F(3)\n");
  WriteFile("bgm.v", "background scene: bgm.dat\nbackground scene: x.dat;bgm.dat\n");
  std::string scene;
  for (int i = 0; i < 20000; ++i) scene += "cylinder 1 1\n";
  WriteFile("bgm.dat", scene);
  WriteFile("x.dat", "box 1 1 1\n");
  auto view = LoadViewFiles(grammar, "");
  ASSERT_NE(view, nullptr);
  const std::string all = Messages(view->diagnostics);
  EXPECT_NE(all.find("2:25 error: background scene: the scenes have more than 4194304 vertices"),
            std::string::npos)
      << all;
  EXPECT_EQ(view->backgrounds.size(), 2u) << all;
}

TEST(ViewFile, AFunctionSetLineGivesFuncItsFunctionsByName) {
  ViewFile v = ParseViewFile("function set: functions.fset\n", "/x/p.v");
  EXPECT_TRUE(v.diagnostics.items.empty()) << Messages(v.diagnostics);
  ASSERT_EQ(v.functions.size(), 1u);
  EXPECT_TRUE(v.functions[0].set);
  EXPECT_EQ(v.functions[0].file, "/x/functions.fset");
  EXPECT_EQ(v.functions[0].column, 15);
  // Through the plant: vlab's GettingStarted lychnis writes func(BR_ANGLE, t).
  const std::string grammar = WriteFile("fs.l", "axiom: A(func(RISE, 0.25), func(2, 0.5))\n");
  WriteFile("fs.v", "angle factor: 40\nfunction set: fs.fset\n");
  WriteFile("fs.fset",
            "funcgalleryver 1 1\nitems: 2\n"
            "fver 1 1\nname: FLAT\nsamples: 100\nflip: off\npoints: 4\n0 1\n0.3 1\n0.6 1\n1 1\n"
            "fver 1 1\nname: RISE\nsamples: 100\nflip: off\npoints: 4\n0 0\n0.333333 "
            "0.666667\n0.666667 1.333333\n1 2\n");
  plant::PlantSpec spec;
  spec.path = grammar;
  spec.until = plant::Stage::kWord;
  AttachViewFile(LoadViewFiles(grammar, ""), spec);
  plant::PlantResult r = plant::BuildPlant(spec);
  ASSERT_TRUE(r.plant.has_value()) << r.diagnostics.FormatAll();
  ASSERT_EQ(r.plant->word.params.size(), 2u);
  EXPECT_NEAR(r.plant->word.params[0], 0.5, 0.003) << r.plant->word.params[0];  // RISE is 2
  EXPECT_NEAR(r.plant->word.params[1], 1, 0.003) << r.plant->word.params[1];
}

TEST(ViewFile, TheTurtleDrawsWithTheViewFilesSettings) {
  const std::string grammar = WriteFile("vt.l", "axiom: F + F ; F ! F\n");
  WriteFile("vt.v",
            "angle increment: 30\ninitial color: 3\ncolor increment: 2\n"
            "initial line width: 0.5\nline width increment: 0\n");
  auto view = LoadViewFiles(grammar, "");
  ASSERT_TRUE(view != nullptr);
  plant::PlantSpec spec;
  spec.path = grammar;
  spec.until = plant::Stage::kGeometry;
  AttachViewFile(view, spec);
  plant::PlantResult r = plant::BuildPlant(spec);
  ASSERT_TRUE(r.plant.has_value()) << r.diagnostics.FormatAll();
  const auto& s = r.plant->geometry.segments;
  ASSERT_EQ(s.size(), 4u);
  // + turns by 30 degrees: the second segment ends at (-sin 30, 1 + cos 30).
  EXPECT_NEAR(s[1].end.x(), -0.5, 1e-12);
  EXPECT_NEAR(s[1].end.y(), 1 + std::sqrt(3.0) / 2, 1e-12);
  EXPECT_EQ(s[0].color, 3);
  EXPECT_EQ(s[2].color, 5);                       // ; adds the colour increment
  EXPECT_FLOAT_EQ(s[3].radiusStart, 0.25f);       // ! with an increment of 0: unchanged
  EXPECT_TRUE(r.plant->grammar.palette.empty());  // no colour file yet
  // A colour map beside the grammar becomes the palette (sRGB 255 -> linear 1).
  std::string map(768, '\0');
  map[3 * 5] = char(255);
  WriteFile("vt.map", map);
  spec.amendGrammar = nullptr;
  AttachViewFile(LoadViewFiles(grammar, ""), spec);
  plant::PlantResult colored = plant::BuildPlant(spec);
  ASSERT_TRUE(colored.plant.has_value()) << colored.diagnostics.FormatAll();
  ASSERT_EQ(colored.plant->palette.size(), 256u);
  EXPECT_FLOAT_EQ(colored.plant->palette[5].x(), 1.0f);
  EXPECT_FLOAT_EQ(colored.plant->palette[5].y(), 0.0f);
  EXPECT_FLOAT_EQ(colored.plant->palette[4].x(), 0.0f);
  std::filesystem::remove(Scratch() / "vt.v");
  std::filesystem::remove(Scratch() / "vt.map");
}

TEST(ViewFile, StrictMakesItsWarningsErrorsAndViewNamesTheFile) {
  const std::string grammar = WriteFile("vs.l", "axiom: F\n");
  const std::string view = WriteFile("other.v", "angle increment: 10\nshade mode: 2\n");
  auto plain = RunSylva({"derive", grammar, "--view", view});
  EXPECT_EQ(plain.code, 0) << plain.err;
  EXPECT_NE(plain.err.find("other.v:2:1: warning: 'shade mode:' is read but not acted on"),
            std::string::npos)
      << plain.err;
  auto strict = RunSylva({"derive", "--strict", grammar, "--view", view});
  EXPECT_EQ(strict.code, 2) << strict.err;
  auto check = RunSylva({"check", "--strict", grammar, "--view", view});
  EXPECT_EQ(check.code, 2) << check.err;
  EXPECT_NE(check.err.find("other.v:2:1: warning: 'shade mode:'"), std::string::npos) << check.err;
  auto bad = RunSylva({"derive", grammar, "--view", "/dev/null"});
  EXPECT_EQ(bad.code, 2) << bad.err;
  EXPECT_NE(bad.err.find("/dev/null: error: view file: is not a regular file"), std::string::npos)
      << bad.err;
}

TEST(ViewFile, ASurfaceFileThatIsNotThereWarnsAndDrawsNothing) {
  // vlab objects copied without one of their .s files (lychnis' calyx.s):
  // the plant opens, the surface is not drawn, the warning says which file.
  const std::string grammar = WriteFile("vm.l", "axiom: F [~c(1)] F\n");
  WriteFile("vm.v", "angle increment: 30\nsurface: c calyx_gone.s 2 3 3\n");
  auto view = LoadViewFiles(grammar, "");
  ASSERT_TRUE(view != nullptr);
  const std::string all = Messages(view->diagnostics);
  EXPECT_NE(all.find("2:12 warning: surface 'c' is not drawn: its file " +
                     (Scratch() / "calyx_gone.s").lexically_normal().string() + " does not exist"),
            std::string::npos)
      << all;
  ASSERT_EQ(view->surfaces.size(), 1u);
  EXPECT_TRUE(view->surfaces[0].missing);
  plant::PlantSpec spec;
  spec.path = grammar;
  spec.until = plant::Stage::kMesh;
  AttachViewFile(view, spec);
  plant::PlantResult r = plant::BuildPlant(spec);
  ASSERT_TRUE(r.plant.has_value()) << r.diagnostics.FormatAll();
  EXPECT_EQ(r.plant->geometry.surfaces.size(), 1u);
  EXPECT_GT(r.plant->mesh.triangleCount(), 0u);  // the two F
  EXPECT_EQ(r.diagnostics.ErrorCount(), 0u) << r.diagnostics.FormatAll();
  // --strict makes the warning an error.
  auto strict = RunSylva({"check", "--strict", grammar});
  EXPECT_EQ(strict.code, 2) << strict.err;
  EXPECT_NE(strict.err.find("vm.v:2:12: warning: surface 'c' is not drawn"), std::string::npos)
      << strict.err;
  // A surface file that exists but is malformed stays an error.
  WriteFile("calyx_gone.s", "not a surface\n");
  spec.amendGrammar = nullptr;
  AttachViewFile(LoadViewFiles(grammar, ""), spec);
  plant::PlantResult bad = plant::BuildPlant(spec);
  EXPECT_FALSE(bad.plant.has_value());
  EXPECT_GT(bad.diagnostics.ErrorCount(), 0u);
  std::filesystem::remove(Scratch() / "calyx_gone.s");
}

}  // namespace
}  // namespace sylva::app

namespace sylva::app {
namespace {

TEST(ViewFile, ContourLinesReadTheirFilesForCylinderLineStyle) {
  testing::WriteFile("ct_leaf.con", "5 3 open\n-1 0 0\n-1 0 0\n0 0.2 0\n1 0 0\n1 0 0\n");
  testing::WriteFile("CT_Sepal.con",
                     "cver 1 3\nname: s\npoints: 2 6\ntype: or\nsamples: 8\n"
                     "-1 0 0 3\n1 0 0 3\n");
  const std::string path = (testing::Scratch() / "ct.v").string();
  ViewFile v = ParseViewFile(
      "line style: cylinder\ncontour sides: 12\ntwist of cylinders: on\n"
      "contour: 1 ct_leaf.con\ncontour: 2 ct_sepal.con\ncontour: 3 ct_gone.con\n",
      path, /*checkFiles=*/true);
  EXPECT_FALSE(v.diagnostics.HasErrors()) << Messages(v.diagnostics);
  EXPECT_TRUE(v.cylinderStyle);
  EXPECT_EQ(v.contours.sides, 12);
  EXPECT_TRUE(v.contours.twist);
  ASSERT_EQ(v.contours.byId.size(), 2u) << Messages(v.diagnostics);
  EXPECT_EQ(v.contours.byId.at(1).points.size(), 5u);
  EXPECT_EQ(v.contours.byId.at(2).points.size(), 6u);
  // Found in another case, and missing: warnings at the file's name.
  const std::string all = Messages(v.diagnostics);
  ASSERT_EQ(v.diagnostics.items.size(), 2u) << all;
  EXPECT_EQ(all.rfind("5:12 warning: contour file ", 0), 0u) << all;
  EXPECT_NE(all.find("whose name differs in case"), std::string::npos) << all;
  EXPECT_NE(all.find("6:12 warning: contour 3 is not drawn: its file"), std::string::npos) << all;
  plant::PlantSpec spec;
  AttachViewFile(std::make_shared<const ViewFile>(v), spec);
  ASSERT_TRUE(spec.draw.contours != nullptr);
  EXPECT_EQ(spec.draw.contours->byId.size(), 2u);
  EXPECT_TRUE(spec.draw.cylinderStyle);
}

TEST(ViewFile, BadContourFileIsAnErrorAtItsOwnLine) {
  testing::WriteFile("ct_bad.con", "4 3 open\n0 0 0\n1 zero 0\n");
  const std::string path = (testing::Scratch() / "ctb.v").string();
  ViewFile v = ParseViewFile("line style: cylinder\ncontour: 1 ct_bad.con\n", path, true);
  ASSERT_EQ(v.diagnostics.ErrorCount(), 1u) << Messages(v.diagnostics);
  const Diagnostic& d = v.diagnostics.items[0];
  EXPECT_EQ(d.loc.file, (testing::Scratch() / "ct_bad.con").string());
  EXPECT_EQ(d.loc.line, 3);
  EXPECT_EQ(d.loc.column, 3);
  EXPECT_NE(d.message.find("expected a number"), std::string::npos) << d.message;
}

// A contour name that is a symbolic link to itself: one error saying so,
// not also a warning that the file "does not exist" and was found in
// another case (as the same name) before.
TEST(ViewFile, ContourSymlinkLoopIsOneErrorAtItsName) {
  const std::filesystem::path link = testing::Scratch() / "ct_loop.con";
  std::error_code ec;
  std::filesystem::remove(link, ec);
  std::filesystem::create_symlink("ct_loop.con", link);
  const std::string path = (testing::Scratch() / "ctl.v").string();
  ViewFile v = ParseViewFile("line style: cylinder\ncontour: 1 ct_loop.con\n", path, true);
  const std::string all = Messages(v.diagnostics);
  ASSERT_EQ(v.diagnostics.items.size(), 1u) << all;
  EXPECT_EQ(all.rfind("2:12 error: contour file ", 0), 0u) << all;
  EXPECT_NE(all.find("symbolic links"), std::string::npos) << all;
}

TEST(ViewFile, ContoursWithoutCylinderLineStyleWarnAndAreNotUsed) {
  testing::WriteFile("ct_p.con", "4 2 open\n-1 0\n-1 0\n1 0\n1 0\n");
  const std::string path = (testing::Scratch() / "ctp.v").string();
  ViewFile v = ParseViewFile("initial line width: 2 pixels\ncontour: 1 ct_p.con\n", path, true);
  ASSERT_EQ(v.diagnostics.items.size(), 1u) << Messages(v.diagnostics);
  EXPECT_EQ(v.diagnostics.items[0].loc.line, 2);
  EXPECT_NE(v.diagnostics.items[0].message.find("line style cylinder only"), std::string::npos)
      << Messages(v.diagnostics);
  plant::PlantSpec spec;
  AttachViewFile(std::make_shared<const ViewFile>(v), spec);
  EXPECT_TRUE(spec.draw.contours == nullptr);
  EXPECT_FALSE(spec.draw.cylinderStyle);
  // cpfg's older `polygonization level: n` is 2^(n+1) sides.
  ViewFile level =
      ParseViewFile("line style: cylinder\npolygonization level: 3\ncontour: 1 x.con\n", "l.v");
  EXPECT_TRUE(level.diagnostics.items.empty()) << Messages(level.diagnostics);
  EXPECT_EQ(level.contours.sides, 16);
  // A negative id (no @#(n) can name it) was accepted without a word.
  ViewFile negative = ParseViewFile("line style: cylinder\ncontour: -1 x.con\n", "n.v");
  ASSERT_EQ(negative.diagnostics.items.size(), 1u) << Messages(negative.diagnostics);
  EXPECT_EQ(
      negative.diagnostics.items[0].Format().rfind(
          "n.v:2:10: error: a contour id is a whole number from 0 (the n of @#(n)), not '-1'", 0),
      0u)
      << Messages(negative.diagnostics);
  // `contour sides:` alone (no contour) is read but not acted on.
  ViewFile s = ParseViewFile("contour sides: 16\n", "s.v");
  ASSERT_EQ(s.diagnostics.items.size(), 1u) << Messages(s.diagnostics);
  EXPECT_NE(s.diagnostics.items[0].message.find("no 'contour:' line"), std::string::npos);
}

}  // namespace
}  // namespace sylva::app
