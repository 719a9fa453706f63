// The `sylva` command with its drawing commands (render, view) linked in:
// what `sylva-graphics` runs, and what tests that draw call in-process.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "app/cli.h"

namespace sylva::app {

// The runners this build has (view is null without the viewer).
const GraphicsCommands& LinkedGraphics();

inline int RunCliWithGraphics(const std::vector<std::string>& args, std::ostream& out,
                              std::ostream& err) {
  return RunCli(args, out, err, &LinkedGraphics());
}

}  // namespace sylva::app
