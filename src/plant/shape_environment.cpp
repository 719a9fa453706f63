#include "plant/shape_environment.h"

namespace sylva::plant {

bool Contains(const ShapeDef& s, const Vec3& p) {
  switch (s.kind) {
    case ShapeDef::Kind::kBox:
      // Written so that a NaN compares false in every component.
      return p.x() >= s.a.x() && p.x() <= s.b.x() && p.y() >= s.a.y() && p.y() <= s.b.y() &&
             p.z() >= s.a.z() && p.z() <= s.b.z();
    case ShapeDef::Kind::kSphere:
    case ShapeDef::Kind::kEllipsoid: {
      const Vec3 d = (p - s.a).cwiseQuotient(s.b);
      return d.squaredNorm() <= 1.0;
    }
  }
  return false;
}

Status ShapeEnvironment::Answer(std::span<EnvQuery> queries) {
  for (EnvQuery& q : queries) {
    if (!q.params.empty()) q.params[0] = Contains(def_, q.position) ? 1.0 : 0.0;
  }
  return {};
}

}  // namespace sylva::plant
