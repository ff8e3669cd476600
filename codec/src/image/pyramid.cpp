// The CoNUS image's mip chain (pyramid.h): building and checking it, and the level of detail of a
// footprint on it.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "conus/codec/image/encode.h"
#include "conus/core/error.h"
#include "pyramid_pvt.h"

namespace conus::codec {
namespace detail {

std::vector<Level> pyramidLevels(const Image& conus, const ImagePyramid* pyramid) {
    const auto last = [](const Image& im) { return im.pixels.data() + im.pixels.size() - im.channels.size(); };
    std::vector<Level> levels{{conus.pixels.data(), conus.width, conus.height, 1.0f, 1.0f, 0.0f, 0.0f, last(conus)}};
    if (!pyramid) return levels;
    for (const Image& l : pyramid->levels) {
        const double sx = double(l.width) / conus.width, sy = double(l.height) / conus.height;
        levels.push_back({l.pixels.data(), l.width, l.height, float(sx), float(sy), float(0.5 - 0.5 * sx),
                          float(0.5 - 0.5 * sy), last(l)});
    }
    return levels;
}

}  // namespace detail

float pyramidLevel(float rhoSquared) {
    if (!(rhoSquared > 1.0f)) return 0.0f;  // magnified (or NaN): level 0

    std::uint32_t bits;
    std::memcpy(&bits, &rhoSquared, sizeof bits);
    const int exponent = static_cast<int>(bits >> 23) - 127;
    const std::uint32_t mantissaBits = (bits & 0x7fffffu) | 0x3f800000u;
    float mantissa;
    std::memcpy(&mantissa, &mantissaBits, sizeof mantissa);
    const float t = mantissa - 1.0f;  // log2(1 + t) ~ t (1.3465553 - 0.3465553 t), exact at t = 0 and 1
    return std::max(0.0f, 0.5f * (static_cast<float>(exponent) + t * (1.3465553f - 0.3465553f * t)) -
                              static_cast<float>(kDecodePyramidBias));
}

void checkPyramid(const Image& conus, const ImagePyramid& pyramid) {
    int w = conus.width, h = conus.height;
    for (const Image& level : pyramid.levels) {
        w = std::max(1, w / 2);
        h = std::max(1, h / 2);
        if (level.width != w || level.height != h || level.channels != conus.channels ||
            level.pixels.size() != static_cast<std::size_t>(w) * h * conus.channels.size())
            throw Error(ErrorCode::InvalidArgument, "decode: the pyramid was not built from a " +
                                                        std::to_string(conus.width) + "x" +
                                                        std::to_string(conus.height) + " image with these channels");
    }
    if (w != 1 || h != 1)
        throw Error(ErrorCode::InvalidArgument, "decode: the pyramid stops before 1x1");
}

ImagePyramid buildPyramid(const Image& conus, int threads) {
    checkImage(conus, "buildPyramid");
    ImagePyramid pyramid;
    const Image* previous = &conus;
    while (previous->width > 1 || previous->height > 1) {
        pyramid.levels.push_back(
            areaDownsample(*previous, std::max(1, previous->width / 2), std::max(1, previous->height / 2), threads));
        previous = &pyramid.levels.back();
    }
    return pyramid;
}

}  // namespace conus::codec
