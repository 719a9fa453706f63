// The `sylva` command, callable in-process (main.cpp and the tests).
//
// Exit status: 0 success; 1 a run-time failure (a limit reached, an I/O
// error); 2 bad usage or bad input, with GCC-style diagnostics on `err`.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

namespace sylva::app {

inline constexpr int kExitOk = 0;
inline constexpr int kExitRuntime = 1;
inline constexpr int kExitBadInput = 2;

struct RenderCommand;
struct ViewCommand;
struct MeshCommand;
struct SimulateCommand;

// The commands that draw (render, view) need OpenGL, EGL, X11 and GLFW.
// The `sylva` executable links none of them, so `sylva derive` starts as
// fast as a program can: for a command that draws it replaces itself
// (exec) with `sylva-graphics`, found beside it (or in
// ../libexec/sylva/ when installed), which links everything and passes
// these runners. Tests that draw call RunCliWithGraphics (graphics.h).
struct GraphicsCommands {
  int (*render)(const RenderCommand&, std::ostream& out, std::ostream& err) = nullptr;
  int (*view)(const ViewCommand&, std::ostream& out, std::ostream& err) = nullptr;
  // `sylva mesh --lod-eps`: the view is framed by the renderer's camera.
  int (*meshForView)(const MeshCommand&, std::ostream& out, std::ostream& err) = nullptr;
  int (*simulate)(const SimulateCommand&, std::ostream& out, std::ostream& err) = nullptr;
  // Only the `sylva` executable sets this: render, view, simulate with frames and mesh --lod-eps
  // exec `sylva-graphics` with the same arguments (never in a test process).
  bool execGraphicsBinary = false;
};

// `graphics` null or without a runner: render and view are an error saying
// this build lacks them.
int RunCli(const std::vector<std::string>& args, std::ostream& out, std::ostream& err,
           const GraphicsCommands* graphics = nullptr);

}  // namespace sylva::app
