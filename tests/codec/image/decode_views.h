// The decode options the image tests ask for: a view decoded to w x h, through a pyramid or not,
// on a given number of threads (0: all).
#pragma once

#include "conus/codec/image/decode.h"

namespace conus::test {

inline codec::DecodeOptions viewOf(codec::View view, int w, int h, const codec::ImagePyramid* pyramid = nullptr,
                                   int threads = 0) {
    codec::DecodeOptions o;
    o.view = view;
    o.width = w;
    o.height = h;
    o.pyramid = pyramid;
    o.threads = threads;
    return o;
}

}  // namespace conus::test
