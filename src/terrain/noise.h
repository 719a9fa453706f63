// Sylva's gradient noise, 2D and 3D: Perlin's improved noise (Perlin 2002,
// "Improving Noise", SIGGRAPH; the quintic fade 6t^5 - 15t^4 + 10t^3 and
// fixed gradient sets) with the permutation table replaced by a
// counter-based hash of the lattice point and a seed, so any 64-bit seed
// gives its own field and a value is a pure function of (seed, point).
//
// Values:
//   * 2D: in [-1, 1]. Gradients are the 8 unit vectors at 22.5 + 45k
//     degrees; the largest value they can reach is 0.66082 (found by
//     maximising each corner's best gradient over the cell), scaled by 1.5
//     to 0.9912.
//   * 3D: in [-1, 1]. Gradients are Perlin's 12 cube edges, padded to 16 as
//     in his reference code; their largest value 1.03635 is scaled by 0.96
//     to 0.9949.
//   * Exactly 0 at every lattice point (integer coordinates); C2 continuous.
//   * NaN in any coordinate gives NaN; coordinates should stay within
//     +-2^24 (16.7 million), where floats still have a fraction; beyond
//     2^31 a coordinate's lattice index is meaningless (the value stays
//     finite and deterministic).
//
// Determinism: all arithmetic is single precision IEEE in a fixed order
// (the project builds with -ffp-contract=off), integers are 32-bit wrapping.
// The AVX2 kernels and their scalar twins run the same operations in the
// same order and give the same bits; `BestKernel()` picks AVX2 at run time
// where the processor has it (the binary stays baseline x86-64). Results do
// not depend on thread count, batch size or alignment.
//
// The batch calls are the hot path: on the 2-core VM, about 910 M 2D
// samples/s on one core with AVX2, 134 M/s with the scalar twin
// (bench/bench_terrain.cpp; docs/terrain.md has the figures).
#pragma once

#include <cstddef>
#include <cstdint>

namespace sylva {
class ThreadPool;
}

namespace sylva::terrain {

enum class Kernel { kScalar, kAvx2 };

// The widest kernel this processor runs (AVX2 where available).
Kernel BestKernel();

// One sample.
float GradientNoise2(uint64_t seed, float x, float y);
float GradientNoise3(uint64_t seed, float x, float y, float z);

// A grid of sample points: point (i, j) is (x0 + i dx, y0 + j dy), both
// computed in float exactly as written (float(i) * dx, then + x0), and its
// value goes to out[j * nx + i]. nx and ny must be below 2^24.
struct Grid2 {
  float x0 = 0, y0 = 0;
  float dx = 1, dy = 1;
  size_t nx = 0, ny = 0;
};

// out[i] = GradientNoise2(seed, x[i], y[i]) for i in [0, n): bit for bit
// the single-sample values, whatever the kernel. The caller allocates out.
void GradientNoise2(uint64_t seed, const float* x, const float* y, size_t n, float* out,
                    Kernel kernel = BestKernel());
void GradientNoise3(uint64_t seed, const float* x, const float* y, const float* z, size_t n,
                    float* out, Kernel kernel = BestKernel());

// Fills out[0 .. nx ny) with the grid's samples; rows run on `pool` when
// given (the values do not depend on it).
void GradientNoise2Grid(uint64_t seed, const Grid2& grid, float* out, Kernel kernel = BestKernel(),
                        ThreadPool* pool = nullptr);

}  // namespace sylva::terrain
