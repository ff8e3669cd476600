// The CPU encoder's sources (encode.h): 8-bit codes and their tables, the memory bound, the levels
// kept across encodes. The encoder itself is encode.cpp, its pyramid encode_pyramid_pvt.h.
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "conus/codec/image/encode.h"
#include "conus/core/error.h"
#include "encode_pyramid_pvt.h"

namespace conus::codec {
namespace {

std::array<float, 256> codeTable(bool srgb) {
    std::array<float, 256> t{};
    const float scale = 1.0f / 255.0f;
    for (int v = 0; v < 256; ++v) {
        const float unit = static_cast<float>(v) * scale;  // as imageio's 8-bit reads take it
        const double e = unit;
        t[v] = !srgb ? unit : static_cast<float>(e <= 0.04045 ? e / 12.92 : std::pow((e + 0.055) / 1.055, 2.4));
    }
    return t;
}

}  // namespace

namespace detail {

void checkCodes(const EightBitImage& codes, const char* what) {
    if (codes.width < 1 || codes.height < 1 || codes.channels.empty() ||
        codes.codes.size() != std::size_t(codes.width) * codes.height * codes.channels.size())
        throw Error(ErrorCode::InvalidArgument, std::string(what) + ": the 8-bit picture is empty or its codes do not fill it");
}

}  // namespace detail

std::int64_t EncodeLevels::bytes() const {
    std::int64_t total = 0;
    for (const Image& level : m_levels) total += static_cast<std::int64_t>(level.pixels.size()) * std::int64_t(sizeof(float));
    return total;
}

void EncodeLevels::clear() {
    m_levels.clear();
    m_source = nullptr;
    m_width = m_height = m_channels = 0;
}

void checkEncodeMemory(const Image& source, int width, int height, std::int64_t maxBytes) {
    const std::int64_t channels = source.channelCount();
    const std::int64_t bytes =
        (std::int64_t{source.width} * source.height + std::int64_t{width} * height) * channels * std::int64_t(sizeof(float));
    if (bytes > maxBytes)
        throw Error(ErrorCode::LimitExceeded, "encoding a " + std::to_string(source.width) + "x" + std::to_string(source.height) +
                                                  " picture to " + std::to_string(width) + "x" + std::to_string(height) +
                                                  " pixels of " + std::to_string(channels) + " channels takes " +
                                                  std::to_string(bytes) + " bytes, beyond the encode memory limit of " +
                                                  std::to_string(maxBytes) + "; give a smaller size");
}

const float* srgbCodeToLinear() {
    static const std::array<float, 256> table = codeTable(true);
    return table.data();
}

const float* codeToUnit() {
    static const std::array<float, 256> table = codeTable(false);
    return table.data();
}

bool isColourChannelName(const std::string& name) { return name == "R" || name == "G" || name == "B" || name == "Y"; }

Image linearImage(const EightBitImage& codes) {
    detail::checkCodes(codes, "linearImage");
    Image image = makeImage(codes.width, codes.height, codes.channels);
    const int ch = codes.channelCount();
    std::vector<const float*> tables;
    for (int c = 0; c < ch; ++c) tables.push_back(isColourChannelName(codes.channels[c]) ? srgbCodeToLinear() : codeToUnit());
    for (std::size_t i = 0; i < codes.codes.size(); ++i) image.pixels[i] = tables[i % ch][codes.codes[i]];
    return image;
}

}  // namespace conus::codec
