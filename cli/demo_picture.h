// The demo's built-in input: a 4096x4096 picture with detail that shows what a CoNUS image buys:
// fine print, a zone plate, and face-like figures with hair-fine stripes, on a smooth background.
#pragma once

#include "conus/core/image.h"

namespace conus::cli {

// Square picture `size` pixels a side (RGB, values in [0,1]). The fine print sits around
// (0.28,0.30) and the zone plate around (0.70,0.66), the demo's two foci.
Image makeDemoPicture(int size);

}  // namespace conus::cli
