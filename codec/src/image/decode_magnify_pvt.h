// Private: magnified spans, the decode's common case (one bilinear tap a pixel). Inside a span
// the position advances by a constant step; where no tap can leave the image it is stepped in
// 32.32 fixed point (the integer part and the weight come out of one add and two shifts), four
// pixels at a time in vector lanes where the image's offsets fit 16-bit multiply-adds, so a
// magnified pixel costs about the bilinear baseline's one tap with its precomputed weights.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "decode_reference_pvt.h"
#include "resample_pvt.h"

namespace conus::codec::detail {

// Fixed point 32.32 for the stepped coordinates of interior spans: the integer part and the
// weight come out of one add and two shifts instead of float-int round trips.
constexpr double kFixedOne = 4294967296.0;

// x in 32.32 fixed point, rounded half away from zero like std::llround (inline: a span's set-up
// called llround four times); |x| is far below 2^31 here, so x * 2^32 + 0.5 is exact.
inline std::int64_t toFixed(double x) {
    const double scaled = x * kFixedOne;
    return static_cast<std::int64_t>(scaled < 0.0 ? scaled - 0.5 : scaled + 0.5);
}

// A span's first biased position and its step per pixel, in 32.32 fixed point.
struct FixedSteps {
    std::int64_t x, y, sx, sy;
};

// bilinearLanes for a pixel whose 2x2 neighbourhood starts at p0 and whose 4-float reads all lie
// inside the array: the same loads and operations without the check for the last pixel.
template <int kC>
[[gnu::always_inline]] inline PixelLanes interiorTapAt(const float* p0, std::size_t stride, float fx,
                                                               float fy) {
    const PixelLanes top = lerpLanes(loadLanes(p0), loadLanes(p0 + kC), fx);
    const PixelLanes bottom =
        lerpLanes(loadLanes(p0 + stride), loadLanes(p0 + stride + kC), fx);
    return lerpLanes(top, bottom, fy);
}

// The weight of a 32.32 fixed-point coordinate: the top 24 bits of its fraction (exact in a
// float, and the same in the scalar and the vector code below).
inline float fixedWeight(std::int64_t x) {
    return static_cast<float>(static_cast<std::int32_t>((x & 0xffffffff) >> 8)) * 0x1p-24f;
}

// Whether magnifyInteriorLanes can take a width x height image of `channels` channels: its
// coordinates and row stride (in floats) below 2^15, so that the offsets come out of 16-bit
// multiply-adds (images wider than 8191 pixels of 4 channels take magnifyInterior).
inline bool lanesFit(int width, int height, int channels) {
    return std::int64_t{width} * channels < 32767 && height < 32766;
}

// A magnified span whose 4-float reads all lie inside the array (3 or 4 channels, the taps' 2x2
// neighbourhoods inside the image and, with 3 channels, above its last row): one bilinear tap a
// pixel. The positions, weights and offsets of four pixels at a time come out of vector lanes
// (two 32.32 coordinates a register, stepped exactly as the scalar loop steps them), so a pixel
// costs little more than the baseline's tap with its precomputed per-axis weights; every pixel but
// the span's last stores four lanes (the next pixel overwrites the fourth).
template <int kC>
[[gnu::always_inline]] inline void magnifyInteriorLanes(const float* pixels, std::size_t stride, FixedSteps p,
                                                        int count, float* out) {
    static_assert(kLanes<kC>);
    typedef std::int64_t Fixed2 __attribute__((vector_size(16)));
    typedef std::int32_t Int4 __attribute__((vector_size(16)));
    typedef std::uint32_t Uint4 __attribute__((vector_size(16)));
    typedef float Float4 __attribute__((vector_size(16)));
    // Biased coordinates: the 2x2 neighbourhood of (xi, yi) starts at pixel (xi - 1, yi - 1). The
    // caller checks lanesFit: xi, yi and the row stride fit 16 bits, the offsets 32.
    static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "the plan takes a coordinate's fraction from its low word");
    const std::int32_t rowStride = static_cast<std::int32_t>(stride);
    Fixed2 x01 = {p.x, p.x + p.sx}, x23 = {p.x + 2 * p.sx, p.x + 3 * p.sx};
    Fixed2 y01 = {p.y, p.y + p.sy}, y23 = {p.y + 2 * p.sy, p.y + 3 * p.sy};
    const std::int64_t sx4 = 4 * p.sx, sy4 = 4 * p.sy;
    Float4 fx, fy;
    Int4 offset;
#if defined(__SSE2__)
    const __m128i weights16 = _mm_set1_epi32(rowStride | kC << 16);
#endif
    // The next four pixels' weights and offsets (little-endian words of the coordinates: the
    // fractions, then the integer parts).
    const auto plan = [&] {
        const Uint4 xw0 = reinterpret_cast<Uint4>(x01), xw1 = reinterpret_cast<Uint4>(x23);
        const Uint4 yw0 = reinterpret_cast<Uint4>(y01), yw1 = reinterpret_cast<Uint4>(y23);
        const Uint4 xFraction = __builtin_shufflevector(xw0, xw1, 0, 2, 4, 6);
        const Uint4 yFraction = __builtin_shufflevector(yw0, yw1, 0, 2, 4, 6);
        const Int4 xi = reinterpret_cast<Int4>(__builtin_shufflevector(xw0, xw1, 1, 3, 5, 7)) - 1;
        const Int4 yi = reinterpret_cast<Int4>(__builtin_shufflevector(yw0, yw1, 1, 3, 5, 7)) - 1;
        fx = __builtin_convertvector(reinterpret_cast<Int4>(xFraction >> 8), Float4) * 0x1p-24f;
        fy = __builtin_convertvector(reinterpret_cast<Int4>(yFraction >> 8), Float4) * 0x1p-24f;
#if defined(__SSE2__)
        // yi * rowStride + xi * kC (the neighbourhood's first pixel) in one multiply-add of 16-bit halves.
        offset = reinterpret_cast<Int4>(_mm_madd_epi16(reinterpret_cast<__m128i>(yi | (xi << 16)), weights16));
#else
        offset = yi * rowStride + xi * kC;
#endif
        x01 += sx4;
        x23 += sx4;
        y01 += sy4;
        y23 += sy4;
    };
    const auto tap = [&](int j) { return interiorTapAt<kC>(pixels + offset[j], stride, fx[j], fy[j]); };
    int k = 0;
    plan();
    // Groups without the span's last pixel: four-lane stores. The next group is planned before
    // this one's taps, so that its chain of shuffles and multiplies overlaps them.
    for (; k + 4 < count; k += 4) {
        const Float4 gx = fx, gy = fy;
        const Int4 go = offset;
        plan();
        float* o = out + static_cast<std::size_t>(k) * kC;
        for (int j = 0; j < 4; ++j) {
            const PixelLanes v = interiorTapAt<kC>(pixels + go[j], stride, gx[j], gy[j]);
            std::memcpy(o + j * kC, &v, sizeof v);
        }
    }
    // The last one to four pixels, the span's last stored exactly.
    for (int j = 0; k + j < count; ++j) {
        storeLanesInRun<kC>(out + static_cast<std::size_t>(k + j) * kC, tap(j), k + j + 1 < count);
    }
}

// A magnified span whose taps are all inside the image, one pixel at a time (the channels in
// lanes, with the check for the last pixel, or one by one): what magnifyInteriorLanes does
// where it cannot.
template <int kC>
[[gnu::always_inline]] inline void magnifyInterior(const float* pixels, std::size_t stride, int c, const float* last,
                                                   FixedSteps p, int count, float* out) {
    const int channels = kC > 0 ? kC : c;
    const std::ptrdiff_t rowStride = static_cast<std::ptrdiff_t>(stride);
    for (int k = 0; k < count; ++k, p.x += p.sx, p.y += p.sy, out += channels) {
        const float fx = fixedWeight(p.x), fy = fixedWeight(p.y);
        const float* p0 = pixels + ((p.y >> 32) - 1) * rowStride + ((p.x >> 32) - 1) * channels;
        if constexpr (kLanes<kC>) {
            storeLanes<kC>(out, bilinearLanes<kC>(p0, p0 + stride, 0, kC, fx, fy, last));
        } else {
            const float* p1 = p0 + stride;
            for (int j = 0; j < channels; ++j) {
                const float top = p0[j] + fx * (p0[channels + j] - p0[j]);
                const float bottom = p1[j] + fx * (p1[channels + j] - p1[j]);
                out[j] = top + fy * (bottom - top);
            }
        }
    }
}

// A magnified span of `count` pixels from biased position (px, py), step (sx, sy) per pixel:
// stepped in fixed point where every tap's neighbourhood is inside the image (in lanes where
// `lanes`: lanesFit holds), else one clamped tap a pixel.
template <int kC>
[[gnu::always_inline]] inline void magnifySpan(const float* pixels, int width, int height, int channels,
                                               std::size_t stride, const float* last, bool lanes, double px, double py,
                                               double sx, double sy, int count, float* out) {
    const int Wc = width, Hc = height;
    const double pxEnd = px + (count - 1) * sx, pyEnd = py + (count - 1) * sy;
    const double ylo = std::min(py, pyEnd), yhi = std::max(py, pyEnd);
    if (interior(std::min(px, pxEnd), std::max(px, pxEnd), ylo, yhi, Wc, Hc)) {
        const FixedSteps steps{toFixed(px), toFixed(py), toFixed(sx), toFixed(sy)};
        // Above the last row, no 4-float read of a 3-channel pixel passes the array's end.
        if constexpr (kLanes<kC>) {
            if (lanes && (kC == 4 || yhi < Hc - 1 - kInteriorMargin)) {
                magnifyInteriorLanes<kC>(pixels, stride, steps, count, out);
                return;
            }
        }
        magnifyInterior<kC>(pixels, stride, channels, last, steps, count, out);
    } else {
        for (int k = 0; k < count; ++k, px += sx, py += sy, out += channels)
            tapBiased<kC, true, false>(pixels, Wc, Hc, channels, px, py, 1.0f, out);
    }
}

}  // namespace conus::codec::detail
