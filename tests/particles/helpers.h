// Helpers shared by the particle tests.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <memory>

#include "particles/system.h"

// STEP_OK(system, h, integrator): one step that must succeed, with the
// fault's message in the failure.
#define STEP_OK(sys, h, in)                       \
  do {                                            \
    ::sylva::Status st_ = (sys).Step((h), (in));  \
    ASSERT_TRUE(st_.ok()) << st_.error().message; \
  } while (0)

// ASSERT_OK(status): a Status that must be ok, with its message in the
// failure.
#define ASSERT_OK(expr)                           \
  do {                                            \
    ::sylva::Status st_ = (expr);                 \
    ASSERT_TRUE(st_.ok()) << st_.error().message; \
  } while (0)

// EXPECT_OK(status): the same, not fatal (usable in any function).
#define EXPECT_OK(expr)                           \
  do {                                            \
    ::sylva::Status st_ = (expr);                 \
    EXPECT_TRUE(st_.ok()) << st_.error().message; \
  } while (0)

namespace sylva::particles::testing {

// The value of an Expected that the test's own (valid) input must give; a
// Diagnostic fails the test with its message and stops it.
template <typename T>
T Made(Expected<T> e) {
  if (!e.ok()) {
    ADD_FAILURE() << "unexpected diagnostic: " << e.error().message;
    std::abort();
  }
  return std::move(e).value();
}

// An immovable anchor at the origin (particle 0) and a unit mass at x0 on
// the x axis (particle 1), joined by an undamped spring.
inline void AddAnchoredSpring(System& s, double x0, double rest, double ks) {
  s.state.AddPinned(Vec3::Zero());
  s.state.Add(Vec3(x0, 0, 0), Vec3::Zero(), 1);
  auto springs = std::make_shared<Springs>();
  const Status added = springs->Add(1, 0, rest, ks, 0.0);
  EXPECT_TRUE(added.ok()) << added.error().message;
  s.AddForce(springs);
}

}  // namespace sylva::particles::testing
