// Golden bits: values and hashes written down from a GCC 12 build and
// checked identical under clang 14. A change to the hash, the gradients, the
// fade, the octave keys or the order of any operation changes them: scenes
// that name a seed would get other terrain. Change them only on purpose,
// and say so in docs/terrain.md.
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "core/rng.h"
#include "terrain/diamond_square.h"
#include "terrain/fractal.h"
#include "terrain/height_field.h"
#include "terrain/noise.h"

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

TEST(TerrainGolden, SamplesHaveTheirRecordedBits) {
  EXPECT_EQ(GradientNoise2(1, 0.5f, 0.25f), 0x1.4cdd28p-1f);
  EXPECT_EQ(GradientNoise3(42, 1.3f, -2.7f, 0.1f), -0x1.2d19e2p-2f);
  EXPECT_EQ(Fbm2(7, FractalDef{}, 3.7f, -1.2f), 0x1.bd455p-3f);
  EXPECT_EQ(Ridged2(7, FractalDef{}, 3.7f, -1.2f), 0x1.04fbfcp-2f);
  EXPECT_EQ(Fbm3(7, FractalDef{}, 3.7f, -1.2f, 0.4f), 0x1.66a416p-2f);
}

TEST(TerrainGolden, FieldsHaveTheirRecordedHashes) {
  DiamondSquareDef d;
  d.size = 65;
  EXPECT_EQ(HashBits(*DiamondSquare(d)), 0xf1538c7382095ed2ull);
  EXPECT_EQ(HashBits(HeightField::Create(TerrainDef{})->heights()), 0x7c816eb6b1fb20b7ull);
  for (Kernel kernel : {Kernel::kScalar, BestKernel()}) {
    const Grid2 g{-3, -3, 0.01f, 0.013f, 333, 111};
    std::vector<float> v(g.nx * g.ny);
    GradientNoise2Grid(5, g, v.data(), kernel);
    EXPECT_EQ(HashBits(v), 0x70572a7a0a08b603ull) << "kernel " << int(kernel);
  }
}

}  // namespace
}  // namespace sylva::terrain
