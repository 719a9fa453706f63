// The scene's simulation clock (simulation.h) on small scenes read from
// memory.
#include "scene/simulation.h"

#include <gtest/gtest.h>

#include <sstream>

#include "scene/reader.h"

namespace sylva::scene {
namespace {

struct World {
  Scene scene;
  BuiltScene built;
  std::unique_ptr<Simulation> sim;
};

std::unique_ptr<World> Load(const std::string& text, int threads = 1) {
  ReadOptions o;
  o.readFile = [&](const std::string&) -> Expected<std::string> { return text; };
  ReadResult r = ReadScene("s.xml", o);
  EXPECT_TRUE(r.scene) << r.diagnostics.FormatAll();
  if (!r.scene) return nullptr;
  auto w = std::make_unique<World>();
  w->scene = std::move(*r.scene);
  BuildResult b = Build(w->scene, {});
  EXPECT_TRUE(b.scene) << b.diagnostics.FormatAll();
  if (!b.scene) return nullptr;
  w->built = std::move(*b.scene);
  DiagnosticList d;
  SimulationOptions options;
  options.threads = threads;
  auto sim = Simulation::Create(w->scene, w->built, options, d);
  EXPECT_TRUE(sim) << (sim ? "" : sim.error().Format());
  if (!sim) return nullptr;
  w->sim = std::move(*sim);
  return w;
}

std::string Csv(const Simulation& sim) {
  std::ostringstream out;
  sim.WriteCsv(out);
  return out.str();
}

// Snow that sticks where it lands stays there while gusts blow over it
// (the wind's drag is not even sampled for immovable particles).
TEST(SceneSimulation, StuckParticlesStayPutInAGustingWind) {
  const auto w = Load(
      "<scene version=\"1\">\n"
      "  <wind velocity=\"4 0 1\" gust=\"2\" scale=\"3\" frequency=\"0.5\"/>\n"
      "  <particles id=\"snow\" max=\"500\">\n"
      "    <emitter shape=\"box\" at=\"0 1 0\" size=\"2 0.2 2\" burst=\"500\" lifetime=\"100\" "
      "mass=\"0.001\" radius=\"0.01\"/>\n"
      "    <gravity/>\n    <drag k=\"0.002\"/>\n"
      "    <collide with=\"ground\" stick=\"true\"/>\n"
      "  </particles>\n"
      "  <simulation fps=\"30\" substeps=\"2\"/>\n"
      "</scene>\n");
  ASSERT_TRUE(w);
  ASSERT_TRUE(w->sim->AdvanceTo(4).ok());
  ASSERT_EQ(w->sim->Count(), 500u);
  const std::string landed = Csv(*w->sim);
  ASSERT_TRUE(w->sim->AdvanceTo(8).ok());
  // Every row but the age column is the same four seconds later.
  auto withoutAge = [](const std::string& csv) {
    std::istringstream in(csv);
    std::string line, out;
    while (std::getline(in, line)) out += line.substr(0, line.rfind(',')) + "\n";
    return out;
  };
  EXPECT_EQ(withoutAge(Csv(*w->sim)), withoutAge(landed));
  // And they are on the ground (y about 0), not held in the air.
  std::istringstream in(landed);
  std::string line;
  std::getline(in, line);  // header
  int rows = 0;
  while (std::getline(in, line)) {
    std::vector<double> v;
    std::istringstream cells(line.substr(line.find(',') + 1));
    for (std::string c; std::getline(cells, c, ',');) v.push_back(std::stod(c));
    ASSERT_GE(v.size(), 4u) << line;
    EXPECT_NEAR(v[2], 0, 0.05) << "y of " << line;
    ++rows;
  }
  EXPECT_EQ(rows, 500);
}

}  // namespace
}  // namespace sylva::scene
