#include "app/cpfg_specifications.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "app/cli_test_util.h"
#include "app/view_file.h"

namespace sylva::app {
namespace {

namespace fs = std::filesystem;
using testing::Scratch;

// A vlab object's folder of its own under the scratch folder.
fs::path Object(const std::string& name) {
  fs::path dir = Scratch() / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void Write(const fs::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

TEST(CpfgSpecifications, ReadsTheFilesOfEachCpfgLineAsCpfgsCommandLineDoes) {
  auto c = ParseCpfgCommands(
      "lamp.l\nview.v\nignore:\n*\nlamp:\n\tgenerate:\n"
      "\t\tcpfg -a -w 300 500 -M materials.mat -e lamp.e lamp.l view.v anim.a\n"
      "\tother:\n\t\tloadmap x.map;cpfg3.2 -sb -g -rgb \"a b.rgb\" -m2 b.map -m1 a.map -v f.l f.v\n"
      "\t\tcpfg -Q x.l\n",
      "specifications");
  ASSERT_EQ(c.size(), 3u);
  EXPECT_EQ(c[0].loc.line, 7);
  EXPECT_EQ(c[0].loc.column, 3);
  EXPECT_EQ(c[0].lsystem, "lamp.l");
  EXPECT_EQ(c[0].view, "view.v");
  EXPECT_EQ(c[0].animation, "anim.a");
  EXPECT_EQ(c[0].material, "materials.mat");
  EXPECT_TRUE(c[0].materialWins);
  EXPECT_EQ(c[0].environment, "lamp.e");
  // -w takes two numbers, -rgb a (quoted) file name; -m1 wins over -m2.
  EXPECT_EQ(c[1].lsystem, "f.l");
  EXPECT_EQ(c[1].view, "f.v");
  EXPECT_EQ(c[1].colormap, "a.map");
  EXPECT_FALSE(c[1].materialWins);
  EXPECT_TRUE(c[1].unknownOptions.empty());
  ASSERT_EQ(c[2].unknownOptions.size(), 1u);
  EXPECT_EQ(c[2].unknownOptions[0], "-Q");
}

TEST(CpfgSpecifications, ViewFileNotNamedAfterTheGrammarIsRead) {
  const fs::path dir = Object("spec_lamp");
  Write(dir / "lamp.l", "axiom: F\n");
  Write(dir / "view.v", "angle increment: 22.5\n");
  Write(dir / "specifications", "generate:\n\tcpfg -M materials.mat lamp.l view.v\n");
  std::string mat(15, '\0');
  mat[0] = 2;
  mat[5] = char(255);  // diffuse red of material 2
  Write(dir / "materials.mat", mat);
  auto v = LoadViewFiles((dir / "lamp.l").string(), "");
  ASSERT_TRUE(v != nullptr);
  EXPECT_EQ(v->path, (dir / "view.v").string());
  EXPECT_EQ(v->angle.value_or(-1), 22.5);
  EXPECT_EQ(v->colorsPath, (dir / "materials.mat").string());
  ASSERT_EQ(v->palette.size(), 256u);
  EXPECT_FLOAT_EQ(v->palette[2][0], 1.0f);
  EXPECT_TRUE(v->diagnostics.items.empty()) << v->diagnostics.FormatAll();

  // lamp.v beside the grammar wins, as before.
  Write(dir / "lamp.v", "angle increment: 30\n");
  auto own = LoadViewFiles((dir / "lamp.l").string(), "");
  ASSERT_TRUE(own != nullptr);
  EXPECT_EQ(own->angle.value_or(-1), 30);
}

TEST(CpfgSpecifications, MissingNamedFilesWarnAndHostileSpecificationsAreNotRead) {
  const fs::path dir = Object("spec_missing");
  Write(dir / "p.l", "axiom: F\n");
  Write(dir / "specifications", "x:\n  cpfg -m p.map p.l gone.v\n");
  auto v = LoadViewFiles((dir / "p.l").string(), "");
  ASSERT_TRUE(v != nullptr);
  const std::string all = v->diagnostics.FormatAll();
  EXPECT_FALSE(v->diagnostics.HasErrors()) << all;
  EXPECT_NE(all.find("specifications:2:3"), std::string::npos) << all;
  EXPECT_NE(all.find("view file 'gone.v', which is not in the object's folder"), std::string::npos)
      << all;
  EXPECT_NE(all.find("colour map 'p.map'"), std::string::npos) << all;

  const fs::path huge = Object("spec_huge");
  Write(huge / "p.l", "axiom: F\n");
  Write(huge / "specifications", std::string(size_t(2) << 20, 'x'));
  auto h = LoadViewFiles((huge / "p.l").string(), "");
  ASSERT_TRUE(h != nullptr);
  EXPECT_NE(h->diagnostics.FormatAll().find("larger than the limit"), std::string::npos)
      << h->diagnostics.FormatAll();
  EXPECT_TRUE(h->path.empty());

  // Thousands of cpfg lines of many words: bounded.
  std::string many;
  for (int i = 0; i < 20000; ++i) many += "cpfg " + std::string(200, 'a') + " -w 1 2\n";
  EXPECT_LE(ParseCpfgCommands(many, "s").size(), 4096u);
}

}  // namespace
}  // namespace sylva::app
