// Linear light to display-encoded sRGB without OpenImageIO (display_encode_pvt.h). Between the
// linear segment's end and 1 the curve 1.055 x^(1/2.4) - 0.055 is tabled at every float whose
// lowest 13 mantissa bits are 0 (1024 entries an octave) and interpolated linearly in between:
// a float's mantissa is linear in its value within an octave, and the curve's second derivative
// keeps the interpolation within 1e-7 of it there, where std::pow a value would cost ~20 ns
// (48 million values in a 16-megapixel photograph).
#include "display_encode_pvt.h"

#include <bit>
#include <cmath>
#include <cstdint>
#include <vector>

#include "conus/core/parallel.h"
#include "image_colour_pvt.h"

namespace conus::imageio {
namespace {

constexpr float kLinearEnd = 0.0031308f;  // below it the curve is 12.92 x
constexpr int kDropBits = 13;

double srgbCurve(double x) { return x <= kLinearEnd ? 12.92 * x : 1.055 * std::pow(x, 1.0 / 2.4) - 0.055; }

struct SrgbTable {
    std::uint32_t first = std::bit_cast<std::uint32_t>(kLinearEnd) >> kDropBits;
    std::uint32_t last = std::bit_cast<std::uint32_t>(1.0f) >> kDropBits;
    std::vector<float> value;  // at (first + i) << kDropBits, i = 0 .. last - first
    SrgbTable() {
        value.resize(last - first + 1);
        for (std::uint32_t i = 0; i <= last - first; ++i)
            value[i] = static_cast<float>(srgbCurve(std::bit_cast<float>((first + i) << kDropBits)));
    }
};

const SrgbTable& srgbTable() {
    static const SrgbTable table;
    return table;
}

inline float encode(const SrgbTable& t, float x) {
    if (!(x > kLinearEnd)) return x > 0.0f ? 12.92f * x : 0.0f;  // NaN, negative, the linear part
    if (!(x < 1.0f)) return x == x && x != INFINITY ? 1.0f : 0.0f;
    const std::uint32_t bits = std::bit_cast<std::uint32_t>(x);
    const std::uint32_t i = (bits >> kDropBits) - t.first;
    const float f = static_cast<float>(bits & ((1u << kDropBits) - 1)) * (1.0f / (1u << kDropBits));
    const float a = t.value[i], b = t.value[i + 1];
    return a + f * (b - a);
}

}  // namespace

float linearToSrgbClamped(float linear) { return encode(srgbTable(), linear); }

Image displayEncodedOpaque(const Image& image) {
    checkImage(image, "displayEncoded");
    std::vector<int> colour = oiio::rolesOf(image).colour;
    if (colour.empty()) colour = {0};
    const int channels = image.channelCount();
    std::vector<char> isColour(channels, 0);
    for (int c : colour) isColour[c] = 1;
    const SrgbTable& table = srgbTable();
    // Through makeImage: a large array is faulted in huge pages, on every core (core/image.h).
    Image out = makeImage(image.width, image.height, image.channels);
    const std::size_t row = static_cast<std::size_t>(image.width) * channels;
    parallelRows(image.height, 0, [&](int y0, int y1) {
        for (std::size_t i = y0 * row, end = y1 * row; i < end; i += channels)
            for (int c = 0; c < channels; ++c) {
                const float v = image.pixels[i + c];
                out.pixels[i + c] = isColour[c] ? encode(table, v) : std::isfinite(v) ? v : 0.0f;
            }
    }, 64);
    return out;
}

}  // namespace conus::imageio
