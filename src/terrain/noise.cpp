#include "terrain/noise.h"

#include "core/assert.h"
#include "core/parallel.h"
#include "terrain/noise_kernels.h"

namespace sylva::terrain {

Kernel BestKernel() {
  // cpu_init first: BestKernel() may run in a static constructor, before main.
  static const Kernel best =
      (__builtin_cpu_init(), __builtin_cpu_supports("avx2")) ? Kernel::kAvx2 : Kernel::kScalar;
  return best;
}

float GradientNoise2(uint64_t seed, float x, float y) {
  return kernels::Noise2(kernels::KeyOf(seed), x, y);
}

float GradientNoise3(uint64_t seed, float x, float y, float z) {
  return kernels::Noise3(kernels::KeyOf(seed), x, y, z);
}

void GradientNoise2(uint64_t seed, const float* x, const float* y, size_t n, float* out,
                    Kernel kernel) {
  kernels::Noise2Points(kernel, kernels::KeyOf(seed), x, y, 1.0f, n, out);
}

void GradientNoise3(uint64_t seed, const float* x, const float* y, const float* z, size_t n,
                    float* out, Kernel kernel) {
  kernels::Noise3Points(kernel, kernels::KeyOf(seed), x, y, z, 1.0f, n, out);
}

void GradientNoise2Grid(uint64_t seed, const Grid2& grid, float* out, Kernel kernel,
                        ThreadPool* pool) {
  SYLVA_ASSERT(grid.nx < (size_t(1) << 24) && grid.ny < (size_t(1) << 24));
  const uint32_t key = kernels::KeyOf(seed);
  const size_t grain = BalancedGrain(pool, grid.ny, 8);
  ForRanges(pool, grid.ny, grain, [&](size_t begin, size_t end) {
    for (size_t j = begin; j < end; ++j) {
      const float y = grid.y0 + float(int32_t(j)) * grid.dy;
      kernels::Noise2Row(kernel, key, grid.x0, grid.dx, y, 1.0f, grid.nx, out + j * grid.nx);
    }
  });
}

}  // namespace sylva::terrain
