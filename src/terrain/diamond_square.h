// Diamond-square midpoint displacement (Fournier, Fussell & Carpenter 1982,
// "Computer rendering of stochastic models", CACM 25(6); the diamond-square
// ordering of Miller 1986, "The definition and rendering of terrain maps",
// SIGGRAPH) on a (2^k + 1)^2 grid.
//
// The four corners are seeded (values in [-1, 1]: given, or hashed from the
// seed). Level l = 1..k halves the step s = (n - 1) / 2^l:
//   diamond: each square's centre = mean of its 4 corners + r^l u
//   square:  each edge midpoint  = mean of its 4 (3 on the border)
//            diamond neighbours + r^l u
// with r the roughness and u in [-1, 1) a counter-based hash of (seed, i,
// j): a value does not depend on the order of evaluation, so each level's
// points run in parallel and the result is the same whatever the thread
// count. Means are summed in a fixed order. |value| <= Bound(def) =
// sum_{l=0..k} r^l (corners count as level 0).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/status.h"

namespace sylva {
class ThreadPool;
}

namespace sylva::terrain {

struct DiamondSquareDef {
  int size = 257;  // vertices per side: 2^k + 1, 2..8193
  uint64_t seed = 1;
  float roughness = 0.5f;  // 0..1: displacement factor per level (0.5: Hurst exponent 1)
  // Corner values (i, j) = (0, 0), (n-1, 0), (0, n-1), (n-1, n-1), each in
  // [-1, 1]; absent: hashed from the seed.
  std::optional<std::array<float, 4>> corners;
};

// "DiamondSquareDef.size 200 is not 2^k + 1 (2..8193)" and the like.
Status Validate(const DiamondSquareDef& def);

// The largest |value| the def can produce.
float Bound(const DiamondSquareDef& def);

// size^2 values, row-major: value (i, j) at [j size + i]. Validates first.
Expected<std::vector<float>> DiamondSquare(const DiamondSquareDef& def, ThreadPool* pool = nullptr);

}  // namespace sylva::terrain
