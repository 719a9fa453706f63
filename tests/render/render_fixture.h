// A current headless OpenGL context and a Renderer with the source tree's
// shaders, for the render tests.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "render/headless_context.h"
#include "render/renderer.h"

namespace sylva::render::testing {

class RenderFixture : public ::testing::Test {
 protected:
  void SetUp() override {
    auto c = HeadlessContext::Create();
    ASSERT_TRUE(c.ok()) << c.error().Format();
    context_ = std::move(*c);
    auto r = Renderer::Create(std::string(SYLVA_SOURCE_DIR) + "/shaders");
    ASSERT_TRUE(r.ok()) << r.error().Format();
    renderer_ = std::move(*r);
  }
  std::unique_ptr<HeadlessContext> context_;
  std::unique_ptr<Renderer> renderer_;
};

}  // namespace sylva::render::testing
