// The area average (box filter with exact overlap weights) over a pixel array: the baseline
// areaDownsample and the encoder's pyramid levels.
#pragma once

#include <functional>

namespace conus::codec::detail {

// A pixel array without its channel names.
struct Plane {
    const float* data = nullptr;
    int width = 0, height = 0;
};

// `src` (interleaved, `channels` a pixel) averaged over each of width x height output pixels'
// areas into `dst`, on `threads` threads.
void areaDownsamplePlane(Plane src, float* dst, int width, int height, int channels, int threads);

// The same of a srcWidth x srcHeight picture whose rows fill(k, row) writes (`channels` values a
// pixel) as they are needed, a few rows more than once, never the whole picture at a time: the
// same values as areaDownsamplePlane of the rows fill writes.
void areaDownsampleRows(int srcWidth, int srcHeight, int channels, const std::function<void(int, float*)>& fill, float* dst,
                        int width, int height, int threads);

}  // namespace conus::codec::detail
