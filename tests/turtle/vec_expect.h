// Vector comparisons for the turtle tests: the failure message prints both
// vectors.
#pragma once

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "core/math.h"

namespace sylva::turtle {

inline std::string Str(const Vec3& v) {
  char b[96];
  std::snprintf(b, sizeof b, "(%.12g, %.12g, %.12g)", v.x(), v.y(), v.z());
  return b;
}

}  // namespace sylva::turtle

#define EXPECT_VEC_NEAR(a, b, tol) \
  EXPECT_LT(((a) - (b)).norm(), tol) << "got " << Str(a) << ", want " << Str(b)
