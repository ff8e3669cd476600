// Image quality measures used by tests, benchmarks and `conus demo`.
#pragma once

#include "conus/core/image.h"

namespace conus::codec {

// Mean squared error over the channels both images share by name (alpha and Z excluded unless
// they are the only ones); throws conus::Error(InvalidArgument) on different sizes.
double meanSquaredError(const Image& a, const Image& b);
// PSNR in dB for values whose peak is `peak` (1 for normalized images); +inf when identical.
double psnr(const Image& a, const Image& b, double peak = 1.0);

}  // namespace conus::codec
