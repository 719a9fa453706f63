// Does the segment a + t d, t in [0, tmax], meet the box [lo, hi]? The slab
// test the bounding hierarchies share (collider.cpp, capsules.cpp).
#pragma once

#include <algorithm>

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

}  // namespace sylva::particles
