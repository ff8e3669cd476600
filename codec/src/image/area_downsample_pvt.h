// The area average (box filter with exact overlap weights) over a pixel array: the baseline
// areaDownsample and the encoder's pyramid levels.
#pragma once

namespace conus::codec::detail {

// A pixel array without its channel names.
struct Plane {
    const float* data = nullptr;
    int width = 0, height = 0;
};

// `src` (interleaved, `channels` a pixel) averaged over each of width x height output pixels'
// areas into `dst`, on `threads` threads.
void areaDownsamplePlane(Plane src, float* dst, int width, int height, int channels, int threads);

}  // namespace conus::codec::detail
