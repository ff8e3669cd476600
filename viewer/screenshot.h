// --screenshot: the first file drawn offscreen on the renderers' own headless context (EGL, then
// OSMesa) into a framebuffer object, written as PNG. No window and no display are needed.
#pragma once

#include "options.h"

namespace conus::viewer {

// Returns the process exit status: 0, or 1 with the reason on stderr.
int runScreenshot(const Options& options);

}  // namespace conus::viewer
