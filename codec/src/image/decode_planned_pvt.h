// Private: the pyramid decode's planned pass for 3 and 4 channels, a block of a span at a time:
// the first pass plans every pixel's taps (level, offsets, weights) in vector lanes and touches no
// image; the second only loads and blends, with many pixels' loads in flight. The pass is built
// twice from one source (decode_planned.cpp): the baseline copy and an AVX2 copy, chosen once at
// run time; both give the scalar trilinear tap's floats (pyramid_pvt.h).
#pragma once

#include <cstdint>

#include "pyramid_pvt.h"

namespace conus::codec::detail {

constexpr int kPlanBlock = 64;  // pixels planned at once (a multiple of 4)

struct TapPlan {
    alignas(32) std::int32_t offset[kPlanBlock];  // the top-left pixel, floats from the level's first
    alignas(32) std::int32_t dx[kPlanBlock];      // to its right neighbour: channels, 0 at the edge
    alignas(32) std::int32_t dy[kPlanBlock];      // to the one below: a row, 0 at the edge
    alignas(32) float fx[kPlanBlock];
    alignas(32) float fy[kPlanBlock];
};
struct PixelPlan {
    TapPlan taps[2];                           // on levels `level` and `level` + 1
    alignas(32) std::int32_t level[kPlanBlock];
    alignas(32) float blend[kPlanBlock];  // trilinearTap's f: 0 takes the first tap alone
    // Where the taps on level `uniform` will be kPrefetchRows output rows further down (prefetched).
    alignas(32) std::int32_t ahead[kPlanBlock];
    // The common block: every pixel on one level pair, every 2x2 neighbourhood inside both levels
    // and above their last row: the level (taps hold offset, fx, fy only); else -1.
    int uniform = -1;
    bool oneTap = false;  // with `uniform`: every blend is 0 (or the level is the top), one tap each
};


// Whether the levels' offsets fit the plan's 32-bit integers.
bool plannable(const Level& level0, int channels);

// Decodes pixels k0 .. k0 + count - 1 (count <= kPlanBlock) of a span into out, `top` the top
// level's index; `plan` is scratch.
using BlockFn = void (*)(const Level*, int top, const SpanInputs&, int k0, int count, PixelPlan& plan, float* out);

// The copy this processor runs (the baseline one where forceBaselineDecode asks), for kC = 3, 4.
template <int kC>
BlockFn chooseBlockFn();

}  // namespace conus::codec::detail
