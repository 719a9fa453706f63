// Conversions from simulation arrays to DrawList parts: what goes in comes
// out (positions, diameters, colours, facing, normals), and arrays of the
// wrong length are Diagnostics, never read past their end.
#include "draw/convert.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace sylva::draw {
namespace {

TEST(PointSprites, CarryPositionsColoursAndDiametersFromRadii) {
  const std::vector<Vec3> x = {Vec3(1, 2, 3), Vec3(-4, 5.5, 1e-3)};
  const std::vector<Vec3f> c = {Vec3f(1, 0, 0), Vec3f(0, 0.5f, 1)};
  const std::vector<float> r = {0.1f, 0.25f};
  PointStyle style;
  style.name = "sparks";
  style.blend = Blend::kAdditive;
  style.alpha = 0.5f;
  auto s = PointSprites(x, style, c, r);
  ASSERT_TRUE(s.ok()) << s.error().message;
  ASSERT_EQ(s->positions.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(s->positions[i], x[i].cast<float>()) << "point " << i;
    EXPECT_EQ(s->colors[i], c[i]) << "point " << i;
    EXPECT_EQ(s->sizes[i], 2 * r[i]) << "a sprite's size is a diameter";
    EXPECT_EQ(s->alphas[i], 0.5f);
  }
  EXPECT_EQ(s->name, "sparks");
  EXPECT_EQ(s->blend, Blend::kAdditive);
  DrawList list;
  list.sprites.push_back(*s);
  EXPECT_TRUE(list.Check().ok()) << list.Check().error().message;
}

TEST(PointSprites, TakeTheStyleWhereArraysAreEmpty) {
  const std::vector<float> px = {0, 1, 2}, py = {3, 4, 5}, pz = {6, 7, 8};
  PointStyle style;
  style.size = 0.2f;
  style.color = Vec3f(0.1f, 0.2f, 0.3f);
  auto s = PointSprites(px, py, pz, style);
  ASSERT_TRUE(s.ok()) << s.error().message;
  ASSERT_EQ(s->positions.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(s->positions[i], Vec3f(px[i], py[i], pz[i]));
    EXPECT_EQ(s->sizes[i], 0.2f);
    EXPECT_EQ(s->colors[i], style.color);
  }
  EXPECT_TRUE(s->alphas.empty()) << "opaque: no alpha array";
}

TEST(PointSprites, ArraysOfTheWrongLengthAreDiagnostics) {
  const std::vector<Vec3> x(3, Vec3::Zero());
  const std::vector<Vec3f> c(2, Vec3f::Ones());
  const std::vector<float> r(4, 1.0f);
  auto a = PointSprites(x, {}, c);
  ASSERT_FALSE(a.ok());
  EXPECT_NE(a.error().message.find("colors has 2 entries for 3 positions"), std::string::npos)
      << a.error().message;
  auto b = PointSprites(x, {}, {}, r);
  ASSERT_FALSE(b.ok());
  EXPECT_NE(b.error().message.find("radii has 4"), std::string::npos) << b.error().message;
  const std::vector<float> p3(3), p2(2);
  auto d = PointSprites(p3, p3, p2, {});
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.error().message.find("3, 3 and 2"), std::string::npos) << d.error().message;
}

TEST(FacingInstances, TurnPlusZToTheVelocityAndScale) {
  const std::vector<Vec3> x = {Vec3(1, 2, 3), Vec3(0, 0, 0), Vec3(5, 5, 5)};
  const std::vector<Vec3> v = {Vec3(3, 0, 4), Vec3(0, 0, 0), Vec3(0, 2, 0)};
  auto inst = FacingInstances(x, v, 2.0, Vec3f(1, 0.5f, 0));
  ASSERT_TRUE(inst.ok()) << inst.error().message;
  ASSERT_EQ(inst->size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    const Mat4f& m = (*inst)[i].transform;
    const Eigen::Vector4f z = m * Eigen::Vector4f(0, 0, 1, 0);
    const Vec3 want = v[i].norm() > 0 ? Vec3(v[i].normalized()) : Vec3::UnitZ();
    EXPECT_LT((z.head<3>().cast<double>() - 2 * want).norm(), 1e-6)
        << "instance " << i << ": +Z goes to " << z.head<3>().transpose();
    EXPECT_LT((m.block<3, 1>(0, 3).cast<double>() - x[i]).norm(), 1e-6) << "instance " << i;
    // A rotation times the scale: the columns are orthogonal, of length 2.
    const Eigen::Matrix3f r = m.block<3, 3>(0, 0) / 2;
    EXPECT_LT((r.transpose() * r - Eigen::Matrix3f::Identity()).norm(), 1e-5) << "instance " << i;
    EXPECT_EQ((*inst)[i].tint, Vec3f(1, 0.5f, 0));
  }
  auto bad = FacingInstances(x, std::span<const Vec3>(v.data(), 2), 1);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("velocities has 2 entries for 3"), std::string::npos)
      << bad.error().message;
}

// A streak per particle from seconds back along its velocity to where it
// is, the tail shaded; colours per particle or one; lengths checked.
TEST(Trails, RunBackAlongTheVelocityWithAShadedTail) {
  const std::vector<Vec3> x = {Vec3(1, 2, 3), Vec3(0, 0, 0)};
  const std::vector<Vec3> v = {Vec3(10, 0, -5), Vec3(0, 0, 0)};
  const std::vector<Vec3f> c = {Vec3f(1, 0.5f, 0), Vec3f(0, 0, 1)};
  auto t = Trails(x, v, 0.1, c, Vec3f(1, 1, 1), 0.25f, "sparks");
  ASSERT_TRUE(t.ok()) << t.error().message;
  ASSERT_EQ(t->points.size(), 4u);
  ASSERT_EQ(t->colors.size(), 4u);
  EXPECT_EQ(t->name, "sparks");
  EXPECT_LT((t->points[0] - Vec3f(0, 2, 3.5f)).norm(), 1e-6f) << t->points[0].transpose();
  EXPECT_EQ(t->points[1], Vec3f(1, 2, 3));
  EXPECT_EQ(t->points[2], t->points[3]) << "a particle at rest is a point";
  EXPECT_EQ(t->colors[0], Vec3f(0.25f, 0.125f, 0));
  EXPECT_EQ(t->colors[1], c[0]);
  auto one = Trails(x, v, 0.1, {}, Vec3f(0, 1, 0));
  ASSERT_TRUE(one.ok()) << one.error().message;
  EXPECT_EQ(one->colors[3], Vec3f(0, 1, 0));
  EXPECT_EQ(one->colors[2], Vec3f(0, 0.3f, 0));
  auto badV = Trails(x, std::span<const Vec3>(v.data(), 1), 0.1);
  ASSERT_FALSE(badV.ok());
  EXPECT_NE(badV.error().message.find("velocities has 1 entries for 2"), std::string::npos)
      << badV.error().message;
  auto badC = Trails(x, v, 0.1, std::span<const Vec3f>(c.data(), 1));
  ASSERT_FALSE(badC.ok());
  EXPECT_NE(badC.error().message.find("colors has 1 entries for 2"), std::string::npos)
      << badC.error().message;
}

TEST(SheetMesh, SmoothNormalsAreTheAreaWeightedFaceNormals) {
  // A unit square in z = 0 (two counter-clockwise triangles seen from +Z)
  // and a third triangle folded up at 90 degrees along the edge 1-2.
  const std::vector<Vec3> x = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0),
                               Vec3(1, 0, 1)};
  const std::vector<std::array<uint32_t, 3>> tris = {{0, 1, 2}, {0, 2, 3}, {1, 4, 2}};
  const std::vector<uint16_t> mats = {3, 4, 5};
  auto m = SheetMesh(x, tris, mats);
  ASSERT_TRUE(m.ok()) << m.error().message;
  ASSERT_EQ(m->positions.size(), 5u);
  ASSERT_EQ(m->indices.size(), 9u);
  EXPECT_EQ(m->material, mats);
  for (size_t i : {0u, 3u}) {
    EXPECT_LT((m->normals[i] - Vec3f(0, 0, 1)).norm(), 1e-6) << "flat vertex " << i;
  }
  // Vertex 4 lies on the folded triangle alone: its normal is that face's.
  const Vec3 n = (x[4] - x[1]).cross(x[2] - x[1]).normalized();
  EXPECT_LT((m->normals[4].cast<double>() - n).norm(), 1e-6) << m->normals[4].transpose();
  // Vertex 1 shares a flat triangle (area 1/2) and the folded one (area
  // 1/2): the normal halfway.
  const Vec3 half = (Vec3(0, 0, 1) + n).normalized();
  EXPECT_LT((m->normals[1].cast<double>() - half).norm(), 1e-6) << m->normals[1].transpose();
  for (const Vec3f& q : m->normals) EXPECT_NEAR(q.norm(), 1, 1e-6);
}

TEST(SheetMesh, BadIndicesAndMaterialsAreDiagnostics) {
  const std::vector<Vec3> x = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  const std::vector<std::array<uint32_t, 3>> bad = {{0, 1, 2}, {0, 2, 9}};
  auto a = SheetMesh(x, bad);
  ASSERT_FALSE(a.ok());
  EXPECT_NE(a.error().message.find("triangle 1 has index 9"), std::string::npos)
      << a.error().message;
  const std::vector<std::array<uint32_t, 3>> one = {{0, 1, 2}};
  const std::vector<uint16_t> two = {1, 2};
  auto b = SheetMesh(x, one, two);
  ASSERT_FALSE(b.ok());
  EXPECT_NE(b.error().message.find("materials has 2 entries for 1 triangles"), std::string::npos)
      << b.error().message;
}

}  // namespace
}  // namespace sylva::draw
