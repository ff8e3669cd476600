// The display transform as the budget's model and its confirming measure take it
// (frame_budget.cpp): the sRGB curve through a table, and the 8-bit code a display shows for a
// linear colour value. Private, for those files and their tests.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace conus::codec::detail {

// The display curve D through a table, linear between its entries (continuous, and some 20x
// faster than pow): displayTable()[i] = D(i / kDisplayTableSteps), one entry more at the end.
inline constexpr int kDisplayTableSteps = 4096;
const std::vector<float>& displayTable();

// A value as the model weighs it: through the table where `display`, else as it is; a NaN or
// infinite one (a picture kept as read, which filtering spreads) as 0, so that it neither indexes
// the table nor turns a tile's error into NaN.
inline float shown(float v, bool display, const std::vector<float>& table) {
    if (!std::isfinite(v)) return 0.0f;
    if (!display) return v;
    const float x = std::clamp(v, 0.0f, 1.0f) * kDisplayTableSteps;
    const int i = static_cast<int>(x);
    const float f = x - float(i);
    return table[i] + f * (table[i + 1] - table[i]);
}

// The code of a colour value: shown() through the table, then the nearest code; NaN,
// infinities and values up to 0 give 0, 1 and above 255.
std::uint8_t displayCode(float v);
// out[i] = displayCode(in[i]) for i < n. `vectors`: the AVX2 copy where the processor has one
// (the same codes as the scalar form, which false forces).
void displayCodes(const float* in, std::uint8_t* out, std::size_t n, bool vectors = true);

}  // namespace conus::codec::detail
