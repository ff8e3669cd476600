// A picture file read back with someone else's reader (OpenImageIO): what a user's tool sees.
#pragma once

#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>

#include "conus/core/image.h"

namespace conus::test {

// Every channel of the picture's first subimage as float, channels named "C"; an empty image when
// OpenImageIO cannot open or read it.
inline Image readPictureWithOiio(const std::string& path) {
    auto in = OIIO::ImageInput::open(path);
    if (!in) return {};
    const OIIO::ImageSpec spec = in->spec();
    Image im = makeImage(spec.width, spec.height, std::vector<std::string>(spec.nchannels, "C"));
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, im.pixels.data())) return {};
    return im;
}

}  // namespace conus::test
