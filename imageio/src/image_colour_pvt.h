// Private to the OpenImageIO module: colour by channel role, shared by reading and writing (which
// channels are colour and which alpha, sRGB <-> linear and (un)premultiplying through OpenImageIO).
#pragma once

#include <string>
#include <vector>

#include "conus/core/image.h"

namespace conus::imageio::oiio {

// The colour channels of an image in display order: R,G,B when all three are there, else Y, else
// (an image of other names) its first channel for a grey picture; A separately.
struct ChannelRoles {
    std::vector<int> colour;
    int alpha = -1;
};

// The roles of `image`'s channels.
ChannelRoles rolesOf(const Image& image);

// Converts the channels `colour` of an interleaved float buffer between OpenImageIO colour spaces
// ("sRGB", "linear"). OpenImageIO converts the first channels of a buffer (its colorconvert does
// not honour a channel range that starts past 0), so colour channels that do not lead the pixel
// are gathered into a buffer of their own first.
void convertColour(float* pixels, int width, int height, int channels, const std::vector<int>& colour,
                   const char* from, const char* to, const std::string& path);

// Multiplies (or divides) the colour channels by alpha, through OpenImageIO.
void premultiply(float* pixels, int width, int height, int channels, int alpha, bool associate);

}  // namespace conus::imageio::oiio
