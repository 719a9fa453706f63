// `sylva mesh scene.xml`: glTF of a scene, read back with nlohmann-json
// (the GLB's JSON chunk). The Khronos validator runs on the same files in
// tests/scene/validate_scene_exports.sh.
#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>
#include <set>

#include "app/cli_test_util.h"

namespace sylva::app {
namespace {

using nlohmann::json;
using testing::RunSylva;
using testing::Scratch;
using testing::Source;
using testing::WriteFile;

// The JSON chunk of a .glb (glTF 2.0 section 4.4), or a .gltf file;
// null when the file is missing or malformed.
json ReadGltfJson(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  if (bytes.size() >= 20 && bytes.compare(0, 4, "glTF") == 0) {
    uint32_t length = 0, type = 0;
    std::memcpy(&length, bytes.data() + 12, 4);
    std::memcpy(&type, bytes.data() + 16, 4);
    if (type != 0x4E4F534Au || 20 + size_t(length) > bytes.size()) return nullptr;
    return json::parse(bytes.substr(20, length), nullptr, false);
  }
  json j = json::parse(bytes, nullptr, false);
  return j.is_discarded() ? json() : j;
}

std::string Forest50() {
  return Source("tests/scene/data/forest50.xml");
}

TEST(CliMeshScene, ForestTreesAreNodesSharingAtMostVariantsMeshes) {
  const std::string out = (Scratch() / "forest50.glb").string();
  auto r = RunSylva({"mesh", Forest50(), "-o", out, "--time", "1"});
  ASSERT_EQ(r.code, 0) << r.err;
  const json j = ReadGltfJson(out);
  ASSERT_TRUE(j.is_object()) << "no glTF JSON in " << out;
  std::set<int> treeMeshes;
  size_t trees = 0;
  for (const json& node : j["nodes"]) {
    const std::string name = node.value("name", "");
    if (name.rfind("woods/", 0) != 0) continue;
    ++trees;
    ASSERT_TRUE(node.contains("mesh")) << name;
    treeMeshes.insert(node["mesh"].get<int>());
    ASSERT_TRUE(node.contains("translation") && node.contains("rotation") && node.contains("scale"))
        << node.dump();
    EXPECT_FALSE(node.contains("matrix")) << node.dump();
    const std::vector<double> q = node["rotation"].get<std::vector<double>>();
    const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    EXPECT_NEAR(norm, 1.0, 1e-6) << name;
    // A tree stands upright: it turns about Y only, scaled uniformly (0.8 to 1.2 of its
    // height unit).
    EXPECT_NEAR(q[0], 0.0, 1e-6) << name;
    EXPECT_NEAR(q[2], 0.0, 1e-6) << name;
    const std::vector<double> s = node["scale"].get<std::vector<double>>();
    EXPECT_NEAR(s[0], s[1], 1e-5 * s[0]) << name;
    EXPECT_NEAR(s[0], s[2], 1e-5 * s[0]) << name;
  }
  EXPECT_EQ(trees, 50u) << r.err;
  EXPECT_GE(treeMeshes.size(), 1u);
  EXPECT_LE(treeMeshes.size(), 4u) << "variants=\"4\" in " << Forest50();
  for (int m : treeMeshes)
    EXPECT_EQ(j["meshes"][m]["name"].get<std::string>().rfind("woods variant ", 0), 0u)
        << j["meshes"][m].dump();
  // The terrain once, the snow as points and the sparks as lines, with colours.
  size_t terrains = 0, points = 0, lineEnds = 0;
  for (const json& node : j["nodes"]) terrains += node.value("name", "") == "hill";
  for (const json& mesh : j["meshes"]) {
    for (const json& p : mesh["primitives"]) {
      const int mode = p.value("mode", 4);
      if (mode != 0 && mode != 1) continue;
      const size_t n = j["accessors"][p["attributes"]["COLOR_0"].get<int>()]["count"].get<size_t>();
      (mode == 0 ? points : lineEnds) += n;
      EXPECT_EQ(mesh["name"], mode == 0 ? "snow" : "sparks");
    }
  }
  EXPECT_EQ(terrains, 1u);
  EXPECT_GT(points, 0u) << "snow at t = 1 s";
  EXPECT_GT(lineEnds, 0u) << "sparks at t = 1 s";
  EXPECT_EQ(lineEnds % 2, 0u);
  EXPECT_NE(r.err.find(": t = 1.000 s, "), std::string::npos) << r.err;
}

TEST(CliMeshScene, SameBytesForAnyThreadCount) {
  std::string bytes[2];
  for (int k = 0; k < 2; ++k) {
    const std::string threads = k == 0 ? "1" : "3";
    const std::string out = (Scratch() / ("threads" + threads + ".glb")).string();
    auto r = RunSylva({"mesh", Forest50(), "-o", out, "--time", "1", "--threads", threads});
    ASSERT_EQ(r.code, 0) << r.err;
    std::ifstream f(out, std::ios::binary);
    bytes[k].assign(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
  }
  EXPECT_GT(bytes[0].size(), 1000u);
  EXPECT_TRUE(bytes[0] == bytes[1]) << "sizes " << bytes[0].size() << " and " << bytes[1].size();
}

TEST(CliMeshScene, SnowAtTwoSecondsIsAPointCloudWithColours) {
  const std::string out = (Scratch() / "snowy.gltf").string();
  auto r = RunSylva({"mesh", Source("examples/scenes/snowy_forest.xml"), "-o", out, "--time", "2"});
  ASSERT_EQ(r.code, 0) << r.err;
  const json j = ReadGltfJson(out);
  ASSERT_TRUE(j.is_object());
  size_t points = 0;
  for (const json& mesh : j["meshes"]) {
    for (const json& p : mesh["primitives"]) {
      if (p.value("mode", 4) != 0) continue;
      ASSERT_TRUE(p["attributes"].contains("COLOR_0")) << p.dump();
      const json& position = j["accessors"][p["attributes"]["POSITION"].get<int>()];
      const json& color = j["accessors"][p["attributes"]["COLOR_0"].get<int>()];
      EXPECT_EQ(position["count"], color["count"]);
      EXPECT_EQ(color["type"], "VEC3");
      points += position["count"].get<size_t>();
    }
  }
  EXPECT_GT(points, 1000u) << r.err;
}

TEST(CliMeshScene, FireworksSparksAreExportedAsPoints) {
  const std::string out = (Scratch() / "fireworks.glb").string();
  auto r = RunSylva({"mesh", Source("examples/scenes/fireworks.xml"), "-o", out, "--time", "3"});
  ASSERT_EQ(r.code, 0) << r.err;
  const json j = ReadGltfJson(out);
  ASSERT_TRUE(j.is_object());
  size_t sparks = 0;
  for (const json& node : j["nodes"])
    if (node.value("name", "") == "sparks")
      sparks = j["accessors"]
                [j["meshes"][node["mesh"].get<int>()]["primitives"][0]["attributes"]["POSITION"]
                     .get<int>()]["count"]
                    .get<size_t>();
  EXPECT_GT(sparks, 100u) << "a shell bursts into 300 sparks before t = 3 s; " << r.err;
}

TEST(CliMeshScene, BoidsAreNodesSharingOneMesh) {
  const std::string out = (Scratch() / "flock.glb").string();
  auto r = RunSylva({"mesh", Source("examples/scenes/flock.xml"), "-o", out, "--time", "1"});
  ASSERT_EQ(r.code, 0) << r.err;
  const json j = ReadGltfJson(out);
  ASSERT_TRUE(j.is_object());
  // examples/scenes/flock.xml: <flock id="birds" count="400">.
  std::set<int> meshes;
  size_t boids = 0;
  for (const json& node : j["nodes"]) {
    if (node.value("name", "").rfind("birds/", 0) != 0) continue;
    ++boids;
    meshes.insert(node["mesh"].get<int>());
  }
  EXPECT_EQ(meshes.size(), 1u) << "one colour, one mesh";
  EXPECT_EQ(boids, 400u) << r.err;
}

TEST(CliMeshScene, ObjAndPlyOfASceneAreExitTwoAndWriteNothing) {
  for (const char* ext : {"obj", "ply", "stl"}) {
    const std::string out = (Scratch() / (std::string("scene.") + ext)).string();
    auto r = RunSylva({"mesh", Forest50(), "-o", out});
    EXPECT_EQ(r.code, 2) << ext << ": " << r.err;
    EXPECT_FALSE(std::filesystem::exists(out)) << out;
    EXPECT_NE(
        r.err.find(std::string(ext) == "stl" ? "unknown mesh format" : "glTF (.glb or .gltf)"),
        std::string::npos)
        << r.err;
  }
}

TEST(CliMeshScene, SceneErrorIsExitTwoAndWritesNothing) {
  const std::string bad = WriteFile("bad_scene.xml",
                                    "<scene version=\"1\">\n"
                                    "  <terrain size=\"10 10\" resoluton=\"9\"/>\n"
                                    "</scene>\n");
  const std::string out = (Scratch() / "bad.glb").string();
  auto r = RunSylva({"mesh", bad, "-o", out});
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("bad_scene.xml:2:"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out));
  // An unknown -D name too.
  auto d = RunSylva({"mesh", Forest50(), "-D", "nosuch=3", "-o", out});
  EXPECT_EQ(d.code, 2) << d.err;
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(CliMeshScene, GrammarFlagsOnASceneAndTimeOnAGrammarAreExitTwo) {
  const std::string out = (Scratch() / "flags.glb").string();
  for (const char* flag : {"-n", "--seed", "--max-modules", "--max-triangles"}) {
    auto r = RunSylva({"mesh", Forest50(), flag, "3", "-o", out});
    EXPECT_EQ(r.code, 2) << flag << ": " << r.err;
    EXPECT_NE(r.err.find("are for grammars"), std::string::npos) << r.err;
  }
  auto time =
      RunSylva({"mesh", Source("grammars/abop/fig1_25_bush.lsys"), "--time", "1", "-o", out});
  EXPECT_EQ(time.code, 2) << time.err;
  EXPECT_NE(time.err.find("--time is for scene files"), std::string::npos) << time.err;
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(CliMeshScene, UnwritableOutputIsExitOne) {
  auto r = RunSylva({"mesh", Forest50(), "-o", "/nonexistent-dir/forest.glb"});
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("/nonexistent-dir/forest.glb: error: cannot create output file"),
            std::string::npos)
      << r.err;
}

}  // namespace
}  // namespace sylva::app
