#include "terrain/height_field.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>

#include "core/parallel.h"
#include "core/rng.h"

namespace sylva::terrain {
namespace {

TerrainDef Def(NoiseKind kind, int resolution = 129) {
  TerrainDef def;
  def.sizeX = 80;
  def.sizeZ = 60;
  def.resolution = resolution;
  def.height = 12;
  def.noise = kind;
  def.seed = 5;
  return def;
}

TEST(HeightField, HeightAtGridVerticesEqualsTheGrid) {
  for (NoiseKind kind : {NoiseKind::kFbm, NoiseKind::kRidged, NoiseKind::kDiamondSquare}) {
    const Expected<HeightField> f = HeightField::Create(Def(kind));
    ASSERT_TRUE(f.ok()) << f.error().message;
    double worst = 0;
    for (int j = 0; j < f->resolution(); ++j) {
      for (int i = 0; i < f->resolution(); ++i) {
        const double d = f->Height(f->VertexX(i), f->VertexZ(j)) - double(f->HeightAt(i, j));
        worst = std::max(worst, std::fabs(d));
      }
    }
    EXPECT_LT(worst, 1e-12) << NameOf(kind) << ": largest |Height(vertex) - grid| " << worst;
    EXPECT_GT(f->maxHeight() - f->minHeight(), 1.0f) << NameOf(kind) << " is nearly flat";
  }
}

TEST(HeightField, HeightIsThePlaneOfTheDocumentedTriangle) {
  const HeightField f = *HeightField::Create(Def(NoiseKind::kFbm, 33));
  // Cell (3, 5): a point with u < w lies on (i,j) (i,j+1) (i+1,j+1); one
  // with u > w on (i,j) (i+1,j+1) (i+1,j).
  const double h00 = f.HeightAt(3, 5), h10 = f.HeightAt(4, 5), h01 = f.HeightAt(3, 6),
               h11 = f.HeightAt(4, 6);
  const double x0 = f.VertexX(3), z0 = f.VertexZ(5), dx = f.spacingX(), dz = f.spacingZ();
  const double u = 0.2, w = 0.7;
  const double a = (1 - w) * h00 + (w - u) * h01 + u * h11;  // barycentric in A
  EXPECT_NEAR(f.Height(x0 + u * dx, z0 + w * dz), a, 1e-9);
  const double b = (1 - w) * h00 + (w - u) * h10 + u * h11;  // (u, w) swapped: in B
  EXPECT_NEAR(f.Height(x0 + w * dx, z0 + u * dz), (1 - w) * h00 + (w - u) * h10 + u * h11, 1e-9)
      << "expected " << b;
}

TEST(HeightField, NormalIsUnitAndMatchesFiniteDifferences) {
  const HeightField f = *HeightField::Create(Def(NoiseKind::kFbm));
  double worstLength = 0, worstAngle = 0;
  for (int k = 0; k < 5000; ++k) {
    // Points well inside a triangle (away from its edges by more than the step).
    const double gi = 1 + 120 * ToUnit(CounterHash(1, k)), gj = 1 + 120 * ToUnit(CounterHash(2, k));
    const double u = gi - std::floor(gi), w = gj - std::floor(gj);
    if (std::fabs(u - w) < 0.02 || u < 0.01 || u > 0.99 || w < 0.01 || w > 0.99) continue;
    const double x = f.VertexX(0) + gi * f.spacingX(), z = f.VertexZ(0) + gj * f.spacingZ();
    const double h = 1e-4;
    const double dhdx = (f.Height(x + h, z) - f.Height(x - h, z)) / (2 * h);
    const double dhdz = (f.Height(x, z + h) - f.Height(x, z - h)) / (2 * h);
    const Vec3 fd = Vec3(-dhdx, 1, -dhdz).normalized();
    const Vec3 n = f.Normal(x, z);
    worstLength = std::max(worstLength, std::fabs(n.norm() - 1));
    worstAngle = std::max(worstAngle, std::acos(std::min(1.0, n.dot(fd))));
    EXPECT_GT(n.y(), 0) << "normal points down at " << x << ", " << z;
  }
  EXPECT_LT(worstLength, 1e-12) << "largest | |n| - 1 |";
  EXPECT_LT(worstAngle, 1e-5) << "largest angle to the finite-difference normal (rad)";
}

TEST(HeightField, QueriesOutsideTakeTheBorderAndNanGivesNan) {
  const HeightField f = *HeightField::Create(Def(NoiseKind::kRidged, 65));
  EXPECT_FALSE(f.Contains(40.5, 0));
  EXPECT_TRUE(f.Contains(40, -30));
  EXPECT_EQ(f.Height(1000, -1000), double(f.HeightAt(64, 0)));
  EXPECT_TRUE(std::isnan(f.Height(0, std::nan(""))));
  EXPECT_TRUE(std::isnan(f.Normal(std::nan(""), 0).x()));
}

TEST(HeightField, FlatIsZeroAndRidgedIsNonNegative) {
  const HeightField flat = *HeightField::Create(Def(NoiseKind::kFlat, 17));
  EXPECT_EQ(flat.minHeight(), 0.0f);
  EXPECT_EQ(flat.maxHeight(), 0.0f);
  EXPECT_EQ(flat.Normal(3, 4), Vec3(0, 1, 0));
  const HeightField ridged = *HeightField::Create(Def(NoiseKind::kRidged));
  EXPECT_GE(ridged.minHeight(), 0.0f);
  EXPECT_LE(ridged.maxHeight(), 12.0f);
  const HeightField fbm = *HeightField::Create(Def(NoiseKind::kFbm));
  EXPECT_GE(fbm.minHeight(), -12.0f);
  EXPECT_LE(fbm.maxHeight(), 12.0f);
}

TEST(HeightField, SameHeightsOnAnyThreadCount) {
  for (NoiseKind kind : {NoiseKind::kFbm, NoiseKind::kRidged, NoiseKind::kDiamondSquare}) {
    const HeightField ref = *HeightField::Create(Def(kind, 257));
    for (int threads : {1, 2, 4}) {
      ThreadPool pool(threads);
      const HeightField f = *HeightField::Create(Def(kind, 257), &pool);
      EXPECT_EQ(std::memcmp(f.heights().data(), ref.heights().data(),
                            ref.heights().size() * sizeof(float)),
                0)
          << NameOf(kind) << ", " << threads << " threads";
    }
  }
}

TEST(HeightField, MeshArraysMatchTheGridAndFaceUp) {
  const HeightField f = *HeightField::Create(Def(NoiseKind::kFbm, 9));
  const Expected<TerrainMesh> m = f.MakeMesh();
  ASSERT_TRUE(m.ok());
  ASSERT_EQ(m->positions.size(), size_t(81 * 3));
  ASSERT_EQ(m->normals.size(), size_t(81 * 3));
  ASSERT_EQ(m->indices.size(), size_t(64 * 6));
  EXPECT_EQ(m->positions[3 * 10 + 1], f.HeightAt(1, 1));
  EXPECT_FLOAT_EQ(m->positions[3 * 10 + 0], float(f.VertexX(1)));
  EXPECT_FLOAT_EQ(m->positions[0], -40.0f);
  EXPECT_FLOAT_EQ(m->positions[2], -30.0f);
  int down = 0;
  for (size_t t = 0; t < m->indices.size(); t += 3) {
    const float* a = &m->positions[3 * m->indices[t]];
    const float* b = &m->positions[3 * m->indices[t + 1]];
    const float* c = &m->positions[3 * m->indices[t + 2]];
    const Vec3 e1(b[0] - a[0], b[1] - a[1], b[2] - a[2]), e2(c[0] - a[0], c[1] - a[1], c[2] - a[2]);
    down += e1.cross(e2).y() <= 0;
  }
  EXPECT_EQ(down, 0) << "triangles not counter-clockwise from above";
  for (size_t v = 0; v < 81; ++v) {
    const Vec3 n(m->normals[3 * v], m->normals[3 * v + 1], m->normals[3 * v + 2]);
    EXPECT_NEAR(n.norm(), 1.0, 1e-6) << "vertex " << v;
  }
}

std::string Rejection(const TerrainDef& def) {
  const Status st = Validate(def);
  if (st.ok()) return "accepted";
  const Expected<HeightField> f = HeightField::Create(def);
  EXPECT_FALSE(f.ok());
  return st.error().message;
}

TEST(HeightField, BadDefsAreRejectedWithAMessage) {
  EXPECT_TRUE(Validate(TerrainDef{}).ok());
  TerrainDef d;
  d.sizeZ = std::nan("");
  EXPECT_EQ(Rejection(d), "TerrainDef.sizeZ nan is outside 0.001..1e+06 m");
  d = {};
  d.sizeX = -5;
  EXPECT_EQ(Rejection(d), "TerrainDef.sizeX -5 is outside 0.001..1e+06 m");
  d = {};
  d.resolution = 1;
  EXPECT_EQ(Rejection(d), "TerrainDef.resolution 1 is outside 2..8193");
  d.resolution = 1'000'000;  // 4 TB of heights: rejected before any allocation
  EXPECT_EQ(Rejection(d), "TerrainDef.resolution 1000000 is outside 2..8193");
  d = {};
  d.height = INFINITY;
  EXPECT_EQ(Rejection(d), "TerrainDef.height inf is outside 0..1e+05 m");
  d = {};
  d.octaves = 0;
  EXPECT_EQ(Rejection(d), "TerrainDef.octaves 0 is outside 1..16");
  d = {};
  d.gain = std::nan("");
  EXPECT_EQ(Rejection(d), "TerrainDef.gain nan is outside 0..1");
  d = {};
  d.lacunarity = 0.5;
  EXPECT_EQ(Rejection(d), "TerrainDef.lacunarity 0.5 is outside 1..16");
  d = {};
  d.featureSize = -1;
  EXPECT_EQ(Rejection(d), "TerrainDef.featureSize -1 is outside 0 (auto) or 0.001..1e+07 m");
  d = {};
  d.noise = NoiseKind(7);
  EXPECT_EQ(Rejection(d), "TerrainDef.noise 7 is not a noise kind");
  d = {};
  d.noise = NoiseKind::kDiamondSquare;
  d.resolution = 200;
  EXPECT_EQ(Rejection(d),
            "TerrainDef.resolution 200 is not 2^k + 1, as diamond-square needs (e.g. 129, 257, "
            "513)");
  d.noise = NoiseKind::kFbm;
  EXPECT_EQ(Rejection(d), "accepted") << "fbm takes any resolution";
  d.octaves = 16;
  d.lacunarity = 8;
  EXPECT_NE(Rejection(d).find("past 2^24"), std::string::npos) << Rejection(d);
}

TEST(HeightField, NoiseNamesAndSuggestions) {
  EXPECT_EQ(*NoiseKindFromName("diamond-square"), NoiseKind::kDiamondSquare);
  EXPECT_EQ(*NoiseKindFromName("flat"), NoiseKind::kFlat);
  const Expected<NoiseKind> bad = NoiseKindFromName("ridge");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().message,
            "unknown noise 'ridge'; did you mean 'ridged'? (fbm, ridged, diamond-square, flat)");
  EXPECT_FALSE(NoiseKindFromName("perlin").ok());
}

}  // namespace
}  // namespace sylva::terrain
