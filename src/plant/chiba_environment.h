// cpfg's `chiba` environment program, built in: the light that reaches a
// leaf cluster through the other clusters (N. Chiba, K. Ohkawa, K. Muraoka
// & M. Miura, "Visual simulation of botanical trees based on virtual
// heliotropism and dormancy break", J. Visualization and Computer Animation
// 5, 1994; vlab's two-trees object). cpfg runs it as a separate process;
// Sylva answers the same ?E modules with the same rules.
//
// After each step every ?E(r) (or ?E(r, a, b, c)) is a leaf cluster: a ball
// of radius r at the turtle's position (the spec file's `radius:` when
// r <= 0). For each light direction (the `source direction: x y z w` lines,
// intensities scaled to sum 1; without them, the centres of a subdivided
// octahedron's triangles, `number of samples:` rounded up to 8 * 4^k, the
// upper half weighted against the lower by `lower to upper ratio:`, or by
// the CIE overcast sky with `use CIE formula: yes`) a ray leaves the
// cluster's centre toward the light, and each other cluster on its way
// takes a share:
//   `estimate intersection area: on`: a cluster whose centre is not behind
//     the start (toward the light) and whose disc, seen along the ray,
//     overlaps the querying cluster's disc by area A lets 1 - (1 - t) A /
//     (pi r^2) through;
//   off: a cluster whose ball (radius + `beam radius:` x r) the ray crosses
//     for a length s lets t^(s / (2 (its radius + beam radius x r))).
// with t the `transmittance:`. ?E's first parameter becomes the light
// received (0..1); with 4 parameters the other three become the brightest
// direction (the sum of the light directions weighted by what arrives,
// normalized). ?E with 2 or 3 parameters is not answered, as in chiba.
//
// Differences from the program: every cluster is tested against each ray
// (chiba walks a voxel grid that tightly encloses the clusters and stops at
// its border, so it can miss a cluster whose overlap with the ray lies
// outside the grid). Computation is in single precision as in chiba.
#pragma once

#include <span>
#include <vector>

#include "core/math.h"
#include "plant/environment.h"

namespace sylva::plant {

struct ChibaDef {
  struct Source {
    float dir[3] = {0, 1, 0};
    float intensity = 1;
  };
  std::vector<Source> sources;  // `source direction:`; empty: sky samples
  int samples = 20;             // `number of samples:`
  float lowerToUpper = 0.7f;    // `lower to upper ratio:`
  bool cie = false;             // `use CIE formula: yes`
  float transmittance = 0.6f;   // `transmittance:`
  float radius = 25;            // `radius:` for ?E(0)
  float beamRadius = 0;         // `beam radius:`
  bool estimateArea = false;    // `estimate intersection area: on`
};

// The light directions and intensities the program uses for `def`: the
// sources normalized, or the sky samples.
std::vector<ChibaDef::Source> ChibaDirections(const ChibaDef& def);

class ChibaEnvironment final : public Environment {
 public:
  // `coordinates`: how many the .e file's `turtle position:` sends (3
  // needed).
  ChibaEnvironment(const ChibaDef& def, int coordinates);
  Status Answer(std::span<EnvQuery> queries) override;

 private:
  ChibaDef def_;
  std::vector<ChibaDef::Source> dirs_;
  int coordinates_;
};

}  // namespace sylva::plant
