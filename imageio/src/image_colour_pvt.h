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

// The roles of `image`'s channels (inline: the display encode without OpenImageIO,
// display_encode.cpp, outside the module, takes them too).
inline ChannelRoles rolesOf(const Image& image) {
    ChannelRoles roles;
    const int r = image.channelIndex("R"), g = image.channelIndex("G"), b = image.channelIndex("B");
    const int y = image.channelIndex("Y");
    if (r >= 0 && g >= 0 && b >= 0) roles.colour = {r, g, b};
    else if (y >= 0) roles.colour = {y};
    roles.alpha = image.channelIndex("A");
    return roles;
}

// Converts the channels `colour` of an interleaved float buffer between OpenImageIO colour spaces
// ("sRGB", "linear"). OpenImageIO converts the first channels of a buffer (its colorconvert does
// not honour a channel range that starts past 0), so colour channels that do not lead the pixel
// are gathered into a buffer of their own first.
void convertColour(float* pixels, int width, int height, int channels, const std::vector<int>& colour,
                   const char* from, const char* to, const std::string& path);

// Multiplies (or divides) the colour channels by alpha, through OpenImageIO.
void premultiply(float* pixels, int width, int height, int channels, int alpha, bool associate);

}  // namespace conus::imageio::oiio
