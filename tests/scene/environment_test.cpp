// Plants of a scene in their environment: a <plant> whose grammar says
// `environment: terrain` reads the scene's terrain under it through ?E, in
// its own coordinates (plant/ground_environment.h); those that say
// `environment: light` grow together in one light grid (plant/grow_together.h).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "scene/build.h"
#include "scene/reader.h"
#include "scratch_dir.h"

namespace sylva::scene {
namespace {

constexpr double kPi = 3.14159265358979323846;

TEST(SceneGround, PlantQueriesReadTheTerrainUnderThemThroughTheirPlacement) {
  const auto dir = sylva::testing::ScratchDir("sylva_scene_ground_");
  std::ofstream(dir / "g.lsys") << "environment: terrain\n"
                                   "axiom: [ +(90) f(3) ?E(0,0,0,0) ] [ -(90) f(2) &(90) f(1.5) "
                                   "?E(0,0,0,0) ]\n";
  const std::string path = (dir / "s.xml").string();
  std::ofstream(path) << "<?xml version=\"1.0\"?>\n<scene version=\"1\" seed=\"3\">\n"
                         "<terrain id=\"land\" size=\"60 60\" resolution=\"65\" height=\"4\" "
                         "noise=\"fbm\" seed=\"9\"/>\n"
                         "<plant grammar=\"g.lsys\" position=\"5 -4\" rotate=\"30\" scale=\"2\"/>\n"
                         "<plant grammar=\"g.lsys\" position=\"5 -4\" rotate=\"30\" scale=\"2\" "
                         "height=\"3\"/>\n"
                         "</scene>\n";
  ReadResult r = ReadScene(path);
  ASSERT_TRUE(r.scene) << r.diagnostics.FormatAll();
  const BuildResult b = Build(*r.scene, {});
  ASSERT_TRUE(b.scene) << b.diagnostics.FormatAll();
  const BuiltScene& s = *b.scene;
  // The plant's mesh: the one with a plant after the terrain.
  const plant::Plant* p = nullptr;
  for (const BuiltMesh& m : s.meshes)
    if (m.plant && !p) p = m.plant.get();
  ASSERT_NE(p, nullptr);
  const Vec3 at(5, s.GroundHeight(5, -4), -4);
  const Eigen::Matrix3d rot = Eigen::AngleAxisd(30 * kPi / 180, Vec3::UnitY()).toRotationMatrix();
  // The queries' own positions: +(90) f(3) goes to (-3, 0, 0); -(90) f(2)
  // to (2, 0, 0), then &(90) turns H to U = (0, 0, -1) and f(1.5) goes on
  // to (2, 0, -1.5). The plant stands on the terrain ("x z" position).
  const Vec3 local[2] = {Vec3(-3, 0, 0), Vec3(2, 0, -1.5)};
  int seen = 0;
  for (size_t i = 0; i < p->word.size(); ++i) {
    if (p->grammar.symbols.name(p->word.symbols[i]) != "?E") continue;
    ASSERT_LT(seen, 2);
    const auto e = p->word.ParamsOf(i);
    const Vec3 w = at + rot * (2 * local[seen]);
    const double want = (s.GroundHeight(w.x(), w.z()) - at.y()) / 2;
    EXPECT_NEAR(e[0], want, 1e-9) << "query " << seen << " at world " << w.transpose();
    EXPECT_GT(std::abs(want), 1e-3) << "the terrain is not flat there";
    const Vec3 n = rot.transpose() * s.terrains[0].Normal(w.x(), w.z());
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(e[1 + c], n[c], 1e-9) << "normal component " << c;
    ++seen;
  }
  EXPECT_EQ(seen, 2);
  // The second plant's `height` rescales it after it grew: said, at it.
  const std::string all = b.diagnostics.FormatAll();
  EXPECT_NE(all.find("s.xml:5:1: warning: 'height' rescales this plant after it grew"),
            std::string::npos)
      << all;
}

// The words of the scene's plants, in order.
std::vector<std::string> Words(const BuiltScene& s) {
  std::vector<std::string> out;
  for (const BuiltMesh& m : s.meshes)
    if (m.plant) out.push_back(lsys::FormatWord(m.plant->word, m.plant->grammar.symbols));
  return out;
}

BuildResult BuildScene(const std::filesystem::path& dir, const std::string& body) {
  const std::string path = (dir / "s.xml").string();
  std::ofstream(path) << "<?xml version=\"1.0\"?>\n<scene version=\"1\" seed=\"3\">\n"
                      << body << "</scene>\n";
  ReadResult r = ReadScene(path);
  EXPECT_TRUE(r.scene) << r.diagnostics.FormatAll();
  if (!r.scene) return {};
  return Build(*r.scene, {});
}

TEST(SceneLight, PlantsThatSayLightCompeteInOneGrid) {
  const auto dir = sylva::testing::ScratchDir("sylva_scene_light_");
  // A tip grows while it has nearly full light; each plant alone would.
  std::ofstream(dir / "tip.lsys") << "environment: light cell=1 depth=3 shadow=0.2\n"
                                     "derivation length: 3\n"
                                     "axiom: A ?E(0)\n"
                                     "A > ?E(e) : e > 0.9 --> F A\n";
  std::ofstream(dir / "tip2.lsys") << "environment: light cell=2 depth=3 shadow=0.2\n"
                                      "derivation length: 3\n"
                                      "axiom: A ?E(0)\n"
                                      "A > ?E(e) : e > 0.9 --> F A\n";
  // Two in one voxel column shade each other (1 - 0.2); one far away does not.
  const BuildResult b = BuildScene(dir,
                                   "<plant grammar=\"tip.lsys\" position=\"0.3 0.5\"/>\n"
                                   "<plant grammar=\"tip.lsys\" position=\"0.7 0.5\"/>\n"
                                   "<plant grammar=\"tip.lsys\" position=\"20.5 0.5\"/>\n");
  ASSERT_TRUE(b.scene) << b.diagnostics.FormatAll();
  EXPECT_EQ(Words(*b.scene), (std::vector<std::string>{"A?E(0.8)", "A?E(0.8)", "FFFA?E(1)"}));
  // (The two that never grow draw nothing, and say so; nothing else.)
  EXPECT_EQ(b.diagnostics.FormatAll().find("differs"), std::string::npos)
      << b.diagnostics.FormatAll();
  // A plant whose light statement differs shares the first one's grid, with
  // a warning at it; `height` warns that the light was read at `scale`.
  const BuildResult c = BuildScene(dir,
                                   "<plant grammar=\"tip.lsys\" position=\"0.3 0.5\"/>\n"
                                   "<plant grammar=\"tip2.lsys\" position=\"0.7 0.5\" "
                                   "height=\"2\"/>\n");
  ASSERT_TRUE(c.scene) << c.diagnostics.FormatAll();
  EXPECT_EQ(Words(*c.scene), (std::vector<std::string>{"A?E(0.8)", "A?E(0.8)"}));
  const std::string all = c.diagnostics.FormatAll();
  EXPECT_NE(all.find("s.xml:4:1: warning: this plant's 'environment: light'"), std::string::npos)
      << all;
  EXPECT_NE(all.find("differs from the first light plant's"), std::string::npos) << all;
}

}  // namespace
}  // namespace sylva::scene
