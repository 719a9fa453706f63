#include "app/view_file.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "app/cli_test_util.h"

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
  ASSERT_TRUE(v.tropism.has_value());
  EXPECT_LT((*v.tropism - Vec3(0, -1, 0)).norm(), 1e-15);  // unit, as cpfg
  EXPECT_EQ(v.elasticity.value_or(-1), 0.15);              // E times I
  EXPECT_EQ(v.elasticityIncrement.value_or(-1), 0.01);
  auto dir = ViewDirection(v);
  ASSERT_TRUE(dir.has_value());
  EXPECT_NEAR((*dir)[0], 90, 1e-12);  // from +X
  EXPECT_NEAR((*dir)[1], 0, 1e-12);
  EXPECT_EQ(ParseViewFile("angle factor: 16\n", "p.v").angle.value_or(-1), 22.5);
}

TEST(ViewFile, TropismLettersMayCarryAColonAndAnAttachedValue) {
  // As vlab's published view files write them.
  ViewFile v = ParseViewFile("tropism: T: 0.0 -1.0 0.0  A:0 E: 0.3\n", "p.v");
  EXPECT_TRUE(v.diagnostics.items.empty()) << Messages(v.diagnostics);
  ASSERT_TRUE(v.tropism.has_value());
  EXPECT_LT((*v.tropism - Vec3(0, -1, 0)).norm(), 1e-15) << v.tropism->transpose();
  EXPECT_EQ(v.elasticity.value_or(-1), 0.3);
  ViewFile angled = ParseViewFile("tropism: T: 0 1 0  A:90\n", "p.v");
  EXPECT_NE(Messages(angled.diagnostics).find("1:22 warning: a tropism at an angle"),
            std::string::npos)
      << Messages(angled.diagnostics);
  // A zero tropism direction bends nothing, as in cpfg: no tropism, no error.
  ViewFile none = ParseViewFile("tropism direction: 0.0,0.0,0.0\ninitial elasticity: 0.2\n", "p.v");
  EXPECT_TRUE(none.diagnostics.items.empty()) << Messages(none.diagnostics);
  EXPECT_FALSE(none.tropism.has_value());
}

TEST(ViewFile, WarnsOncePerLabelItDoesNotActOnWithItsLocation) {
  ViewFile v = ParseViewFile(
      "twist: 0\nz buffer: on\nprojection: perspective\n"  // as Sylva draws: silent
      "light direction: 1,1,1\n"
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
  EXPECT_NE(all.find("4:1 warning: 'light direction:' is read but not acted on"), std::string::npos)
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
  EXPECT_EQ(first("angle factor: 0\n").rfind("1:15 error", 0), 0u);
  EXPECT_EQ(first("tropism: E 0.2\n").rfind("1:1 error: 'tropism:' needs its vector", 0), 0u);
  EXPECT_EQ(first("tropism: T 0,0,0 E 1\n").rfind("1:12 error", 0), 0u);
  EXPECT_EQ(first("tropism: T 0,1,0 A 30\n").rfind("1:20 warning: a tropism at an angle", 0), 0u);
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
  EXPECT_EQ(LoadViewFiles(grammar, ""), nullptr);  // nothing beside it
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

}  // namespace
}  // namespace sylva::app
