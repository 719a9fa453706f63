// What the bounding hierarchies of colliders share (collider.cpp's
// triangles, capsules.cpp's capsules): the slab test of a segment against a
// box, and the walk down a hierarchy along a segment.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/math.h"

namespace sylva::particles {

inline bool SegmentBox(const Vec3& a, const Vec3& d, const Vec3& lo, const Vec3& hi, double tmax) {
  double t0 = 0, t1 = tmax;
  for (int k = 0; k < 3; ++k) {
    if (d[k] == 0) {
      if (a[k] < lo[k] || a[k] > hi[k]) return false;
      continue;
    }
    const double inv = 1 / d[k];
    double ta = (lo[k] - a[k]) * inv, tb = (hi[k] - a[k]) * inv;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

// Visits the leaves of a hierarchy (nodes with lo, hi, first, count, left,
// right; node 0 the root, count 0 for an inner node) whose boxes the
// segment a + t d meets for t in [0, min(best, 1)]: leaf(first, count) may
// lower `best` (the first entry found so far), which prunes the rest.
template <typename Node, typename Leaf>
void WalkSegment(const std::vector<Node>& nodes, const Vec3& a, const Vec3& d, const double& best,
                 Leaf&& leaf) {
  if (nodes.empty()) return;
  uint32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes[stack[--top]];
    if (!SegmentBox(a, d, node.lo, node.hi, std::min(best, 1.0))) continue;
    if (node.count == 0) {
      if (top + 2 > 128) continue;  // cannot happen for depth < 64
      stack[top++] = node.left;
      stack[top++] = node.right;
      continue;
    }
    leaf(node.first, node.count);
  }
}

}  // namespace sylva::particles
