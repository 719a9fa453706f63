#include "mesh/triangulate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace sylva::mesh {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Star-shaped: radii at random about a centre, angles increasing.
std::vector<Vec3> Star(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> r(0.3, 1.0);
  std::vector<Vec3> v(n);
  for (size_t i = 0; i < n; ++i) {
    const double a = 2 * kPi * double(i) / double(n);
    const double rr = r(rng);
    v[i] = Vec3(rr * std::cos(a), rr * std::sin(a), 0);
  }
  return v;
}

// A band along an Archimedean spiral: out along the outer edge, back along
// the inner one. Deeply concave: nearly every inner vertex is reflex.
std::vector<Vec3> Spiral(size_t n, double turns) {
  const size_t m = n / 2;
  std::vector<Vec3> v;
  v.reserve(2 * m);
  for (size_t i = 0; i < m; ++i) {
    const double t = turns * 2 * kPi * double(i) / double(m - 1);
    const double r = 3 + t;
    v.emplace_back(r * std::cos(t), r * std::sin(t), 0);
  }
  for (size_t i = m; i-- > 0;) {
    const double t = turns * 2 * kPi * double(i) / double(m - 1);
    const double r = 3 + t - 2.5;
    v.emplace_back(r * std::cos(t), r * std::sin(t), 0);
  }
  return v;
}

// A comb: a spine with narrow teeth (many reflex corners side by side).
std::vector<Vec3> Comb(size_t teeth) {
  std::vector<Vec3> v;
  for (size_t i = 0; i < teeth; ++i) {
    const double x = double(i);
    v.emplace_back(x, 0, 0);
    v.emplace_back(x + 0.25, 5, 0);
    v.emplace_back(x + 0.5, 0.5, 0);
  }
  v.emplace_back(double(teeth), 0, 0);
  v.emplace_back(double(teeth), -1, 0);
  v.emplace_back(0, -1, 0);
  return v;
}

double ShoelaceArea(const std::vector<Vec3>& v) {
  double a = 0;
  for (size_t i = 0; i < v.size(); ++i) {
    const Vec3& p = v[i];
    const Vec3& q = v[(i + 1) % v.size()];
    a += p.x() * q.y() - q.x() * p.y();
  }
  return std::abs(a) / 2;
}

// n - 2 triangles, all turning the polygon's way (none inverted), whose
// areas add up to the polygon's.
void ExpectValid(const std::vector<Vec3>& v, const std::string& what) {
  Vec3 normal;
  const std::vector<uint32_t> t = TriangulatePolygon(v, &normal);
  ASSERT_EQ(t.size(), 3 * (v.size() - 2))
      << what << ": " << t.size() / 3 << " triangles for " << v.size() << " vertices";
  double sum = 0;
  for (size_t k = 0; k < t.size(); k += 3) {
    const Vec3 c = (v[t[k + 1]] - v[t[k]]).cross(v[t[k + 2]] - v[t[k]]);
    ASSERT_GT(c.dot(normal), 0) << what << ": triangle " << k / 3 << " is inverted or flat";
    sum += c.norm() / 2;
  }
  const double want = ShoelaceArea(v);
  EXPECT_NEAR(sum, want, 1e-9 * want) << what;
}

TEST(Triangulate, StarShapedPolygonsOfManySizes) {
  for (size_t n : {10u, 100u, 1000u, 10000u, 100000u})
    ExpectValid(Star(n, uint32_t(n)), "star " + std::to_string(n));
}

TEST(Triangulate, SpiralsAndCombs) {
  for (size_t n : {40u, 400u, 4000u, 40000u, 130000u})
    ExpectValid(Spiral(n, 3), "spiral " + std::to_string(n));
  for (size_t teeth : {3u, 300u, 30000u}) ExpectValid(Comb(teeth), "comb " + std::to_string(teeth));
}

TEST(Triangulate, ClockwiseOutlinesAndTiltedPlanes) {
  std::vector<Vec3> v = Spiral(2000, 2);
  std::reverse(v.begin(), v.end());
  ExpectValid(v, "clockwise spiral");
  // The same star in a tilted plane: projection onto the best-fit plane.
  std::vector<Vec3> tilted = Star(500, 7);
  const Eigen::AngleAxisd rot(0.7, Vec3(1, 2, 3).normalized());
  for (Vec3& p : tilted) p = rot * p;
  Vec3 normal;
  const auto t = TriangulatePolygon(tilted, &normal);
  EXPECT_EQ(t.size(), 3 * (tilted.size() - 2));
  EXPECT_NEAR(std::abs(normal.dot(rot * Vec3(0, 0, 1))), 1, 1e-9);
}

TEST(Triangulate, DegenerateOutlinesGiveNothing) {
  Vec3 n;
  EXPECT_TRUE(TriangulatePolygon({Vec3(0, 0, 0), Vec3(1, 0, 0)}, &n).empty());
  EXPECT_TRUE(
      TriangulatePolygon({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0), Vec3(3, 0, 0)}, &n).empty());
}

}  // namespace
}  // namespace sylva::mesh
