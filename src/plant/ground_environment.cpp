#include "plant/ground_environment.h"

namespace sylva::plant {

Ground FlatGround() {
  return Ground{[](double, double) { return 0.0; }, [](double, double) { return Vec3(0, 1, 0); }};
}

Status GroundEnvironment::Answer(std::span<EnvQuery> queries) {
  for (EnvQuery& q : queries) {
    if (q.params.empty()) continue;
    const double x = q.position.x(), z = q.position.z();
    q.params[0] = ground_.height(x, z);
    if (q.params.size() >= 4) {
      const Vec3 n = ground_.normal(x, z);
      for (int c = 0; c < 3; ++c) q.params[1 + c] = n[c];
    }
  }
  return {};
}

}  // namespace sylva::plant
