// sylva-graphics: the `sylva` command with render and view, which load
// OpenGL, EGL and GLFW. `sylva` execs it for those commands, so the other
// commands never load the graphics stack.
#include <iostream>
#include <string>
#include <vector>

#include "app/graphics.h"
#include "core/atomic_file.h"

int main(int argc, char** argv) {
  std::ios::sync_with_stdio(false);
  sylva::InstallTemporaryFileCleanup();
  std::vector<std::string> args(argv + 1, argv + argc);
  return sylva::app::RunCliWithGraphics(args, std::cout, std::cerr);
}
