#include <iostream>
#include <string>
#include <vector>

#include "app/cli.h"
#include "core/atomic_file.h"

int main(int argc, char** argv) {
  std::ios::sync_with_stdio(false);
  // Ctrl-C or a kill while writing leaves no temporary files behind.
  sylva::InstallTemporaryFileCleanup();
  std::vector<std::string> args(argv + 1, argv + argc);
  // render and view run in sylva-graphics, so this binary loads no GL.
  sylva::app::GraphicsCommands exec;
#ifdef SYLVA_HAS_GRAPHICS
  exec.execGraphicsBinary = true;
#endif
  return sylva::app::RunCli(args, std::cout, std::cerr, &exec);
}
