// countNonFinite: needs no OpenImageIO, so it is compiled into conus_imageio and into the module
// (which counts while reading) alike.
#include <cmath>

#include "conus/imageio/image_file.h"

namespace conus::imageio {

std::int64_t countNonFinite(const Image& image) {
    std::int64_t n = 0;
    for (float v : image.pixels) n += !std::isfinite(v);
    return n;
}

}  // namespace conus::imageio
