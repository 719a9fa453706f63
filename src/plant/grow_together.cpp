#include "plant/grow_together.h"

#include <memory>
#include <optional>

#include "core/assert.h"

namespace sylva::plant {
namespace {

// Keeps one plant's queries of its last step for the shared round. Their
// parameters point into the plant's word, which does not change until the
// plant steps again.
class Collector final : public Environment {
 public:
  std::vector<EnvQuery> queries;
  Status Answer(std::span<EnvQuery> q) override {
    queries.assign(q.begin(), q.end());
    return {};
  }
};

}  // namespace

std::vector<PlantResult> GrowTogether(std::span<const PlantSpec> specs,
                                      std::span<const Placement> placements, Environment& shared) {
  SYLVA_ASSERT(specs.size() == placements.size());
  const size_t n = specs.size();
  std::vector<PlantResult> results(n);
  std::vector<Collector> collectors(n);
  std::vector<std::optional<Grower>> growers(n);
  std::vector<Eigen::Matrix3d> turn(n);
  auto fail = [&](size_t i, Diagnostic d) {
    if (d.loc.file.empty()) d.loc.file = specs[i].path;
    results[i].diagnostics.Add(std::move(d));
    growers[i].reset();
  };
  for (size_t i = 0; i < n; ++i) {
    PlantSpec s = specs[i];
    s.environment = &collectors[i];
    growers[i] = Grower::Start(s, results[i].diagnostics);
    turn[i] =
        Eigen::AngleAxisd(placements[i].yawDegrees * 3.14159265358979323846 / 180, Vec3::UnitY())
            .toRotationMatrix();
  }
  // Every living plant's queries, in world coordinates, in one call.
  auto round = [&]() {
    std::vector<EnvQuery> all;
    for (size_t i = 0; i < n; ++i) {
      if (!growers[i]) continue;
      const Placement& at = placements[i];
      for (EnvQuery q : collectors[i].queries) {
        q.position = at.position + turn[i] * (at.scale * q.position);
        q.frame.heading = turn[i] * q.frame.heading;
        q.frame.left = turn[i] * q.frame.left;
        q.frame.up = turn[i] * q.frame.up;
        q.plant = uint32_t(i);
        all.push_back(q);
      }
    }
    if (all.empty()) return;
    if (Status s = shared.Answer(all); !s.ok()) {
      for (size_t i = 0; i < n; ++i)
        if (growers[i]) fail(i, s.error());
    }
  };
  round();
  while (true) {
    bool stepped = false;
    for (size_t i = 0; i < n; ++i) {
      if (!growers[i] || growers[i]->done()) continue;
      collectors[i].queries.clear();
      if (Status s = growers[i]->Step(); !s.ok()) {
        fail(i, s.error());
        continue;
      }
      stepped = true;
    }
    if (!stepped) break;
    round();
  }
  for (size_t i = 0; i < n; ++i) {
    if (!growers[i]) continue;
    results[i] = std::move(*growers[i]).Finish();
  }
  return results;
}

}  // namespace sylva::plant
