#include "terrain/diamond_square.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "core/parallel.h"

namespace sylva::terrain {
namespace {

TEST(DiamondSquare, SizeIsTheDefsAndGivenCornersAreKept) {
  DiamondSquareDef def;
  def.size = 129;
  def.corners = std::array<float, 4>{0.5f, -0.25f, 1.0f, -1.0f};
  const Expected<std::vector<float>> v = DiamondSquare(def);
  ASSERT_TRUE(v.ok()) << v.error().message;
  ASSERT_EQ(v->size(), size_t(129 * 129));
  EXPECT_EQ((*v)[0], 0.5f);
  EXPECT_EQ((*v)[128], -0.25f);
  EXPECT_EQ((*v)[128 * 129], 1.0f);
  EXPECT_EQ((*v)[128 * 129 + 128], -1.0f);
}

TEST(DiamondSquare, CornersAreSeededFromTheSeed) {
  DiamondSquareDef a, b, c;
  a.size = b.size = c.size = 33;
  a.seed = b.seed = 7;
  c.seed = 8;
  const std::vector<float> va = *DiamondSquare(a), vb = *DiamondSquare(b), vc = *DiamondSquare(c);
  const size_t corners[4] = {0, 32, 32 * 33, 32 * 33 + 32};
  int differ = 0;
  for (size_t k : corners) {
    EXPECT_EQ(va[k], vb[k]) << "corner " << k;
    EXPECT_GE(va[k], -1.0f);
    EXPECT_LE(va[k], 1.0f);
    differ += va[k] != vc[k];
  }
  EXPECT_EQ(differ, 4) << "seeds 7 and 8 share " << 4 - differ << " corners";
  // The four corners are not one value.
  EXPECT_NE(va[0], va[32]);
}

TEST(DiamondSquare, RoughnessZeroIsTheMeanOfTheCorners) {
  DiamondSquareDef def;
  def.size = 17;
  def.roughness = 0.0f;
  def.corners = std::array<float, 4>{0.5f, 0.5f, 0.5f, 0.5f};
  const std::vector<float> v = *DiamondSquare(def);
  float worst = 0;
  for (float f : v) worst = std::max(worst, std::fabs(f - 0.5f));
  EXPECT_EQ(worst, 0.0f) << "largest departure from the corners' value " << worst;
}

TEST(DiamondSquare, ValuesStayWithinTheBound) {
  for (float roughness : {0.3f, 0.5f, 0.8f, 1.0f}) {
    DiamondSquareDef def;
    def.size = 513;
    def.roughness = roughness;
    const std::vector<float> v = *DiamondSquare(def);
    float worst = 0;
    for (float f : v) worst = std::max(worst, std::fabs(f));
    EXPECT_LE(worst, Bound(def) * (1 + 1e-6f)) << "roughness " << roughness;
    EXPECT_GT(worst, 0.2f * Bound(def))
        << "roughness " << roughness << ": max |v| " << worst << " of bound " << Bound(def);
  }
}

TEST(DiamondSquare, SameBitsOnAnyThreadCount) {
  DiamondSquareDef def;
  def.size = 1025;
  def.seed = 99;
  const std::vector<float> ref = *DiamondSquare(def);
  for (int threads : {1, 2, 4, 7}) {
    ThreadPool pool(threads);
    const std::vector<float> v = *DiamondSquare(def, &pool);
    EXPECT_EQ(std::memcmp(v.data(), ref.data(), v.size() * sizeof(float)), 0)
        << threads << " threads";
  }
}

TEST(DiamondSquare, BadDefsAreRejectedWithTheFieldAndValue) {
  DiamondSquareDef def;
  def.size = 200;
  Expected<std::vector<float>> v = DiamondSquare(def);
  ASSERT_FALSE(v.ok());
  EXPECT_EQ(v.error().message, "DiamondSquareDef.size 200 is not 2^k + 1 (2..8193)");
  def.size = 16385;
  EXPECT_FALSE(Validate(def).ok()) << "size 16385 is past the limit";
  def.size = 65;
  def.roughness = std::nanf("");
  ASSERT_FALSE(Validate(def).ok());
  EXPECT_EQ(Validate(def).error().message, "DiamondSquareDef.roughness nan is outside 0..1");
  def.roughness = 0.5f;
  def.corners = std::array<float, 4>{0.0f, 0.0f, 0.0f, std::nanf("")};
  ASSERT_FALSE(Validate(def).ok());
  EXPECT_EQ(Validate(def).error().message, "DiamondSquareDef.corners[3] nan is outside -1..1");
}

}  // namespace
}  // namespace sylva::terrain
