// The conus-view window: GLFW (GL 4.5 core through GLX), the renderers' ViewRenderer on the
// window's adopted context, tev-style navigation (view_state.h), keys (actions.h), the pixel
// inspector in the title, several files, reload, the map editor (--edit), --script and
// --benchmark-frames.
#pragma once

#include "options.h"

namespace conus::viewer {

// Runs until the window closes, the script ends or the benchmark is done. Returns the exit
// status: 0; 1 when a file could not be opened (the window still runs, showing the error) or the
// window could not be created; 2 for a bad script.
int runWindow(const Options& options);

}  // namespace conus::viewer
