// Private: what the CPU encoder, decoder and their baselines share: argument checks, output
// allocation, clamp-to-edge bilinear taps with the channel count known at compile time, and a
// thread-safe progress reporter.
#pragma once

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <string>
#include <utility>

#include "conus/core/error.h"
#include "conus/core/image.h"

namespace conus::codec::detail {

inline void checkOutputSize(int width, int height, const char* what) {
    if (width < 1 || height < 1)
        throw Error(ErrorCode::InvalidArgument, std::string(what) + ": output size " + std::to_string(width) + "x" +
                                                    std::to_string(height) + " must be at least 1x1");
    if (width > kMaxImageSide || height > kMaxImageSide ||
        std::int64_t{width} * height > kMaxImagePixels)
        throw Error(ErrorCode::LimitExceeded, std::string(what) + ": output size " + std::to_string(width) + "x" +
                                                  std::to_string(height) + " exceeds the image limits (" +
                                                  std::to_string(kMaxImageSide) + " a side, " +
                                                  std::to_string(kMaxImagePixels) + " pixels in all)");
}

// Same channels as `like`, zero-filled; sizes already checked. Through makeImage, so a large
// output is first touched in huge pages (core/src/image.cpp).
inline Image makeOutput(const Image& like, int width, int height) { return makeImage(width, height, like.channels); }

inline int floorToInt(double x) {
    const int i = static_cast<int>(x);
    return i - (x < i ? 1 : 0);
}

// Accumulates weight * bilinear(image at pixel coordinates (x,y)) into acc; pixel centres sit at
// integers, coordinates outside the image clamp to the edge. kC > 0 fixes the channel count so the
// compiler unrolls the channel loops; kC == 0 reads it from c.
template <int kC>
inline void addBilinear(const float* pixels, int width, int height, int c, double x, double y, float weight,
                        float* acc) {
    const int channels = kC > 0 ? kC : c;
    // Clamping the coordinate first keeps huge or non-finite values out of the int conversion.
    x = std::clamp(x, -1.0, static_cast<double>(width));
    y = std::clamp(y, -1.0, static_cast<double>(height));
    const int xi = floorToInt(x), yi = floorToInt(y);
    const float fx = static_cast<float>(x - xi), fy = static_cast<float>(y - yi);
    const int x0 = std::clamp(xi, 0, width - 1), x1 = std::clamp(xi + 1, 0, width - 1);
    const int y0 = std::clamp(yi, 0, height - 1), y1 = std::clamp(yi + 1, 0, height - 1);
    const float* r0 = pixels + static_cast<std::size_t>(y0) * width * channels;
    const float* r1 = pixels + static_cast<std::size_t>(y1) * width * channels;
    const float* p00 = r0 + static_cast<std::size_t>(x0) * channels;
    const float* p01 = r0 + static_cast<std::size_t>(x1) * channels;
    const float* p10 = r1 + static_cast<std::size_t>(x0) * channels;
    const float* p11 = r1 + static_cast<std::size_t>(x1) * channels;
    const float w00 = (1 - fx) * (1 - fy) * weight, w01 = fx * (1 - fy) * weight;
    const float w10 = (1 - fx) * fy * weight, w11 = fx * fy * weight;
    for (int k = 0; k < channels; ++k) acc[k] += w00 * p00[k] + w01 * p01[k] + w10 * p10[k] + w11 * p11[k];
}

// Bilinear at pixel coordinates (x,y) whose 2x2 neighbourhood is known to be inside the image
// (0 <= x < width - 1, same for y): no clamping. Adds weight * value to acc.
template <int kC>
inline void addBilinearInterior(const float* pixels, std::size_t stride, int c, double x, double y, float weight,
                                float* acc) {
    const int channels = kC > 0 ? kC : c;
    const int xi = static_cast<int>(x), yi = static_cast<int>(y);
    const float fx = static_cast<float>(x - xi), fy = static_cast<float>(y - yi);
    const float* p0 = pixels + yi * stride + static_cast<std::size_t>(xi) * channels;
    const float* p1 = p0 + stride;
    for (int k = 0; k < channels; ++k) {
        const float top = p0[k] + fx * (p0[channels + k] - p0[k]);
        const float bottom = p1[k] + fx * (p1[channels + k] - p1[k]);
        acc[k] += weight * (top + fy * (bottom - top));
    }
}

// One pixel of a 3- or 4-channel image in the lanes of a 16-byte vector (GCC/Clang vector
// extension: SSE2 on x86-64, NEON on ARM), so a bilinear tap is 4 loads and 9 vector operations
// instead of 12 loads and 27 scalar ones. The operations are the scalar taps' own, lane by lane
// and in the same order (a + t * (b - a)), so the results are the same floats; with 3 channels the
// fourth lane holds whatever follows the pixel: storeLanes leaves it out, and a loop that stores
// all four lanes of a pixel does so only where the next pixel's store overwrites it.
typedef float PixelLanes __attribute__((vector_size(16)));

template <int kC>
inline constexpr bool kLanes = kC == 3 || kC == 4;

// Reads 4 floats at p: the caller makes sure they lie inside the array (see bilinearLanes).
inline PixelLanes loadLanes(const float* p) {
    PixelLanes v;
    std::memcpy(&v, p, sizeof v);
    return v;
}
// Reads exactly kC floats at p (the array's last pixel), the rest zero.
template <int kC>
inline PixelLanes loadLanesExact(const float* p) {
    PixelLanes v = {0, 0, 0, 0};
    std::memcpy(&v, p, kC * sizeof(float));
    return v;
}
template <int kC>
inline void storeLanes(float* out, PixelLanes v) {
    std::memcpy(out, &v, kC * sizeof(float));
}
// storeLanes for a pixel of a run stored in order: all four lanes where the next pixel follows
// (`followed`: its store overwrites the fourth), one 16-byte store instead of a 12-byte copy.
template <int kC>
inline void storeLanesInRun(float* out, PixelLanes v, bool followed) {
    if (kC == 4 || followed) std::memcpy(out, &v, sizeof v);
    else storeLanes<kC>(out, v);
}
inline PixelLanes lerpLanes(PixelLanes a, PixelLanes b, float t) { return a + t * (b - a); }

// Bilinear between the pixels at r0 + o0, r0 + o1, r1 + o0 and r1 + o1 (r0 <= r1, o0 <= o1,
// offsets in floats), weights fx and fy as in addBilinearInterior. `last` is the image's last
// pixel: the only one a 4-float read overruns when there are 3 channels.
template <int kC>
inline PixelLanes bilinearLanes(const float* r0, const float* r1, std::size_t o0, std::size_t o1, float fx, float fy,
                                const float* last) {
    static_assert(kLanes<kC>);
    PixelLanes p00, p01, p10, p11;
    if (kC == 4 || r1 + o1 != last) {
        p00 = loadLanes(r0 + o0);
        p01 = loadLanes(r0 + o1);
        p10 = loadLanes(r1 + o0);
        p11 = loadLanes(r1 + o1);
    } else {
        p00 = loadLanesExact<kC>(r0 + o0);
        p01 = loadLanesExact<kC>(r0 + o1);
        p10 = loadLanesExact<kC>(r1 + o0);
        p11 = loadLanesExact<kC>(r1 + o1);
    }
    const PixelLanes top = lerpLanes(p00, p01, fx);
    return lerpLanes(top, lerpLanes(p10, p11, fx), fy);
}

// Sub-tap offsets (k + 0.5) / n - 0.5, in units of the footprint, for n = 1..kMaxN: n taps at
// the centres of n equal slices of [-0.5, 0.5].
template <int kMaxN>
struct TapOffsets {
    double at[kMaxN + 1][kMaxN];
    constexpr TapOffsets() : at{} {
        for (int n = 1; n <= kMaxN; ++n)
            for (int k = 0; k < n; ++k) at[n][k] = (k + 0.5) / n - 0.5;
    }
};

// Calls fn.template operator()<kC>() with the channel count as a constant for the common counts.
template <typename Fn>
inline void dispatchChannels(int channels, Fn&& fn) {
    switch (channels) {
    case 1: fn.template operator()<1>(); break;
    case 2: fn.template operator()<2>(); break;
    case 3: fn.template operator()<3>(); break;
    case 4: fn.template operator()<4>(); break;
    default: fn.template operator()<0>(); break;
    }
}

// Reports rows done as a fraction; serialized so the callback never runs on two threads at once.
class RowProgress {
public:
    RowProgress(const ProgressFn& fn, int rows) : m_fn(fn), m_rows(rows) {}
    void add(int rows) {
        if (!m_fn) return;
        std::lock_guard lock(m_mutex);
        m_done += rows;
        m_fn(static_cast<double>(m_done) / m_rows);
    }

private:
    const ProgressFn& m_fn;
    int m_rows;
    int m_done = 0;
    std::mutex m_mutex;
};

}  // namespace conus::codec::detail
