// Helpers shared by the particle tests.
#pragma once

#include <gtest/gtest.h>

#include <memory>

#include "particles/system.h"

// STEP_OK(system, h, integrator): one step that must succeed, with the
// fault's message in the failure.
#define STEP_OK(sys, h, in)                       \
  do {                                            \
    ::sylva::Status st_ = (sys).Step((h), (in));  \
    ASSERT_TRUE(st_.ok()) << st_.error().message; \
  } while (0)

namespace sylva::particles::testing {

// An immovable anchor at the origin (particle 0) and a unit mass at x0 on
// the x axis (particle 1), joined by an undamped spring.
inline void AddAnchoredSpring(System& s, double x0, double rest, double ks) {
  s.state.Add(Vec3::Zero(), Vec3::Zero(), 0);
  s.state.Add(Vec3(x0, 0, 0), Vec3::Zero(), 1);
  auto springs = std::make_shared<Springs>();
  springs->Add(1, 0, rest, ks, 0.0);
  s.AddForce(springs);
}

}  // namespace sylva::particles::testing
