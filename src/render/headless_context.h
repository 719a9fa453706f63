// An OpenGL 4.5 core context with no window and no display, through EGL's
// surfaceless platform (Mesa llvmpipe on machines with no GPU). Rendering
// goes to framebuffer objects. Facts found on these machines: GLEW 2.2's
// glewInit() returns GLEW_ERROR_NO_GLX_DISPLAY (4) under EGL although every
// entry point is loaded, so 4 counts as success here and only here.
#pragma once

#include <memory>
#include <string>

#include "core/status.h"

namespace sylva::render {

class HeadlessContext {
 public:
  static Expected<std::unique_ptr<HeadlessContext>> Create();
  ~HeadlessContext();
  HeadlessContext(const HeadlessContext&) = delete;
  HeadlessContext& operator=(const HeadlessContext&) = delete;

  std::string Renderer() const;  // e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"

 private:
  HeadlessContext() = default;
  void* display_ = nullptr;
  void* context_ = nullptr;
};

}  // namespace sylva::render
