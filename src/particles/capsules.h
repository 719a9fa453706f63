// Capsules with a bounding-volume hierarchy: a plant's branches as
// colliders. A capsule is the set of points within `radius` of the segment
// a-b (a cylinder with hemispherical ends), so a chain of capsules along a
// branch is a closed tube with rounded joints and no gaps, and a point's
// path a -> b is tested against it in closed form (Collider::Capsules).
//
// Entry of the path p(s) = a + s (b - a), s in [0, 1], into the union of a
// capsule's side and its two end balls: the first root of
//   side: |(p - pa) x u|^2 = r^2 with the axial coordinate inside the
//         segment (u the unit axis),
//   ends: |p - pa|^2 = r^2 and |p - pb|^2 = r^2,
// whichever comes first (Quilez's capsule intersection, "Intersectors",
// iquilezles.org, in segment form). A path that starts inside a capsule
// reports s = 0 at the nearest surface point.
//
// Two accelerations. A uniform grid (about four cells a capsule, at most
// 256 an axis; each cell lists the capsules whose boxes touch it) answers
// the common query, a particle's short step through a canopy, by testing
// the few capsules of the cells the step's box covers. A hierarchy (the
// triangles' one, collider.h: median split on the longest axis of the
// centres' box, at most 4 capsules a leaf) answers long paths. Both give
// the same first entry. Memory: 56 bytes a capsule, about 64 a node, 4 a
// cell and 4 a listed capsule.
#pragma once

#include <cstdint>
#include <vector>

#include "core/math.h"
#include "particles/collider.h"

namespace sylva::particles {

struct Capsule {  // 56 bytes
  Vec3 a, b;
  double radius = 0;
};

class CapsuleBvh {
 public:
  // Capsules with a non-finite coordinate or a radius not above 0 are
  // dropped (counted by dropped()).
  explicit CapsuleBvh(std::vector<Capsule> capsules);
  // First entry of the segment a -> b into any capsule; with r > 0, into
  // the capsules grown by r (a ball of radius r on the path touching one).
  bool Intersect(const Vec3& a, const Vec3& b, Contact* c, double r = 0) const;
  size_t size() const { return capsules_.size(); }
  size_t dropped() const { return dropped_; }
  int depth() const { return depth_; }
  // Whether x lies inside some capsule (within radius of its segment).
  bool Contains(const Vec3& x) const;

 private:
  struct Node {
    Vec3 lo, hi;
    uint32_t first = 0, count = 0;  // leaf: capsules [first, first + count)
    uint32_t left = 0, right = 0;
  };
  uint32_t Build(uint32_t first, uint32_t count, int depth);
  void BuildGrid();
  bool IntersectGrid(const Vec3& a, const Vec3& b, Contact* c, double r) const;
  std::vector<Capsule> capsules_;
  std::vector<Node> nodes_;
  // The grid: cell (i, j, k) lists items_[start_[cell] .. start_[cell + 1]).
  Vec3 gridLo_ = Vec3::Zero();
  double cell_ = 1;
  int dims_[3] = {0, 0, 0};
  std::vector<uint32_t> start_, items_;
  size_t dropped_ = 0;
  int depth_ = 0;
};

// Entry s in [0, 1] of the path a -> b into one capsule, with the outward
// normal at the entry point; false when the path does not enter it.
bool IntersectCapsule(const Capsule& cap, const Vec3& a, const Vec3& b, double* s, Vec3* normal);

}  // namespace sylva::particles
