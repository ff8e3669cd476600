// Private: the pyramid decode's taps. A zoomed-out pixel takes one trilinear tap: bilinear on
// the two levels around pyramidLevel of its footprint (pyramid.h), blended. Scalar here, the
// pixel's channels in lanes for 3 and 4; the planned pass (decode_planned_pvt.h) does the same
// operations many pixels at a time and gives the same floats.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

#include "conus/codec/image/pyramid.h"
#include "conus/core/check.h"
#include "resample_pvt.h"

namespace conus::codec::detail {

// The levels of a pyramid decode, level 0 first: a biased level-0 coordinate x (see tapBiased)
// is x * sx + ox on a level (pixel edges line up: sx is the level's size over level 0's). Float:
// like the GPU's texture coordinates, 2^-13 pixel or finer on a 4097-pixel side.
struct Level {
    const float* pixels;
    int width, height;
    float sx, sy, ox, oy;
    const float* last;  // the last pixel (bilinearLanes)
};

// Level 0 (the image) and the pyramid's levels, if any.
std::vector<Level> pyramidLevels(const Image& conus, const ImagePyramid* pyramid);

// Bilinear on a level at biased coordinates in [0.5, size + 0.5] (positive: truncation is
// floor), clamped to the edge.
template <int kC>
inline void levelTap(const Level& l, int c, float x, float y, float* out) {
    const int channels = kC > 0 ? kC : c;
    const int xi = static_cast<int>(x), yi = static_cast<int>(y);
    const float fx = x - static_cast<float>(xi), fy = y - static_cast<float>(yi);
    const int o0 = std::max(xi - 1, 0) * channels, o1 = std::min(xi, l.width - 1) * channels;
    const std::size_t stride = static_cast<std::size_t>(l.width) * channels;
    const float* r0 = l.pixels + static_cast<std::size_t>(std::max(yi - 1, 0)) * stride;
    const float* r1 = l.pixels + static_cast<std::size_t>(std::min(yi, l.height - 1)) * stride;
    for (int k = 0; k < channels; ++k) {
        const float top = r0[o0 + k] + fx * (r0[o1 + k] - r0[o0 + k]);
        const float bottom = r1[o0 + k] + fx * (r1[o1 + k] - r1[o0 + k]);
        out[k] = top + fy * (bottom - top);
    }
}

// levelTap with the pixel in lanes.
template <int kC>
inline PixelLanes levelTapLanes(const Level& l, float x, float y) {
    const int xi = static_cast<int>(x), yi = static_cast<int>(y);
    const float fx = x - static_cast<float>(xi), fy = y - static_cast<float>(yi);
    const std::size_t stride = static_cast<std::size_t>(l.width) * kC;
    const float* r0 = l.pixels + static_cast<std::size_t>(std::max(yi - 1, 0)) * stride;
    const float* r1 = l.pixels + static_cast<std::size_t>(std::min(yi, l.height - 1)) * stride;
    return bilinearLanes<kC>(r0, r1, static_cast<std::size_t>(std::max(xi - 1, 0)) * kC,
                                     static_cast<std::size_t>(std::min(xi, l.width - 1)) * kC, fx, fy, l.last);
}

// One trilinear tap at biased level-0 coordinates (x, y) for a footprint whose longer edge
// squared is rho2 CoNUS pixels squared: bilinear on the two levels around pyramidLevel, blended.
// `scratch` holds a pixel's channels.
template <int kC>
inline void trilinearTap(const Level* levels, int top, int c, float x, float y, float rho2, float* out,
                         float* scratch) {
    const int channels = kC > 0 ? kC : c;
    const float lambda = std::min(pyramidLevel(rho2), static_cast<float>(top));
    const int l = static_cast<int>(lambda);
    const float f = lambda - static_cast<float>(l);
    CONUS_DCHECK(l >= 0 && l <= top && (f <= 0.0f || l < top));  // a blend reads level l + 1
    const Level& a = levels[l];
    levelTap<kC>(a, channels, x * a.sx + a.ox, y * a.sy + a.oy, out);
    if (f <= 0.0f) return;
    const Level& b = levels[l + 1];
    levelTap<kC>(b, channels, x * b.sx + b.ox, y * b.sy + b.oy, scratch);
    for (int k = 0; k < channels; ++k) out[k] += f * (scratch[k] - out[k]);
}

// trilinearTap with the pixel in lanes (the same floats).
template <int kC>
inline void trilinearTapLanes(const Level* levels, int top, float x, float y, float rho2, float* out) {
    const float lambda = std::min(pyramidLevel(rho2), static_cast<float>(top));
    const int l = static_cast<int>(lambda);
    const float f = lambda - static_cast<float>(l);
    CONUS_DCHECK(l >= 0 && l <= top && (f <= 0.0f || l < top));  // a blend reads level l + 1
    const Level& a = levels[l];
    PixelLanes value = levelTapLanes<kC>(a, x * a.sx + a.ox, y * a.sy + a.oy);
    if (f > 0.0f) {
        const Level& b = levels[l + 1];
        value = lerpLanes(value, levelTapLanes<kC>(b, x * b.sx + b.ox, y * b.sy + b.oy), f);
    }
    storeLanes<kC>(out, value);
}

// A span's pixels, k = 0, 1, ... from its first: biased level-0 coordinates x0 + k sx, y0 + k sy
// (float, so the scalar and the planned paths compute the same ones), and the footprint: the
// longer of a (a2: its length squared, fixed) and b = b0 + k db, squared (as decodeRows has it).
struct SpanInputs {
    float x0, y0, sx, sy;
    float a2, bx0, by0, dbx, dby;
    float xAt(int k) const { return x0 + static_cast<float>(k) * sx; }
    float yAt(int k) const { return y0 + static_cast<float>(k) * sy; }
    float rho2At(int k) const {
        const float bx = bx0 + static_cast<float>(k) * dbx, by = by0 + static_cast<float>(k) * dby;
        return std::max(a2, bx * bx + by * by);
    }
};

}  // namespace conus::codec::detail
