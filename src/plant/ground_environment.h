// GroundEnvironment: the terrain under a plant. ?E(h[, nx, ny, nz]) becomes
// the ground's height at the query's x and z and, with 4 parameters, its
// unit normal there; with 2 or 3, the parameters past h keep their values.
// Roots that stop at the surface, a creeper that follows the slope:
//
//   environment: terrain
//
// The ground is given in the plant's own coordinates (grammar units, the
// plant's base at the origin). A scene passes its terrain under a <plant>
// this way (docs/scene.md); anywhere else the ground is the plane y = 0.
#pragma once

#include <functional>
#include <span>

#include "core/math.h"
#include "plant/environment.h"

namespace sylva::plant {

struct Ground {
  std::function<double(double x, double z)> height;  // y of the ground at (x, z)
  std::function<Vec3(double x, double z)> normal;    // its unit normal there
};

// The plane y = 0, normal (0, 1, 0).
Ground FlatGround();

class GroundEnvironment final : public Environment {
 public:
  explicit GroundEnvironment(Ground ground) : ground_(std::move(ground)) {}
  Status Answer(std::span<EnvQuery> queries) override;

 private:
  Ground ground_;
};

}  // namespace sylva::plant
