// Image quality measures: MSE over the colour channels two images share, and PSNR from it.
#include "conus/codec/image/metrics.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstddef>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "conus/core/error.h"

namespace conus::codec {
namespace {

int findChannel(const Image& image, const std::string& name) {
    for (int c = 0; c < image.channelCount(); ++c)
        if (image.channels[c] == name) return c;
    return -1;
}

// Pairs of channel indices (in a, in b) to compare. Alpha and depth say nothing about how the
// picture looks, so they count only when nothing else is shared.
std::vector<std::pair<int, int>> sharedChannels(const Image& a, const Image& b) {
    std::vector<std::pair<int, int>> colour, other;
    for (int c = 0; c < a.channelCount(); ++c) {
        const int cb = findChannel(b, a.channels[c]);
        if (cb < 0) continue;
        const bool aux = a.channels[c] == "A" || a.channels[c] == "Z";
        (aux ? other : colour).emplace_back(c, cb);
    }
    return colour.empty() ? other : colour;
}

void checkComparable(const Image& a, const Image& b) {
    if (a.width != b.width || a.height != b.height)
        throw Error(ErrorCode::InvalidArgument, "meanSquaredError: sizes differ (" + std::to_string(a.width) + "x" +
                                                    std::to_string(a.height) + " vs " + std::to_string(b.width) +
                                                    "x" + std::to_string(b.height) + ")");
    for (const Image* im : {&a, &b})
        if (im->pixels.size() != static_cast<std::size_t>(im->width) * im->height * im->channels.size())
            throw Error(ErrorCode::InvalidArgument, "meanSquaredError: pixel array does not match the image size");
}

}  // namespace

double meanSquaredError(const Image& a, const Image& b) {
    checkComparable(a, b);
    const auto pairs = sharedChannels(a, b);
    if (pairs.empty()) throw Error(ErrorCode::InvalidArgument, "meanSquaredError: the images share no channel");
    const std::size_t count = static_cast<std::size_t>(a.width) * a.height;
    if (count == 0) return 0.0;
    const std::size_t ca = a.channels.size(), cb = b.channels.size();
    double sum = 0.0;
    for (std::size_t p = 0; p < count; ++p) {
        const float* pa = a.pixels.data() + p * ca;
        const float* pb = b.pixels.data() + p * cb;
        for (const auto& [ia, ib] : pairs) {
            const double d = static_cast<double>(pa[ia]) - pb[ib];
            sum += d * d;
        }
    }
    return sum / (static_cast<double>(count) * pairs.size());
}

double psnr(const Image& a, const Image& b, double peak) {
    const double mse = meanSquaredError(a, b);
    if (mse == 0.0) return std::numeric_limits<double>::infinity();
    return 10.0 * std::log10(peak * peak / mse);
}

Image crop(const Image& image, int x0, int y0, int width, int height) {
    // In 64 bits so that x0 + width cannot overflow.
    if (width < 1 || height < 1 || x0 < 0 || y0 < 0 || std::int64_t{x0} + width > image.width ||
        std::int64_t{y0} + height > image.height)
        throw Error(ErrorCode::InvalidArgument, "crop " + std::to_string(width) + "x" + std::to_string(height) + " at (" +
                                                    std::to_string(x0) + ", " + std::to_string(y0) + ") is not inside the " +
                                                    std::to_string(image.width) + "x" + std::to_string(image.height) + " image");
    Image out = makeImage(width, height, image.channels);
    const auto rowValues = static_cast<std::ptrdiff_t>(static_cast<std::size_t>(width) * image.channels.size());
    for (int y = 0; y < height; ++y) {
        const auto from = image.pixels.begin() + static_cast<std::ptrdiff_t>(image.index(x0, y0 + y));
        std::copy(from, from + rowValues, out.pixels.begin() + static_cast<std::ptrdiff_t>(out.index(0, y)));
    }
    return out;
}

}  // namespace conus::codec
