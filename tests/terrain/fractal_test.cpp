#include "terrain/fractal.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <vector>

#include "core/parallel.h"
#include "core/rng.h"

namespace sylva::terrain {
namespace {

uint64_t HashBits(const std::vector<float>& v) {
  uint64_t h = 0;
  for (float f : v) {
    uint32_t b;
    std::memcpy(&b, &f, 4);
    h = Mix64(h ^ b);
  }
  return h;
}

struct Range {
  float lo = INFINITY, hi = -INFINITY;
};

Range Measure(const std::vector<float>& v) {
  Range r;
  for (float f : v) r.lo = std::min(r.lo, f), r.hi = std::max(r.hi, f);
  return r;
}

const Grid2 kGrid{-37.1f, -52.9f, 0.0371f, 0.0419f, 1000, 1000};

TEST(Fractal, FbmStaysInMinusOneToOne) {
  std::vector<float> v(kGrid.nx * kGrid.ny);
  for (int octaves : {1, 4, 8}) {
    const FractalDef def{octaves, 2.0f, 0.5f};
    Fbm2Grid(3, def, kGrid, v.data());
    const Range r = Measure(v);
    EXPECT_GE(r.lo, -1.0f) << octaves << " octaves";
    EXPECT_LE(r.hi, 1.0f) << octaves << " octaves";
    EXPECT_LT(r.lo, -0.4f) << octaves << " octaves: measured [" << r.lo << ", " << r.hi << "]";
    EXPECT_GT(r.hi, 0.4f) << octaves << " octaves: measured [" << r.lo << ", " << r.hi << "]";
  }
}

TEST(Fractal, RidgedStaysInZeroToOne) {
  std::vector<float> v(kGrid.nx * kGrid.ny);
  const FractalDef def{6, 2.0f, 0.5f};
  Ridged2Grid(3, def, kGrid, v.data());
  const Range r = Measure(v);
  EXPECT_GE(r.lo, 0.0f);
  EXPECT_LE(r.hi, 1.0f);
  EXPECT_GT(r.hi, 0.6f) << "measured [" << r.lo << ", " << r.hi << "]";
  EXPECT_LT(r.lo, 0.2f) << "measured [" << r.lo << ", " << r.hi << "]";
}

TEST(Fractal, OneOctaveFbmIsTheNoise) {
  const FractalDef def{1, 2.0f, 0.5f};
  // The octave's key is hashed from the seed, so compare shapes through the
  // lattice zeros and the range rather than values: zero at integers.
  for (int x = -5; x <= 5; ++x) EXPECT_EQ(Fbm2(9, def, float(x), 3.0f), 0.0f) << "x " << x;
}

TEST(Fractal, GridGivesThePointValuesOnEitherKernelAndAnyThreadCount) {
  const Grid2 grid{-3.3f, 7.7f, 0.113f, 0.097f, 203, 61};
  const FractalDef def{5, 2.1f, 0.45f};
  for (int ridged = 0; ridged < 2; ++ridged) {
    std::vector<float> ref(grid.nx * grid.ny);
    for (size_t j = 0; j < grid.ny; ++j) {
      for (size_t i = 0; i < grid.nx; ++i) {
        const float x = grid.x0 + float(i) * grid.dx, y = grid.y0 + float(j) * grid.dy;
        ref[j * grid.nx + i] = ridged ? Ridged2(4, def, x, y) : Fbm2(4, def, x, y);
      }
    }
    const uint64_t want = HashBits(ref);
    for (Kernel kernel : {Kernel::kScalar, BestKernel()}) {
      for (int threads : {0, 1, 2, 5}) {
        std::unique_ptr<ThreadPool> pool =
            threads ? std::make_unique<ThreadPool>(threads) : nullptr;
        std::vector<float> v(ref.size());
        if (ridged) {
          Ridged2Grid(4, def, grid, v.data(), kernel, pool.get());
        } else {
          Fbm2Grid(4, def, grid, v.data(), kernel, pool.get());
        }
        EXPECT_EQ(HashBits(v), want) << (ridged ? "ridged" : "fbm") << ", kernel " << int(kernel)
                                     << ", " << threads << " threads";
      }
    }
  }
}

std::vector<float> Uniform(size_t n, uint64_t seed, float lo, float hi) {
  std::vector<float> v(n);
  for (size_t i = 0; i < n; ++i) v[i] = lo + (hi - lo) * float(ToUnit(CounterHash(seed, i)));
  return v;
}

TEST(Fractal, ArraysGiveThePointValuesOnEitherKernelAndAnyThreadCount) {
  const size_t n = 5000 + 3;  // chunks of 1024 and a tail of 8 and of 1
  const std::vector<float> x = Uniform(n, 1, -30, 30), y = Uniform(n, 2, -30, 30);
  const std::vector<float> z = Uniform(n, 3, -30, 30);
  const FractalDef def{6, 1.9f, 0.55f};
  using Point2 = float (*)(uint64_t, const FractalDef&, float, float);
  using Point3 = float (*)(uint64_t, const FractalDef&, float, float, float);
  using Array2 = void (*)(uint64_t, const FractalDef&, const float*, const float*, size_t, float*,
                          Kernel, ThreadPool*);
  using Array3 = void (*)(uint64_t, const FractalDef&, const float*, const float*, const float*,
                          size_t, float*, Kernel, ThreadPool*);
  const Point2 p2[2] = {Fbm2, Ridged2};
  const Point3 p3[2] = {Fbm3, Ridged3};
  const Array2 a2[2] = {Fbm2, Ridged2};
  const Array3 a3[2] = {Fbm3, Ridged3};
  for (int ridged = 0; ridged < 2; ++ridged) {
    std::vector<float> ref2(n), ref3(n);
    for (size_t i = 0; i < n; ++i) {
      ref2[i] = p2[ridged](8, def, x[i], y[i]);
      ref3[i] = p3[ridged](8, def, x[i], y[i], z[i]);
    }
    for (Kernel kernel : {Kernel::kScalar, BestKernel()}) {
      for (int threads : {0, 1, 3}) {
        std::unique_ptr<ThreadPool> pool =
            threads ? std::make_unique<ThreadPool>(threads) : nullptr;
        std::vector<float> v2(n), v3(n);
        a2[ridged](8, def, x.data(), y.data(), n, v2.data(), kernel, pool.get());
        a3[ridged](8, def, x.data(), y.data(), z.data(), n, v3.data(), kernel, pool.get());
        EXPECT_EQ(HashBits(v2), HashBits(ref2))
            << (ridged ? "ridged" : "fbm") << " 2D, kernel " << int(kernel) << ", " << threads;
        EXPECT_EQ(HashBits(v3), HashBits(ref3))
            << (ridged ? "ridged" : "fbm") << " 3D, kernel " << int(kernel) << ", " << threads;
      }
    }
  }
}

TEST(Fractal, ThreeDimensionalSumsStayInTheirRanges) {
  const size_t n = 400000;
  const std::vector<float> x = Uniform(n, 4, -300, 300), y = Uniform(n, 5, -300, 300);
  const std::vector<float> z = Uniform(n, 6, -300, 300);
  std::vector<float> v(n);
  Fbm3(2, FractalDef{}, x.data(), y.data(), z.data(), n, v.data());
  const Range f = Measure(v);
  EXPECT_GE(f.lo, -1.0f);
  EXPECT_LE(f.hi, 1.0f);
  EXPECT_GT(f.hi - f.lo, 0.8f) << "fbm 3D measured [" << f.lo << ", " << f.hi << "]";
  Ridged3(2, FractalDef{}, x.data(), y.data(), z.data(), n, v.data());
  const Range r = Measure(v);
  EXPECT_GE(r.lo, 0.0f);
  EXPECT_LE(r.hi, 1.0f);
  EXPECT_GT(r.hi - r.lo, 0.5f) << "ridged 3D measured [" << r.lo << ", " << r.hi << "]";
}

TEST(Fractal, BadDefsAreRejectedWithTheFieldAndValue) {
  EXPECT_TRUE(Validate(FractalDef{}).ok());
  const Status octaves = Validate(FractalDef{0, 2.0f, 0.5f});
  ASSERT_FALSE(octaves.ok());
  EXPECT_EQ(octaves.error().message, "FractalDef.octaves 0 is outside 1..16");
  const Status lac = Validate(FractalDef{6, std::nanf(""), 0.5f});
  ASSERT_FALSE(lac.ok());
  EXPECT_EQ(lac.error().message, "FractalDef.lacunarity nan is outside 1..16");
  const Status gain = Validate(FractalDef{6, 2.0f, 1.5f});
  ASSERT_FALSE(gain.ok());
  EXPECT_EQ(gain.error().message, "FractalDef.gain 1.5 is outside 0..1");
}

}  // namespace
}  // namespace sylva::terrain
