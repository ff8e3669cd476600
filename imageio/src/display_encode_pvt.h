// Private: linear light to sRGB-encoded display values without OpenImageIO, for pictures without
// alpha (photographs): what displayEncoded computes for them, at the price of a table look-up a
// value. (With alpha, displayEncoded divides it out through OpenImageIO's module first.)
#pragma once

#include "conus/core/image.h"

namespace conus::imageio {

// The sRGB encoding (IEC 61966-2-1) of a linear value, clamped to [0, 1]; a non-finite value is 0.
// Through a table over the float's upper bits, interpolated: within 1e-6 of the exact curve.
float linearToSrgbClamped(float linear);

// displayEncoded (image_file.h) of an image without an "A" channel: non-finite values 0, the
// colour channels (R,G,B, else Y, else the first) encoded to sRGB and clamped to [0, 1].
Image displayEncodedOpaque(const Image& image);

}  // namespace conus::imageio
