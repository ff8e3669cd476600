// Image quality measures used by tests, benchmarks and `conus demo`, and the crop of a source that
// a decoded view is measured against.
#pragma once

#include "conus/core/image.h"

namespace conus::codec {

// Mean squared error over the channels both images share by name (alpha and Z excluded unless
// they are the only ones); throws conus::Error(InvalidArgument) on different sizes.
double meanSquaredError(const Image& a, const Image& b);
// PSNR in dB for values whose peak is `peak` (1 for normalized images); +inf when identical.
double psnr(const Image& a, const Image& b, double peak = 1.0);

// The width x height pixels whose top-left is (x0, y0), every channel: the source under a view whose
// edges fall on pixel edges. Throws conus::Error(InvalidArgument) for a rectangle that is empty or
// not inside the image.
Image crop(const Image& image, int x0, int y0, int width, int height);

}  // namespace conus::codec
