// ShapeEnvironment: pruning to a shape (topiary). ?E's first parameter
// becomes 1 when the query lies inside the shape (its boundary included)
// and 0 outside; further parameters keep their values. A hedge grammar
// stops growing the tips whose ?E reads 0 (Prusinkiewicz, James & Mech,
// "Synthetic topiary", SIGGRAPH 1994).
//
//   environment: shape box(x0, y0, z0, x1, y1, z1)     corners, any order
//   environment: shape sphere(x, y, z, r)
//   environment: shape ellipsoid(x, y, z, rx, ry, rz)  axis-aligned
#pragma once

#include <span>

#include "core/math.h"
#include "plant/environment.h"

namespace sylva::plant {

struct ShapeDef {
  enum class Kind { kBox, kSphere, kEllipsoid };
  Kind kind = Kind::kBox;
  Vec3 a{0, 0, 0};  // box: the low corner; sphere, ellipsoid: the centre
  Vec3 b{1, 1, 1};  // box: the high corner; sphere: (r, r, r); ellipsoid: radii
};

// True when p is inside the shape or on its boundary (a NaN in any
// component is outside).
bool Contains(const ShapeDef& shape, const Vec3& p);

class ShapeEnvironment final : public Environment {
 public:
  explicit ShapeEnvironment(const ShapeDef& def) : def_(def) {}
  Status Answer(std::span<EnvQuery> queries) override;
  const ShapeDef& def() const { return def_; }

 private:
  ShapeDef def_;
};

}  // namespace sylva::plant
