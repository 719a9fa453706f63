// STEP_OK(system, h, integrator): one step that must succeed, with the
// fault's message in the failure.
#pragma once

#include <gtest/gtest.h>

#define STEP_OK(sys, h, in)                         \
  do {                                              \
    ::sylva::Status st_ = (sys).Step((h), (in));    \
    ASSERT_TRUE(st_.ok()) << st_.error().message;   \
  } while (0)
