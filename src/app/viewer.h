// `sylva view`: the interactive viewer (GLFW window + Dear ImGui).
//
// It reloads the grammar when the file changes; a bad edit lists its
// diagnostics in a panel and keeps the last good plant on screen. Sliders
// set every #define, the seed, the derivation step and the detail; changes
// are derived on a worker thread, so the window never freezes. Mouse: left
// drag orbits, right drag pans, wheel zooms; P saves a screenshot.
#pragma once

#include <iosfwd>
#include <string>

namespace sylva::app {

struct ViewCommand {
  std::string file;        // empty: the bundled default grammar
  std::string screenshot;  // with frames > 0: save this PNG after `frames` frames and quit
  int frames = 0;
  std::string size = "1280x720";
  bool strict = false;  // --strict: a plant with warnings is not shown (they are errors)
};

int RunView(const ViewCommand& cmd, std::ostream& out, std::ostream& err);

}  // namespace sylva::app
