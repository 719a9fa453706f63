// Fractal sums of gradient noise (noise.h) in 2D and 3D: fractional Brownian
// motion and Musgrave's ridged multifractal (Musgrave, in Ebert et al.,
// "Texturing and Modeling: A Procedural Approach", 3rd ed. 2003, ch. 16:
// fBm and RidgedMultifractal).
//
// Octave k (0-based) samples noise at frequency f_k = lacunarity^k and
// weighs it by amplitude a_k = gain^k (both accumulated in float by
// repeated multiplication); each octave has its own key, hashed from
// (seed, k), so octaves are independent and no artefact piles up at the
// origin.
//   * fBm:    sum_k a_k n_k(f_k p) / sum_k a_k; in [-1, 1].
//   * ridged: s_k = (1 - |n_k|)^2 w_k, w_0 = 1, w_{k+1} = clamp(2 s_k, 0, 1)
//             (Musgrave's offset 1 and weight gain 2: ridges are sharp and
//             valleys smooth); result sum_k a_k s_k / sum_k a_k; in [0, 1].
// The grid calls give the point calls' values bit for bit, with either
// kernel and any thread count.
#pragma once

#include <cstddef>
#include <cstdint>

#include "core/status.h"
#include "terrain/noise.h"

namespace sylva::terrain {

struct FractalDef {
  int octaves = 6;          // 1..16
  float lacunarity = 2.0f;  // 1..16: frequency factor per octave
  float gain = 0.5f;        // 0..1: amplitude factor per octave
};

// A Diagnostic naming the field and value when a number is out of its range
// (NaN included): "FractalDef.octaves 0 is outside 1..16".
Status Validate(const FractalDef& def);

// One sample. The def must be valid (asserted: octaves in 1..16).
float Fbm2(uint64_t seed, const FractalDef& def, float x, float y);
float Ridged2(uint64_t seed, const FractalDef& def, float x, float y);
float Fbm3(uint64_t seed, const FractalDef& def, float x, float y, float z);
float Ridged3(uint64_t seed, const FractalDef& def, float x, float y, float z);

// Arrays of points: out[i] = Fbm2(seed, def, x[i], y[i]) and so on, bit
// for bit; chunks of 1024 points on `pool` when given. The caller
// allocates out (n floats).
void Fbm2(uint64_t seed, const FractalDef& def, const float* x, const float* y, size_t n,
          float* out, Kernel kernel = BestKernel(), ThreadPool* pool = nullptr);
void Ridged2(uint64_t seed, const FractalDef& def, const float* x, const float* y, size_t n,
             float* out, Kernel kernel = BestKernel(), ThreadPool* pool = nullptr);
void Fbm3(uint64_t seed, const FractalDef& def, const float* x, const float* y, const float* z,
          size_t n, float* out, Kernel kernel = BestKernel(), ThreadPool* pool = nullptr);
void Ridged3(uint64_t seed, const FractalDef& def, const float* x, const float* y, const float* z,
             size_t n, float* out, Kernel kernel = BestKernel(), ThreadPool* pool = nullptr);

// The grid's samples (noise.h's Grid2, out[j nx + i]); rows on `pool` when
// given. The def must be valid.
void Fbm2Grid(uint64_t seed, const FractalDef& def, const Grid2& grid, float* out,
              Kernel kernel = BestKernel(), ThreadPool* pool = nullptr);
void Ridged2Grid(uint64_t seed, const FractalDef& def, const Grid2& grid, float* out,
                 Kernel kernel = BestKernel(), ThreadPool* pool = nullptr);

}  // namespace sylva::terrain
