#include "terrain/diamond_square.h"

#include <cstdio>
#include <string>

#include "core/parallel.h"
#include "core/rng.h"

namespace sylva::terrain {
namespace {

constexpr int kMaxSize = 8193;
constexpr uint64_t kPurpose = 0x6469616d6f6e64ULL;  // "diamond"

// Uniform in [-1, 1) from (seed, i, j): 24 bits, exact in float.
inline float Displacement(uint64_t seed, size_t i, size_t j) {
  const uint64_t h = CounterHash(seed, kPurpose, i, j);
  return float(int32_t(h >> 40) - (1 << 23)) * 0x1.0p-23f;
}

bool IsPowerOfTwoPlusOne(int n) {
  return n >= 2 && ((n - 1) & (n - 2)) == 0;
}

}  // namespace

Status Validate(const DiamondSquareDef& def) {
  char buf[200];
  if (!(def.size >= 2 && def.size <= kMaxSize && IsPowerOfTwoPlusOne(def.size))) {
    std::snprintf(buf, sizeof buf, "DiamondSquareDef.size %d is not 2^k + 1 (2..%d)", def.size,
                  kMaxSize);
  } else if (!(def.roughness >= 0.0f && def.roughness <= 1.0f)) {
    std::snprintf(buf, sizeof buf, "DiamondSquareDef.roughness %g is outside 0..1",
                  double(def.roughness));
  } else {
    if (def.corners) {
      for (int c = 0; c < 4; ++c) {
        const float v = (*def.corners)[size_t(c)];
        if (!(v >= -1.0f && v <= 1.0f)) {
          std::snprintf(buf, sizeof buf, "DiamondSquareDef.corners[%d] %g is outside -1..1", c,
                        double(v));
          Diagnostic d;
          d.message = buf;
          return d;
        }
      }
    }
    return {};
  }
  Diagnostic d;
  d.message = buf;
  return d;
}

float Bound(const DiamondSquareDef& def) {
  float bound = 1.0f, a = 1.0f;
  for (int s = def.size - 1; s > 1; s /= 2) {
    a *= def.roughness;
    bound += a;
  }
  return bound;
}

Expected<std::vector<float>> DiamondSquare(const DiamondSquareDef& def, ThreadPool* pool) {
  if (Status st = Validate(def); !st.ok()) return st.error();
  const size_t n = size_t(def.size), last = n - 1;
  std::vector<float> h(n * n, 0.0f);
  auto at = [&](size_t i, size_t j) -> float& { return h[j * n + i]; };
  const size_t cornerIndex[4][2] = {{0, 0}, {last, 0}, {0, last}, {last, last}};
  for (int c = 0; c < 4; ++c) {
    const size_t i = cornerIndex[c][0], j = cornerIndex[c][1];
    at(i, j) = def.corners ? (*def.corners)[size_t(c)] : Displacement(def.seed, i, j);
  }
  float amp = 1.0f;
  for (size_t step = last; step > 1; step /= 2) {
    const size_t half = step / 2;
    amp *= def.roughness;
    // Diamond: centres of the squares of side `step`.
    const size_t cells = last / step;
    ForRanges(pool, cells, BalancedGrain(pool, cells, 16), [&](size_t b, size_t e) {
      for (size_t cj = b; cj < e; ++cj) {
        const size_t j = cj * step + half;
        for (size_t i = half; i < last; i += step) {
          const float mean =
              (((at(i - half, j - half) + at(i + half, j - half)) + at(i - half, j + half)) +
               at(i + half, j + half)) *
              0.25f;
          at(i, j) = mean + amp * Displacement(def.seed, i, j);
        }
      }
    });
    // Square: edge midpoints, the rows j = 0, half, step, ...; a point's
    // neighbours are up, down, left and right at distance `half`.
    const size_t rows = last / half + 1;
    ForRanges(pool, rows, BalancedGrain(pool, rows, 16), [&](size_t b, size_t e) {
      for (size_t r = b; r < e; ++r) {
        const size_t j = r * half;
        for (size_t i = (r % 2 == 0) ? half : 0; i <= last; i += step) {
          float sum = 0.0f, count = 0.0f;
          if (i >= half) sum += at(i - half, j), count += 1.0f;
          if (i + half <= last) sum += at(i + half, j), count += 1.0f;
          if (j >= half) sum += at(i, j - half), count += 1.0f;
          if (j + half <= last) sum += at(i, j + half), count += 1.0f;
          at(i, j) = sum / count + amp * Displacement(def.seed, i, j);
        }
      }
    });
  }
  return h;
}

}  // namespace sylva::terrain
