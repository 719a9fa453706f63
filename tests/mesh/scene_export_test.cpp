// mesh/scene_export.h: TRS decomposition against matrices built from known
// parts, and the glTF document of tiny hand-made scenes read back as JSON.
#include "mesh/scene_export.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>

#include "scratch_dir.h"

namespace sylva::mesh {
namespace {

using nlohmann::json;

Mat4f Compose(const Vec3f& t, const Quatf& r, const Vec3f& s) {
  Eigen::Affine3f a = Eigen::Affine3f::Identity();
  a.translate(t);
  a.rotate(r);
  a.scale(s);
  return a.matrix();
}

TEST(DecomposeTrs, RecoversTranslationRotationAndScale) {
  const Vec3f t(3, -2, 7.5f);
  const Quatf r = Quatf(Eigen::AngleAxisf(1.1f, Vec3f(0.3f, 0.9f, -0.2f).normalized()));
  const Vec3f s(0.5f, 2, 1.25f);
  std::string why;
  const auto trs = DecomposeTrs(Compose(t, r, s), &why);
  ASSERT_TRUE(trs) << why;
  EXPECT_LT((trs->translation - t).norm(), 1e-6f) << trs->translation.transpose();
  EXPECT_LT((trs->scale - s).norm(), 1e-5f) << trs->scale.transpose();
  // q and -q are the same turn.
  const float dot = std::abs(trs->rotation.coeffs().dot(r.coeffs()));
  EXPECT_NEAR(dot, 1.0f, 1e-5f) << trs->rotation.coeffs().transpose();
  EXPECT_NEAR(trs->rotation.norm(), 1.0f, 1e-6f);
  EXPECT_LT((Compose(trs->translation, trs->rotation, trs->scale) - Compose(t, r, s)).norm(),
            1e-5f);
}

TEST(DecomposeTrs, MirrorBecomesANegativeScale) {
  const Mat4f m =
      Compose(Vec3f(1, 2, 3), Quatf(Eigen::AngleAxisf(0.4f, Vec3f::UnitY())), Vec3f(1, -2, 3));
  std::string why;
  const auto trs = DecomposeTrs(m, &why);
  ASSERT_TRUE(trs) << why;
  EXPECT_LT(trs->scale.x(), 0) << trs->scale.transpose();
  EXPECT_NEAR(trs->scale.prod(), -6.0f, 1e-4f) << trs->scale.transpose();
  EXPECT_LT((Compose(trs->translation, trs->rotation, trs->scale) - m).norm(), 1e-5f);
}

TEST(DecomposeTrs, ZeroScaleAxisKeepsAUnitRotation) {
  for (int axis = 0; axis < 3; ++axis) {
    Vec3f s(2, 3, 4);
    s[axis] = 0;
    const Mat4f m =
        Compose(Vec3f(1, 0, 0), Quatf(Eigen::AngleAxisf(0.7f, Vec3f(1, 1, 0).normalized())), s);
    std::string why;
    const auto trs = DecomposeTrs(m, &why);
    ASSERT_TRUE(trs) << why;
    EXPECT_NEAR(trs->rotation.norm(), 1.0f, 1e-6f) << axis;
    EXPECT_LT((Compose(trs->translation, trs->rotation, trs->scale) - m).norm(), 1e-5f) << axis;
  }
  std::string why;
  const auto point = DecomposeTrs(Compose(Vec3f(1, 2, 3), Quatf::Identity(), Vec3f(0, 0, 5)), &why);
  ASSERT_TRUE(point) << why;
  EXPECT_NEAR(point->scale.z(), 5.0f, 1e-6f);
}

TEST(DecomposeTrs, ShearProjectionAndNaNAreRefused) {
  Mat4f shear = Mat4f::Identity();
  shear(0, 1) = 0.5f;
  std::string why;
  EXPECT_FALSE(DecomposeTrs(shear, &why));
  EXPECT_NE(why.find("shears"), std::string::npos) << why;
  Mat4f projective = Mat4f::Identity();
  projective(3, 2) = -1;
  EXPECT_FALSE(DecomposeTrs(projective, &why));
  EXPECT_NE(why.find("bottom row"), std::string::npos) << why;
  for (int i = 0; i < 3; ++i) {  // NaN in x, y and z of the translation
    Mat4f m = Mat4f::Identity();
    m(i, 3) = std::numeric_limits<float>::quiet_NaN();
    EXPECT_FALSE(DecomposeTrs(m, &why)) << i;
    EXPECT_NE(why.find("not finite"), std::string::npos) << why;
  }
}

// A unit square in the XZ plane with two materials.
std::shared_ptr<const TriangleMesh> Square() {
  auto m = std::make_shared<TriangleMesh>();
  m->positions = {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}};
  m->normals.assign(4, Vec3f(0, 1, 0));
  m->uvs.assign(4, Vec2f(0, 0));
  m->indices = {0, 2, 1, 0, 3, 2};
  m->material = {0, 1};
  return m;
}

std::filesystem::path Scratch() {
  return sylva::testing::ScratchDir("sylva_scene_export_");
}

json ReadJson(const std::string& path) {
  std::ifstream f(path);
  return json::parse(f, nullptr, false);
}

TEST(WriteSceneGltf, NodesShareOneMeshAndTintsShareItsAccessors) {
  ExportScene s;
  s.meshes.push_back({Square(), {Vec3f(1, 0, 0), Vec3f(0, 1, 0)}, "square"});
  for (int k = 0; k < 3; ++k)
    s.nodes.push_back({"a/" + std::to_string(k), 0,
                       Compose(Vec3f(float(k), 0, 0), Quatf::Identity(), Vec3f::Ones())});
  s.nodes.push_back({"tinted", 0, Mat4f::Identity(), Vec3f(0.5f, 0.5f, 0.5f)});
  s.points.push_back({"dots", PointMode::kPoints, {{0, 1, 0}, {0, 2, 0}}, {{1, 1, 1}, {2, 0, 0}}});
  s.points.push_back({"empty", PointMode::kLines, {}, {}});
  const std::string out = (Scratch() / "shared.gltf").string();
  SceneExportStats stats;
  ASSERT_TRUE(WriteSceneGltf(s, out, false, &stats).ok());
  const json j = ReadJson(out);
  ASSERT_FALSE(j.is_discarded());
  ASSERT_EQ(j["nodes"].size(), 5u) << j["nodes"].dump();  // the empty line set is left out
  EXPECT_EQ(stats.nodes, 5u);
  EXPECT_EQ(stats.points, 2u);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(j["nodes"][k]["mesh"], 0) << k;
  EXPECT_EQ(j["nodes"][1]["translation"], json::array({1.0, 0.0, 0.0}));
  const int tinted = j["nodes"][3]["mesh"].get<int>();
  ASSERT_NE(tinted, 0);
  ASSERT_EQ(j["meshes"][tinted]["primitives"].size(), 2u);
  for (int p = 0; p < 2; ++p) {
    EXPECT_EQ(j["meshes"][tinted]["primitives"][p]["attributes"],
              j["meshes"][0]["primitives"][p]["attributes"]);
    EXPECT_EQ(j["meshes"][tinted]["primitives"][p]["indices"],
              j["meshes"][0]["primitives"][p]["indices"]);
  }
  // Red, green, and the tinted pair: 4 materials; the tint halves the linear colour (to
  // within the 8-bit sRGB rounding of the tint).
  EXPECT_EQ(j["materials"].size(), 4u);
  const int m = j["meshes"][tinted]["primitives"][0]["material"].get<int>();
  const double red = j["materials"][m]["pbrMetallicRoughness"]["baseColorFactor"][0].get<double>();
  EXPECT_NEAR(red, 0.5, 0.005) << j["materials"][m].dump();
  // Points: POINTS mode, colours clamped to [0, 1].
  const json& dots = j["meshes"][j["nodes"][4]["mesh"].get<int>()]["primitives"][0];
  EXPECT_EQ(dots["mode"], 0);
  EXPECT_EQ(j["accessors"][dots["attributes"]["COLOR_0"].get<int>()]["count"], 2);
}

TEST(WriteSceneGltf, BadInputIsAnErrorAndWritesNothing) {
  const std::string out = (Scratch() / "bad.glb").string();
  ExportScene dangling;
  dangling.meshes.push_back({Square(), {}, "square"});
  dangling.nodes.push_back({"n", 1, Mat4f::Identity()});
  Status s = WriteSceneGltf(dangling, out, true);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("names mesh 1 of 1"), std::string::npos) << s.error().message;

  ExportScene sheared = dangling;
  sheared.nodes[0].mesh = 0;
  sheared.nodes[0].transform(1, 2) = 0.3f;
  s = WriteSceneGltf(sheared, out, true);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("node 'n': the transform shears"), std::string::npos)
      << s.error().message;

  for (int axis = 0; axis < 3; ++axis) {  // NaN in x, y and z of a point
    ExportScene points;
    Vec3f p(0, 0, 0);
    p[axis] = std::numeric_limits<float>::quiet_NaN();
    points.points.push_back(
        {"p", PointMode::kPoints, {Vec3f::Zero(), p}, {Vec3f::Ones(), Vec3f::Ones()}});
    s = WriteSceneGltf(points, out, true);
    ASSERT_FALSE(s.ok()) << axis;
    EXPECT_NE(s.error().message.find("point 1 is not finite"), std::string::npos)
        << s.error().message;
  }
  ExportScene odd;
  odd.points.push_back({"l", PointMode::kLines, {Vec3f::Zero()}, {Vec3f::Ones()}});
  EXPECT_FALSE(WriteSceneGltf(odd, out, true).ok());
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace sylva::mesh
