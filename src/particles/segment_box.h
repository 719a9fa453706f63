// What the bounding hierarchies of colliders share (collider.cpp's
// triangles, capsules.cpp's capsules): the slab test of a segment against a
// box, and the walk down a hierarchy along a segment.
#pragma once

#include <algorithm>
#include <cmath>
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

// Builds the node over items [first, first + count) and those below it:
// median split on the longest axis of the items' centres, at most 4 items a
// leaf. bounds(item, lo, hi) grows a box by an item; centre(item) is a
// point inside it (any fixed multiple of it sorts the same). Returns the
// node's index; `depth` tracks the deepest level.
template <typename Node, typename Item, typename Bounds, typename Centre>
uint32_t BuildMedianSplit(std::vector<Node>& nodes, std::vector<Item>& items, uint32_t first,
                          uint32_t count, int level, int& depth, const Bounds& bounds,
                          const Centre& centre) {
  depth = std::max(depth, level);
  Node node;
  node.lo = Vec3::Constant(HUGE_VAL);
  node.hi = Vec3::Constant(-HUGE_VAL);
  Vec3 clo = node.lo, chi = node.hi;
  for (uint32_t i = first; i < first + count; ++i) {
    bounds(items[i], node.lo, node.hi);
    const Vec3 c = centre(items[i]);
    clo = clo.cwiseMin(c);
    chi = chi.cwiseMax(c);
  }
  const uint32_t index = uint32_t(nodes.size());
  nodes.push_back(node);
  if (count <= 4) {
    nodes[index].first = first;
    nodes[index].count = count;
    return index;
  }
  int axis;
  (chi - clo).maxCoeff(&axis);
  const uint32_t mid = first + count / 2;
  std::nth_element(items.begin() + first, items.begin() + mid, items.begin() + first + count,
                   [&](const Item& x, const Item& y) { return centre(x)[axis] < centre(y)[axis]; });
  const uint32_t left =
      BuildMedianSplit(nodes, items, first, mid - first, level + 1, depth, bounds, centre);
  const uint32_t right =
      BuildMedianSplit(nodes, items, mid, first + count - mid, level + 1, depth, bounds, centre);
  nodes[index].first = 0;
  nodes[index].count = 0;
  nodes[index].left = left;
  nodes[index].right = right;
  return index;
}

// Visits the leaves of a hierarchy (nodes with lo, hi, first, count, left,
// right; node 0 the root, count 0 for an inner node) whose boxes the
// segment a + t d meets for t in [0, min(best, 1)]: leaf(first, count) may
// lower `best` (the first entry found so far), which prunes the rest. With
// pad > 0, the boxes grown by pad in every direction (a ball's path).
template <typename Node, typename Leaf>
void WalkSegment(const std::vector<Node>& nodes, const Vec3& a, const Vec3& d, const double& best,
                 Leaf&& leaf, double pad = 0) {
  if (nodes.empty()) return;
  uint32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes[stack[--top]];
    if (pad == 0 ? !SegmentBox(a, d, node.lo, node.hi, std::min(best, 1.0))
                 : !SegmentBox(a, d, node.lo - Vec3::Constant(pad), node.hi + Vec3::Constant(pad),
                               std::min(best, 1.0))) {
      continue;
    }
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
