// LightGrid: light in a voxel grid by shadow propagation, after Palubicki,
// Horel, Longay, Runions, Lane, Mech & Prusinkiewicz, "Self-organizing tree
// models for image synthesis", SIGGRAPH 2009, section 4.1.
//
// Light comes from above. Every bud (every ?E query) in voxel (I, J, K)
// shadows the pyramid below it: for q = 0..depth layers down, each voxel
// (I + p, J - q, K + r) with |p|, |r| <= q gets shadow += a * b^-q. The
// light a bud receives is its voxel's exposure
//     Q = clamp(1 - s + a, 0, 1)
// (1 is full light; the + a takes its own shadow back out). Plants that
// share one grid compete for light: a bud under another's crown reads less.
//
// Opaque boxes (walls) are 0 inside, and each of their voxels shadows the
// pyramid below it as a bud does (a * b^-q; a box may set its own a), so a
// wall darkens the side of a tree that faces it, the more the nearer.
//
// The grid is dense and rebuilt on every Update(): it spans the buds' box
// widened by `depth` voxels sideways and downward, on voxel boundaries at
// whole multiples of `cell` (so a bud's light does not depend on where the
// other buds are), at most kMaxLightCells voxels. Cost: each bud touches
// sum (2q+1)^2 voxels, 165 for depth 4 (bench/bench_environment.cpp).
//
//   environment: light cell=0.5 depth=5 shadow=0.2 falloff=2 box(x0,y0,z0, x1,y1,z1[, a]) ...
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/math.h"
#include "core/status.h"
#include "plant/environment.h"

namespace sylva::plant {

// 2^25 voxels: 128 MiB of shadow.
inline constexpr uint64_t kMaxLightCells = uint64_t(1) << 25;
// Voxel updates of one Update() (buds and wall voxels times the pyramid's
// sum (2q+1)^2 voxels): 2^32, about 1.3 s at the measured 3.4 G/s.
inline constexpr uint64_t kMaxLightWork = uint64_t(1) << 32;

struct LightBox {
  Vec3 lo{0, 0, 0}, hi{0, 0, 0};  // corners, any order
  double shadow = -1;             // what each voxel casts into its own; < 0: LightDef::shadow
};

struct LightDef {
  double cell = 0.5;            // voxel edge, grammar units; > 0
  int depth = 5;                // layers a bud shadows below itself; 0..64
  double shadow = 0.2;          // a: the shadow a bud casts into its own voxel; > 0
  double falloff = 2;           // b >= 1: shadow q layers down is a * b^-q
  std::vector<LightBox> walls;  // opaque boxes
};

class LightGrid {
 public:
  explicit LightGrid(const LightDef& def) : def_(def) {}

  // Rebuilds the shadow from these buds and the walls. An error when the
  // grid would pass kMaxLightCells voxels or the work kMaxLightWork (or a
  // position is not finite).
  Status Update(std::span<const Vec3> buds);
  // The light at p, 0..1: 0 inside a wall, 1 outside the grid. For a bud
  // that Update() counted, its own shadow is taken back out.
  double Exposure(const Vec3& p) const;

  uint64_t cellCount() const { return shadow_.size(); }
  const LightDef& def() const { return def_; }

 private:
  bool CellOf(const Vec3& p, int64_t* i, int64_t* j, int64_t* k) const;
  void Cast(int64_t i, int64_t j, int64_t k, double strength);
  LightDef def_;
  int64_t origin_[3] = {0, 0, 0};  // voxel index of the grid's first voxel
  int64_t size_[3] = {0, 0, 0};
  std::vector<float> shadow_;    // x fastest, then z, then y
  std::vector<uint8_t> opaque_;  // 1 inside a wall
};

// ?E's first parameter becomes the light at the query (every query is also
// a bud that casts shadow); further parameters keep their values.
class LightEnvironment final : public Environment {
 public:
  explicit LightEnvironment(const LightDef& def) : grid_(def) {}
  Status Answer(std::span<EnvQuery> queries) override;
  const LightGrid& grid() const { return grid_; }

 private:
  LightGrid grid_;
  std::vector<Vec3> buds_;
};

}  // namespace sylva::plant
