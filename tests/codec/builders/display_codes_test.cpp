// The 8-bit codes a display shows, as the budget's confirming measure takes them
// (codec/src/builders/display_codes.cpp): the AVX2 copy against the scalar form and the sRGB curve.
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "../../../codec/src/builders/display_codes_pvt.h"

#include "conus/core/display.h"

namespace conus::codec {
namespace {

// The measure's codes, eight at a time (AVX2, where the processor has it) and one at a time: the
// same code for every float of a sweep over the bit patterns (every 4099th, and each of the
// 2^23 between 0 and 1 that a photograph's values take most, every 7th), for NaN, infinities and
// negatives; and, off the table's knots and rounding edges, the code of the sRGB curve by pow.
TEST(DisplayCodes, EightAtATimeAreTheScalarOnes) {
    std::vector<float> values = {0.0f, -0.0f, 1.0f, 0.5f, 1e-30f, 2.0f, -1.0f, std::numeric_limits<float>::infinity(),
                                 -std::numeric_limits<float>::infinity(), std::numeric_limits<float>::quiet_NaN()};
    for (std::uint64_t bits = 0; bits <= 0xffffffffull; bits += 4099) values.push_back(std::bit_cast<float>(std::uint32_t(bits)));
    for (std::uint32_t bits = std::bit_cast<std::uint32_t>(0.001f); bits < std::bit_cast<std::uint32_t>(1.0f); bits += 7)
        values.push_back(std::bit_cast<float>(bits));
    values.push_back(0.25f);  // an odd count: the tail after the last eight
    std::vector<std::uint8_t> fast(values.size()), scalar(values.size());
    detail::displayCodes(values.data(), fast.data(), values.size());
    detail::displayCodes(values.data(), scalar.data(), values.size(), false);
    std::size_t differ = 0, offCurve = 0;
    for (std::size_t i = 0; i < values.size(); ++i) {
        differ += fast[i] != scalar[i];
        const float v = values[i];
        const double exact = v > 0 && v < 1 ? 255.0 * linearToSrgbDisplay(v) : v >= 1 && std::isfinite(v) ? 255.0 : 0.0;
        if (std::abs(exact - std::floor(exact) - 0.5) > 0.05) offCurve += std::abs(int(scalar[i]) - std::lround(exact)) > 0;
    }
    EXPECT_EQ(differ, 0u);
    EXPECT_EQ(offCurve, 0u);
    EXPECT_EQ(scalar[0], 0);
    EXPECT_EQ(scalar[2], 255);
    EXPECT_EQ(scalar[3], 188);  // 0.5 linear: sRGB 0.7354
    EXPECT_EQ(scalar[5], 255);
    for (std::size_t i : {6, 7, 8, 9}) EXPECT_EQ(scalar[i], 0) << values[i];
}

}  // namespace
}  // namespace conus::codec
