#include "app/graphics.h"

#include "app/commands.h"
#include "app/viewer.h"

namespace sylva::app {

const GraphicsCommands& LinkedGraphics() {
  static const GraphicsCommands commands = [] {
    GraphicsCommands c;
    c.render = &RunRender;
    c.meshForView = &RunMeshForView;
    c.simulate = &RunSimulateWithFrames;
#ifdef SYLVA_WITH_VIEWER
    c.view = &RunView;
#endif
    return c;
  }();
  return commands;
}

}  // namespace sylva::app
