// Shader programs from the shader folder (internal to src/render).
#pragma once

#include <string>

#include "core/status.h"

namespace sylva::render {

// Compiles and links NAME.vert + NAME.frag from `dir`; an error names the
// file and carries the GLSL compiler's message.
Expected<unsigned> CompileProgram(const std::string& dir, const std::string& name);
// Same, with the vertex shader and fragment shader named separately.
Expected<unsigned> CompileProgram(const std::string& dir, const std::string& vert,
                                  const std::string& frag);

}  // namespace sylva::render
