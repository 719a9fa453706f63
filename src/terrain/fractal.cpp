#include "terrain/fractal.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/assert.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "terrain/noise_kernels.h"

namespace sylva::terrain {
namespace {

constexpr int kMaxOctaves = 16;
constexpr float kRidgeWeight = 2.0f;

// Per-octave keys, frequencies and amplitudes, and their sum (the sum of
// samples is divided by it, not multiplied by its inverse: a sum of a_k s_k
// with every s_k <= 1, accumulated in the same order as the total, then
// stays <= 1 after rounding).
struct Octaves {
  int count = 0;
  uint32_t key[kMaxOctaves];
  float freq[kMaxOctaves];
  float amp[kMaxOctaves];
  float total = 1.0f;
};

Octaves MakeOctaves(uint64_t seed, const FractalDef& def) {
  SYLVA_ASSERT(def.octaves >= 1 && def.octaves <= kMaxOctaves);
  Octaves o;
  o.count = def.octaves;
  float f = 1.0f, a = 1.0f, total = 0.0f;
  for (int k = 0; k < o.count; ++k) {
    o.key[k] = uint32_t(CounterHash(seed, 0x7465727261696eULL, uint64_t(k)) >> 32);
    o.freq[k] = f;
    o.amp[k] = a;
    total += a;
    f *= def.lacunarity;
    a *= def.gain;
  }
  o.total = total;
  return o;
}

inline float RidgeSignal(float n, float weight) {
  const float s = 1.0f - std::fabs(n);
  return (s * s) * weight;
}

inline float NextWeight(float s) {
  return std::min(std::max(s * kRidgeWeight, 0.0f), 1.0f);
}

// One octave's contribution folded into (sum, weight), the same in every
// path: the point calls, the arrays and the grids.
template <bool kRidged>
inline void Accumulate(float a, float n, float& sum, float& weight) {
  if constexpr (kRidged) {
    const float s = RidgeSignal(n, weight);
    sum += a * s;
    weight = NextWeight(s);
  } else {
    sum += a * n;
  }
}

template <bool kRidged>
float PointSum(const Octaves& o, float x, float y) {
  float sum = 0.0f, weight = 1.0f;
  for (int k = 0; k < o.count; ++k) {
    Accumulate<kRidged>(o.amp[k], kernels::Noise2(o.key[k], x * o.freq[k], y * o.freq[k]), sum,
                        weight);
  }
  return sum / o.total;
}

template <bool kRidged>
float PointSum(const Octaves& o, float x, float y, float z) {
  float sum = 0.0f, weight = 1.0f;
  for (int k = 0; k < o.count; ++k) {
    const float f = o.freq[k];
    Accumulate<kRidged>(o.amp[k], kernels::Noise3(o.key[k], x * f, y * f, z * f), sum, weight);
  }
  return sum / o.total;
}

// Arrays of points (z null: 2D), in chunks of kChunk on the pool.
constexpr size_t kChunk = 1024;

template <bool kRidged>
void ArraySum(uint64_t seed, const FractalDef& def, const float* x, const float* y, const float* z,
              size_t count, float* out, Kernel kernel, ThreadPool* pool) {
  const Octaves o = MakeOctaves(seed, def);
  const size_t chunks = (count + kChunk - 1) / kChunk;
  ForRanges(pool, chunks, BalancedGrain(pool, chunks, 1), [&](size_t begin, size_t end) {
    float n[kChunk], weight[kChunk];
    for (size_t c = begin; c < end; ++c) {
      const size_t first = c * kChunk, m = std::min(kChunk, count - first);
      float* sum = out + first;
      std::fill(sum, sum + m, 0.0f);
      std::fill(weight, weight + m, 1.0f);
      for (int k = 0; k < o.count; ++k) {
        if (z) {
          kernels::Noise3Points(kernel, o.key[k], x + first, y + first, z + first, o.freq[k], m, n);
        } else {
          kernels::Noise2Points(kernel, o.key[k], x + first, y + first, o.freq[k], m, n);
        }
        for (size_t i = 0; i < m; ++i) Accumulate<kRidged>(o.amp[k], n[i], sum[i], weight[i]);
      }
      for (size_t i = 0; i < m; ++i) sum[i] /= o.total;
    }
  });
}

template <bool kRidged>
void GridSum(uint64_t seed, const FractalDef& def, const Grid2& grid, float* out, Kernel kernel,
             ThreadPool* pool) {
  SYLVA_ASSERT(grid.nx < (size_t(1) << 24) && grid.ny < (size_t(1) << 24));
  const Octaves o = MakeOctaves(seed, def);
  const size_t grain = BalancedGrain(pool, grid.ny, 4);
  ForRanges(pool, grid.ny, grain, [&](size_t begin, size_t end) {
    std::vector<float> n(grid.nx), weight(grid.nx);  // weight: ridged only
    for (size_t j = begin; j < end; ++j) {
      float* row = out + j * grid.nx;
      const float y = grid.y0 + float(int32_t(j)) * grid.dy;
      std::fill(row, row + grid.nx, 0.0f);
      std::fill(weight.begin(), weight.end(), 1.0f);
      for (int k = 0; k < o.count; ++k) {
        kernels::Noise2Row(kernel, o.key[k], grid.x0, grid.dx, y, o.freq[k], grid.nx, n.data());
        for (size_t i = 0; i < grid.nx; ++i) Accumulate<kRidged>(o.amp[k], n[i], row[i], weight[i]);
      }
      for (size_t i = 0; i < grid.nx; ++i) row[i] /= o.total;
    }
  });
}

std::string Out(const char* field, double v, const char* range) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "FractalDef.%s %g is outside %s", field, v, range);
  return buf;
}

}  // namespace

Status Validate(const FractalDef& def) {
  Diagnostic d;
  if (!(def.octaves >= 1 && def.octaves <= kMaxOctaves)) {
    d.message = Out("octaves", def.octaves, "1..16");
  } else if (!(def.lacunarity >= 1.0f && def.lacunarity <= 16.0f)) {
    d.message = Out("lacunarity", def.lacunarity, "1..16");
  } else if (!(def.gain >= 0.0f && def.gain <= 1.0f)) {
    d.message = Out("gain", def.gain, "0..1");
  } else {
    return {};
  }
  return d;
}

float Fbm2(uint64_t seed, const FractalDef& def, float x, float y) {
  return PointSum<false>(MakeOctaves(seed, def), x, y);
}

float Ridged2(uint64_t seed, const FractalDef& def, float x, float y) {
  return PointSum<true>(MakeOctaves(seed, def), x, y);
}

float Fbm3(uint64_t seed, const FractalDef& def, float x, float y, float z) {
  return PointSum<false>(MakeOctaves(seed, def), x, y, z);
}

float Ridged3(uint64_t seed, const FractalDef& def, float x, float y, float z) {
  return PointSum<true>(MakeOctaves(seed, def), x, y, z);
}

void Fbm2(uint64_t seed, const FractalDef& def, const float* x, const float* y, size_t n,
          float* out, Kernel kernel, ThreadPool* pool) {
  ArraySum<false>(seed, def, x, y, nullptr, n, out, kernel, pool);
}

void Ridged2(uint64_t seed, const FractalDef& def, const float* x, const float* y, size_t n,
             float* out, Kernel kernel, ThreadPool* pool) {
  ArraySum<true>(seed, def, x, y, nullptr, n, out, kernel, pool);
}

void Fbm3(uint64_t seed, const FractalDef& def, const float* x, const float* y, const float* z,
          size_t n, float* out, Kernel kernel, ThreadPool* pool) {
  SYLVA_ASSERT(z != nullptr);
  ArraySum<false>(seed, def, x, y, z, n, out, kernel, pool);
}

void Ridged3(uint64_t seed, const FractalDef& def, const float* x, const float* y, const float* z,
             size_t n, float* out, Kernel kernel, ThreadPool* pool) {
  SYLVA_ASSERT(z != nullptr);
  ArraySum<true>(seed, def, x, y, z, n, out, kernel, pool);
}

void Fbm2Grid(uint64_t seed, const FractalDef& def, const Grid2& grid, float* out, Kernel kernel,
              ThreadPool* pool) {
  GridSum<false>(seed, def, grid, out, kernel, pool);
}

void Ridged2Grid(uint64_t seed, const FractalDef& def, const Grid2& grid, float* out, Kernel kernel,
                 ThreadPool* pool) {
  GridSum<true>(seed, def, grid, out, kernel, pool);
}

}  // namespace sylva::terrain
