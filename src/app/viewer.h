// `sylva view`: the interactive viewer (GLFW window + Dear ImGui).
//
// A scene file (.xml) is played (viewer_scene.cpp): its camera is the
// initial view, a panel has play, pause, step, reset, a time slider, the
// counts and the frame time, and the scene reloads when it, an included file
// or a grammar it names changes. Otherwise the file is a grammar: the
// viewer reloads it when the file changes; a bad edit lists its
// diagnostics in a panel and keeps the last good plant on screen. Sliders
// set every #define, the seed, the derivation step and the detail; changes
// are derived on a worker thread, so the window never freezes. With
// screen-space detail (the default) the worker keeps the plant and
// re-tessellates it for the camera once the camera has moved far enough,
// while the window keeps drawing the previous mesh. In both,
// left drag orbits, right drag pans, wheel zooms; P saves a screenshot.
#pragma once

#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

namespace sylva::app {

struct ViewCommand {
  std::string file;        // empty: the bundled default grammar
  std::string screenshot;  // with frames > 0: save this PNG after `frames` frames and quit
  int frames = 0;
  std::string size = "1280x720";
  bool strict = false;  // --strict: a plant with warnings is not shown (they are errors)
  std::vector<std::string> defines;  // -D NAME=VALUE: a grammar's #defines, a scene's <default>s
  int threads = 0;                   // --threads: derivation, build and simulation (0: all cores)
  // Grammars (.lsys) only: the step and seed the viewer starts at.
  std::optional<int> steps;
  std::optional<uint64_t> seed;
  std::string view;  // --view: a cpfg view file (default: NAME.v beside the grammar)
  // --orbit: degrees of azimuth the camera turns each frame (tests, demos);
  // with --frames, the frame and re-tessellation figures go to stdout.
  double orbit = 0;
  // Scenes (.xml) only:
  std::optional<double> time;  // --time: start paused at this time (seconds)
};

int RunView(const ViewCommand& cmd, std::ostream& out, std::ostream& err);
// The scene mode, once RunView has checked the flags and the file.
int RunViewScene(const ViewCommand& cmd, int width, int height, std::ostream& out,
                 std::ostream& err);

}  // namespace sylva::app
