// The 8-bit code a display shows for a linear colour value, as the budget's confirming measure
// (frame_budget.cpp) takes it over the source's size: private, for that file and its tests.
#pragma once

#include <cstddef>
#include <cstdint>

namespace conus::codec::detail {

// out[i] = the code of in[i] (the display curve through its table, then the nearest code; NaN,
// infinities and values up to 0 give 0, 1 and above 255), for i < n. `vectors`: the AVX2 copy
// where the processor has one (the same codes as the scalar form, which false forces).
void displayCodes(const float* in, std::uint8_t* out, std::size_t n, bool vectors = true);

}  // namespace conus::codec::detail
