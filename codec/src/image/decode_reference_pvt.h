// Private: the readable reference of the decode (decode.cpp), the one the GPU decoder and the
// fit are held to: bilinear taps at biased CoNUS pixel coordinates and, for a zoomed-out pixel
// without a pyramid, the average of na x nb taps over its footprint parallelogram (decode.h's
// multi-tap rule). Positions in double, one tap at a time (a tap's channels in lanes at most).
#pragma once

#include <algorithm>
#include <cstddef>

#include "conus/codec/image/decode.h"
#include "decode_pvt.h"
#include "resample_pvt.h"

namespace conus::codec::detail {

inline constexpr TapOffsets<kDecodeMaxTaps> kTapOffsets;

// Bilinear at CoNUS pixel coordinates plus one, known to lie in [0.5, size + 0.5] (Eq. 1 keeps
// every point inside the image): positive, so truncation is floor. kClamp = false when the whole
// 2x2 neighbourhood is known to be inside the image. kAccumulate adds weight * value to out.
template <int kC, bool kClamp, bool kAccumulate>
inline void tapBiased(const float* pixels, int width, int height, int c, double x, double y, float weight,
                      float* out) {
    const int channels = kC > 0 ? kC : c;
    const int xi = static_cast<int>(x), yi = static_cast<int>(y);
    const float fx = static_cast<float>(x - xi), fy = static_cast<float>(y - yi);
    const int x0 = kClamp ? std::max(xi - 1, 0) : xi - 1, x1 = kClamp ? std::min(xi, width - 1) : xi;
    const int y0 = kClamp ? std::max(yi - 1, 0) : yi - 1, y1 = kClamp ? std::min(yi, height - 1) : yi;
    const std::size_t stride = static_cast<std::size_t>(width) * channels;
    const float* r0 = pixels + y0 * stride;
    const float* r1 = pixels + y1 * stride;
    const int o0 = x0 * channels, o1 = x1 * channels;
    if constexpr (kLanes<kC> && !kAccumulate) {
        const float* last = pixels + (static_cast<std::size_t>(height) * width - 1) * kC;
        storeLanes<kC>(out, bilinearLanes<kC>(r0, r1, o0, o1, fx, fy, last));
        return;
    }
    for (int k = 0; k < channels; ++k) {
        const float top = r0[o0 + k] + fx * (r0[o1 + k] - r0[o0 + k]);
        const float bottom = r1[o0 + k] + fx * (r1[o1 + k] - r1[o0 + k]);
        const float value = top + fy * (bottom - top);
        if constexpr (kAccumulate) out[k] += weight * value;
        else out[k] = value;
    }
}

constexpr double kInteriorMargin = 1e-4;  // covers the fixed-point drift of the longest span

// Whether every biased point in the box [xlo,xhi] x [ylo,yhi] has its 2x2 neighbourhood inside.
inline bool interior(double xlo, double xhi, double ylo, double yhi, int width, int height) {
    return xlo >= 1.0 + kInteriorMargin && xhi < width - kInteriorMargin && ylo >= 1.0 + kInteriorMargin &&
           yhi < height - kInteriorMargin;
}

// A span of `count` output pixels along which the footprint's a axis is (ax, ay) and its b axis
// runs from (bx0, by0) to (bx1, by1) as s goes from 0 to 1 (s, ds: its start and step per pixel),
// positions (px, py) + k (sx, sy) in biased CoNUS pixels: each pixel averages tapsFor(|a|) x
// tapsFor(|b|) bilinear taps, one tap where both are 1. `acc` holds a pixel's channels.
template <int kC>
[[gnu::always_inline]] inline void multiTapSpan(const float* pixels, int width, int height, int channels, double px,
                                                double py, double sx, double sy, double ax, double ay, double bx0,
                                                double by0, double bx1, double by1, double s, double ds, int count,
                                                float* out, float* dynamicAcc) {
    const int Wc = width, Hc = height;
    const int na = tapsFor(length(ax, ay));
    for (int k = 0; k < count; ++k, px += sx, py += sy, s += ds, out += channels) {
        const double bxp = bx0 + s * (bx1 - bx0), byp = by0 + s * (by1 - by0);
        const int nb = tapsFor(length(bxp, byp));
        if (na == 1 && nb == 1) {
            tapBiased<kC, true, false>(pixels, Wc, Hc, channels, px, py, 1.0f, out);
            continue;
        }
        // Average na x nb taps over the footprint parallelogram of the output pixel.
        const float weight = 1.0f / static_cast<float>(na * nb);
        float fixedAcc[kC > 0 ? kC : 1];
        float* acc = kC > 0 ? fixedAcc : dynamicAcc;
        for (int c = 0; c < channels; ++c) acc[c] = 0.0f;
        const double* oa = kTapOffsets.at[na];
        const double* ob = kTapOffsets.at[nb];
        const double ex = std::abs(ax) * 0.5 + std::abs(bxp) * 0.5, ey = std::abs(ay) * 0.5 + std::abs(byp) * 0.5;
        const bool inner = interior(px - ex, px + ex, py - ey, py + ey, Wc, Hc);
        for (int jb = 0; jb < nb; ++jb) {
            const double qx = px + bxp * ob[jb], qy = py + byp * ob[jb];
            for (int ia = 0; ia < na; ++ia) {
                const double tx = qx + ax * oa[ia], ty = qy + ay * oa[ia];
                if (inner) tapBiased<kC, false, true>(pixels, Wc, Hc, channels, tx, ty, weight, acc);
                else
                    tapBiased<kC, true, true>(pixels, Wc, Hc, channels, std::clamp(tx, 0.5, Wc + 0.5),
                                              std::clamp(ty, 0.5, Hc + 0.5), weight, acc);
            }
        }
        for (int c = 0; c < channels; ++c) out[c] = acc[c];
    }
}

}  // namespace conus::codec::detail
