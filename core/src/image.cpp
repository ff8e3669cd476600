// The plain float image: channel lookup and checked allocation.
#include <algorithm>
#include <string>

#include "conus/core/error.h"
#include "conus/core/image.h"

namespace conus {

int Image::channelIndex(const std::string& name) const {
    for (std::size_t c = 0; c < channels.size(); ++c) {
        if (channels[c] == name) return static_cast<int>(c);
    }
    return -1;
}

Image makeImage(int width, int height, std::vector<std::string> channels) {
    if (width < 1 || height < 1 || channels.empty()) {
        throw Error(ErrorCode::InvalidArgument,
                    "makeImage: need width, height and channel count >= 1, got " + std::to_string(width) +
                        "x" + std::to_string(height) + " with " + std::to_string(channels.size()) +
                        " channels");
    }
    // Sizes in 64-bit before allocating, so absurd requests fail cleanly instead of overflowing.
    const std::int64_t pixels = std::int64_t{width} * height;
    if (width > kMaxImageSide || height > kMaxImageSide || pixels > kMaxImagePixels) {
        throw Error(ErrorCode::LimitExceeded, "makeImage: " + std::to_string(width) + "x" +
                                                  std::to_string(height) + " exceeds the limit of " +
                                                  std::to_string(kMaxImageSide) + " a side, " +
                                                  std::to_string(kMaxImagePixels) + " pixels");
    }
    Image image;
    image.width = width;
    image.height = height;
    image.channels = std::move(channels);
    image.pixels.assign(static_cast<std::size_t>(pixels) * image.channels.size(), 0.0f);
    return image;
}

void checkImage(const Image& image, const char* what) {
    if (image.empty())
        throw Error(ErrorCode::InvalidArgument, std::string(what) + ": empty image (" + std::to_string(image.width) +
                                                    "x" + std::to_string(image.height) + ", " +
                                                    std::to_string(image.channelCount()) + " channels)");
    const std::size_t expected = static_cast<std::size_t>(image.width) * image.height * image.channels.size();
    if (image.pixels.size() != expected)
        throw Error(ErrorCode::InvalidArgument, std::string(what) + ": image holds " +
                                                    std::to_string(image.pixels.size()) + " values, expected " +
                                                    std::to_string(expected));
}

std::vector<std::string> displayOrder(const std::vector<std::string>& channels) {
    std::vector<std::string> out;
    for (const char* name : {"R", "G", "B", "Y", "A", "Z"})
        if (std::find(channels.begin(), channels.end(), name) != channels.end()) out.push_back(name);
    for (const std::string& c : channels)
        if (std::find(out.begin(), out.end(), c) == out.end()) out.push_back(c);
    return out;
}

}  // namespace conus
