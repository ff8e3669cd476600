// A plain float image: the in-memory form of every pixel array in CoNUS (sources, CoNUS images,
// decoded frames). Interleaved channels, row-major, top row first, matching the image-plane
// convention of spec/ (v grows downward).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "conus/core/limits.h"

namespace conus {

struct Image {
    int width = 0;
    int height = 0;
    std::vector<std::string> channels;  // e.g. {"R","G","B","A"}, {"Y"}, {"R","G","B","Z"}
    std::vector<float> pixels;          // width * height * channels.size() values

    int channelCount() const { return static_cast<int>(channels.size()); }
    bool empty() const { return width <= 0 || height <= 0 || channels.empty(); }
    std::size_t index(int x, int y, int c = 0) const {
        return (static_cast<std::size_t>(y) * width + x) * channels.size() + c;
    }
    float& at(int x, int y, int c = 0) { return pixels[index(x, y, c)]; }
    float at(int x, int y, int c = 0) const { return pixels[index(x, y, c)]; }
    // Index of a channel by name, or -1.
    int channelIndex(const std::string& name) const;
};

// Channel names in the order people read them: R, G, B, Y, A, Z, then the rest as given (OpenEXR
// stores them sorted: B, G, R).
std::vector<std::string> displayOrder(const std::vector<std::string>& channels);

// A zero-filled image; throws conus::Error(InvalidArgument / LimitExceeded) on absurd sizes.
Image makeImage(int width, int height, std::vector<std::string> channels);

// Throws conus::Error(InvalidArgument), naming `what`, for an empty image or one whose pixel array
// does not hold width * height * channels values: the check every consumer of an Image starts with.
void checkImage(const Image& image, const char* what);

}  // namespace conus
