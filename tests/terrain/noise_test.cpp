#include "terrain/noise.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "core/parallel.h"
#include "core/rng.h"
#include "terrain/noise_kernels.h"

namespace sylva::terrain {
namespace {

// Deterministic pseudo-random floats in [lo, hi).
std::vector<float> Uniform(size_t n, uint64_t seed, float lo, float hi) {
  std::vector<float> v(n);
  for (size_t i = 0; i < n; ++i) v[i] = lo + (hi - lo) * float(ToUnit(CounterHash(seed, i)));
  return v;
}

bool SameBits(const std::vector<float>& a, const std::vector<float>& b, size_t* first) {
  for (size_t i = 0; i < a.size(); ++i) {
    if (std::memcmp(&a[i], &b[i], sizeof(float)) != 0) {
      *first = i;
      return false;
    }
  }
  return true;
}

uint64_t HashBits(const std::vector<float>& v) {
  uint64_t h = 0;
  for (float f : v) {
    uint32_t b;
    std::memcpy(&b, &f, 4);
    h = Mix64(h ^ b);
  }
  return h;
}

TEST(GradientNoise, ZeroAtLatticePoints) {
  float worst = 0;
  for (uint64_t seed : {0ull, 1ull, 42ull, 0xdeadbeefcafef00dull}) {
    for (int y = -20; y <= 20; ++y) {
      for (int x = -20; x <= 20; ++x) {
        worst = std::max(worst, std::fabs(GradientNoise2(seed, float(x), float(y))));
        for (int z : {-7, 0, 3}) {
          worst = std::max(worst, std::fabs(GradientNoise3(seed, float(x), float(y), float(z))));
        }
      }
    }
  }
  EXPECT_EQ(worst, 0.0f) << "largest |noise| at a lattice point: " << worst;
}

TEST(GradientNoise, RangeMeasuredOverManySamples) {
  const size_t n = 2'000'000;
  const std::vector<float> x = Uniform(n, 1, -1000, 1000), y = Uniform(n, 2, -1000, 1000);
  const std::vector<float> z = Uniform(n, 3, -1000, 1000);
  std::vector<float> v2(n), v3(n);
  GradientNoise2(7, x.data(), y.data(), n, v2.data());
  GradientNoise3(7, x.data(), y.data(), z.data(), n, v3.data());
  float lo2 = 0, hi2 = 0, lo3 = 0, hi3 = 0;
  double mean2 = 0;
  for (size_t i = 0; i < n; ++i) {
    lo2 = std::min(lo2, v2[i]), hi2 = std::max(hi2, v2[i]);
    lo3 = std::min(lo3, v3[i]), hi3 = std::max(hi3, v3[i]);
    mean2 += v2[i];
  }
  mean2 /= double(n);
  EXPECT_GE(lo2, -1.0f);
  EXPECT_LE(hi2, 1.0f);
  EXPECT_GE(lo3, -1.0f);
  EXPECT_LE(hi3, 1.0f);
  // The documented range is used, not a sliver of it.
  EXPECT_LT(lo2, -0.8f) << "2D range measured [" << lo2 << ", " << hi2 << "]";
  EXPECT_GT(hi2, 0.8f) << "2D range measured [" << lo2 << ", " << hi2 << "]";
  EXPECT_LT(lo3, -0.8f) << "3D range measured [" << lo3 << ", " << hi3 << "]";
  EXPECT_GT(hi3, 0.8f) << "3D range measured [" << lo3 << ", " << hi3 << "]";
  EXPECT_LT(std::fabs(mean2), 0.01) << "2D mean " << mean2;
}

// The theoretical maximum: each corner's best gradient at every point of a
// cell (the 2D gradient set as documented in noise.h), times the scale.
TEST(GradientNoise, BoundOfTheGradientSetTimesScaleIsBelowOne) {
  auto fade = [](double t) { return t * t * t * (t * (t * 6 - 15) + 10); };
  double best = 0;
  const int n = 400;
  for (int a = 0; a <= n; ++a) {
    for (int b = 0; b <= n; ++b) {
      const double x = double(a) / n, y = double(b) / n;
      double total = 0;
      for (int c = 0; c < 4; ++c) {
        const int cx = c & 1, cy = c >> 1;
        double m = -1;
        for (int k = 0; k < 8; ++k) {
          const double ang = (22.5 + 45.0 * k) * 3.14159265358979323846 / 180;
          m = std::max(m, std::cos(ang) * (x - cx) + std::sin(ang) * (y - cy));
        }
        total += (cx ? fade(x) : 1 - fade(x)) * (cy ? fade(y) : 1 - fade(y)) * m;
      }
      best = std::max(best, total);
    }
  }
  EXPECT_NEAR(best, 0.66082, 1e-3);
  EXPECT_LT(best * 1.5, 0.995) << "scaled bound " << best * 1.5;
}

TEST(GradientNoise, SmallStepsGiveSmallChanges) {
  const std::vector<float> x = Uniform(20000, 4, -50, 50), y = Uniform(20000, 5, -50, 50);
  const float h = 1e-3f;
  float worst2 = 0, worst3 = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    const float v = GradientNoise2(3, x[i], y[i]);
    worst2 = std::max(worst2, std::fabs(GradientNoise2(3, x[i] + h, y[i]) - v));
    worst2 = std::max(worst2, std::fabs(GradientNoise2(3, x[i], y[i] + h) - v));
    const float w = GradientNoise3(3, x[i], y[i], x[i] - y[i]);
    worst3 = std::max(worst3, std::fabs(GradientNoise3(3, x[i], y[i], x[i] - y[i] + h) - w));
  }
  // The gradient of the noise is a few units at most; a step of 1e-3 moves
  // it by a few thousandths.
  EXPECT_LT(worst2, 5e-3f) << "largest change over a step of 1e-3 (2D): " << worst2;
  EXPECT_LT(worst3, 5e-3f) << "largest change over a step of 1e-3 (3D): " << worst3;
}

TEST(GradientNoise, SeedsGiveDifferentFields) {
  int same = 0;
  for (int i = 0; i < 1000; ++i) {
    const float x = 0.37f + 0.91f * float(i), y = 0.53f * float(i);
    same += GradientNoise2(1, x, y) == GradientNoise2(2, x, y);
  }
  EXPECT_LT(same, 10) << same << " of 1000 samples equal under seeds 1 and 2";
}

TEST(GradientNoise, NanGivesNan) {
  const float nan = std::nanf("");
  EXPECT_TRUE(std::isnan(GradientNoise2(1, nan, 0.5f)));
  EXPECT_TRUE(std::isnan(GradientNoise2(1, 0.5f, nan)));
  EXPECT_TRUE(std::isnan(GradientNoise3(1, 0.5f, 0.5f, nan)));
}

// Inputs for the twin tests: ordinary, negative, near lattice lines, huge,
// NaN and infinite, and a length that leaves a scalar tail.
std::vector<float> Awkward(size_t n, uint64_t seed) {
  std::vector<float> v = Uniform(n, seed, -300, 300);
  const float specials[] = {0.0f,  -0.0f, 1.0f,          -1.0f,    0.99999994f, -1e-30f,    1e7f,
                            -3e9f, 5e30f, std::nanf(""), INFINITY, -INFINITY,   16777215.5f};
  for (size_t k = 0; k < sizeof specials / sizeof *specials; ++k) v[k * 7 % n] = specials[k];
  return v;
}

TEST(GradientNoise, ScalarAndAvx2TwinsAgreeBitForBit) {
  if (BestKernel() != Kernel::kAvx2) GTEST_SKIP() << "this processor has no AVX2";
  const size_t n = 100003;
  const std::vector<float> x = Awkward(n, 11), y = Awkward(n, 12), z = Awkward(n, 13);
  std::vector<float> a(n), b(n);
  size_t first = 0;
  GradientNoise2(9, x.data(), y.data(), n, a.data(), Kernel::kScalar);
  GradientNoise2(9, x.data(), y.data(), n, b.data(), Kernel::kAvx2);
  EXPECT_TRUE(SameBits(a, b, &first))
      << "2D points differ at " << first << ": " << a[first] << " vs " << b[first];
  GradientNoise3(9, x.data(), y.data(), z.data(), n, a.data(), Kernel::kScalar);
  GradientNoise3(9, x.data(), y.data(), z.data(), n, b.data(), Kernel::kAvx2);
  EXPECT_TRUE(SameBits(a, b, &first))
      << "3D points differ at " << first << ": " << a[first] << " vs " << b[first];
  const Grid2 grid{-12.3f, 4.56f, 0.0137f, 0.031f, 1021, 67};
  std::vector<float> ga(grid.nx * grid.ny), gb(ga.size());
  GradientNoise2Grid(9, grid, ga.data(), Kernel::kScalar);
  GradientNoise2Grid(9, grid, gb.data(), Kernel::kAvx2);
  EXPECT_TRUE(SameBits(ga, gb, &first)) << "grid differs at " << first;
}

TEST(GradientNoise, BatchGivesThePointValuesBitForBit) {
  for (Kernel kernel : {Kernel::kScalar, BestKernel()}) {
    const size_t n = 5000;
    const std::vector<float> x = Uniform(n, 21, -40, 40), y = Uniform(n, 22, -40, 40);
    const std::vector<float> z = Uniform(n, 23, -40, 40);
    std::vector<float> v2(n), v3(n);
    GradientNoise2(5, x.data(), y.data(), n, v2.data(), kernel);
    GradientNoise3(5, x.data(), y.data(), z.data(), n, v3.data(), kernel);
    int differ = 0;
    for (size_t i = 0; i < n; ++i) {
      differ += GradientNoise2(5, x[i], y[i]) != v2[i];
      differ += GradientNoise3(5, x[i], y[i], z[i]) != v3[i];
    }
    EXPECT_EQ(differ, 0) << "kernel " << int(kernel);
    const Grid2 grid{-3.5f, 2.25f, 0.173f, 0.071f, 77, 13};
    std::vector<float> g(grid.nx * grid.ny);
    GradientNoise2Grid(5, grid, g.data(), kernel);
    differ = 0;
    for (size_t j = 0; j < grid.ny; ++j) {
      for (size_t i = 0; i < grid.nx; ++i) {
        const float px = grid.x0 + float(i) * grid.dx, py = grid.y0 + float(j) * grid.dy;
        differ += GradientNoise2(5, px, py) != g[j * grid.nx + i];
      }
    }
    EXPECT_EQ(differ, 0) << "grid, kernel " << int(kernel);
  }
}

TEST(GradientNoise, GridIsTheSameOnAnyThreadCount) {
  const Grid2 grid{-100.0f, -100.0f, 0.25f, 0.25f, 800, 800};
  std::vector<float> v(grid.nx * grid.ny);
  GradientNoise2Grid(77, grid, v.data(), BestKernel(), nullptr);
  const uint64_t reference = HashBits(v);
  for (int threads : {1, 2, 3, 8}) {
    ThreadPool pool(threads);
    std::fill(v.begin(), v.end(), 0.0f);
    GradientNoise2Grid(77, grid, v.data(), BestKernel(), &pool);
    EXPECT_EQ(HashBits(v), reference) << threads << " threads";
  }
}

// The lattice hash picks each of the 8 (2D) and 16 (3D) gradients about
// equally often, and a corner's gradient says nothing about its right or
// upper neighbour's (a coarse check: it catches a lost gradient or a
// hash that repeats along an axis, not subtle statistical defects).
TEST(GradientNoise, LatticeHashSpreadsGradientsEvenly) {
  using namespace kernels;
  for (uint64_t seed : {1ull, 2ull, 0x123456789abcdefull}) {
    const uint32_t key = KeyOf(seed);
    const int n = 256;
    double count2[8] = {}, count3[16] = {}, pairs[8][8] = {};
    for (int y = -n / 2; y < n / 2; ++y) {
      for (int x = -n / 2; x < n / 2; ++x) {
        const uint32_t xp = uint32_t(x) * kPrimeX, yp = uint32_t(y) * kPrimeY;
        const uint32_t g = Hash(key ^ xp ^ yp) >> 29;
        count2[g] += 1;
        pairs[g][Hash(key ^ (xp + kPrimeX) ^ yp) >> 29] += 1;
        pairs[g][Hash(key ^ xp ^ (yp + kPrimeY)) >> 29] += 1;
        count3[Hash(key ^ xp ^ yp ^ (uint32_t(x - y) * kPrimeZ)) >> 28] += 1;
      }
    }
    // Chi-square against uniform: 7, 15 and 63 degrees of freedom; the
    // bounds are far beyond the 99.9th percentiles (24.3, 37.7, 103.4).
    auto chi2 = [](const double* c, int k, double total) {
      double s = 0;
      for (int i = 0; i < k; ++i) s += (c[i] - total / k) * (c[i] - total / k) / (total / k);
      return s;
    };
    const double total = double(n) * n;
    EXPECT_LT(chi2(count2, 8, total), 30) << "seed " << seed;
    EXPECT_LT(chi2(count3, 16, total), 45) << "seed " << seed;
    EXPECT_LT(chi2(&pairs[0][0], 64, 2 * total), 120) << "seed " << seed;
  }
}

}  // namespace
}  // namespace sylva::terrain
