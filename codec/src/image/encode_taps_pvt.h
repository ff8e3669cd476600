// The anisotropic kernel's row of taps (encode.cpp): bilinear on all channels at once, a baseline
// loop and an AVX2 copy of it.
#pragma once

#include <cstddef>
#include <cstring>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "conus/codec/image/encode.h"
#include "cpu_features_pvt.h"

namespace conus::codec::detail {

// One grid row's taps, all worked out before any texel is read: each tap's arithmetic is then
// independent of the others' and the loops vectorize (the loop this replaced took a tap at a time,
// each waiting on two divisions, two erf table reads and a branch).
struct RowTaps {
    static constexpr int kMax = 2 * kEncodeMaxAxisTaps;
    int count = 0;
    double x[kMax], y[kMax];
    double weight[kMax];  // <= 0: the tap is left out
};

// Four floats: one texel's channels (kC <= 4) in one register, so a bilinear tap is a handful of
// vector operations instead of a loop over channels.
using Float4 = float __attribute__((vector_size(16)));

inline Float4 load4(const float* p) {
    Float4 v;
    std::memcpy(&v, p, sizeof v);
    return v;
}

// One row of the anisotropic kernel's taps, all inside the level a row clear of its last: tap i
// at texel coordinates (x + i sx, y + i sy), weight weight[i] (every one > 0), bilinear on all
// channels at once, added to acc. The taps' texel offsets and fractions are worked out first,
// without a branch, so that loop vectorizes.
struct TapRow {
    double x = 0, y = 0, sx = 0, sy = 0;
    int count = 0;
    const float* weight = nullptr;
};

// The row's taps' first texels (offsets in floats) and their fractions, without a branch so the
// loop vectorizes (inlined into each copy of the tap loop, with that copy's instructions).
template <int kC>
inline void tapPlaces(std::size_t stride, const TapRow& row, std::size_t* offset, float* fx, float* fy) {
    for (int n = 0; n < row.count; ++n) {
        const double x = row.x + n * row.sx, y = row.y + n * row.sy;
        const int xi = static_cast<int>(x), yi = static_cast<int>(y);
        fx[n] = static_cast<float>(x - xi);
        fy[n] = static_cast<float>(y - yi);
        offset[n] = yi * stride + static_cast<std::size_t>(xi) * kC;
    }
}

template <int kC>
inline void tapRowBaseline(const float* pixels, std::size_t stride, const TapRow& row, Float4& acc) {
    std::size_t offset[RowTaps::kMax];
    float fx[RowTaps::kMax], fy[RowTaps::kMax];
    tapPlaces<kC>(stride, row, offset, fx, fy);
    for (int n = 0; n < row.count; ++n) {
        const float* p0 = pixels + offset[n];
        const float* p1 = p0 + stride;
        const Float4 a = load4(p0), b = load4(p1);
        const Float4 top = a + fx[n] * (load4(p0 + kC) - a);
        const Float4 bottom = b + fx[n] * (load4(p1 + kC) - b);
        acc += row.weight[n] * (top + fy[n] * (bottom - top));
    }
}

#if CONUS_HAVE_AVX2_COPY
// tapRowBaseline on a processor with AVX2: the offsets four taps at a time, then two taps a step,
// one in each 128-bit half of a register, each lerp a fused multiply-add (so the sums differ from
// the baseline's in their last bits); the same four-float texel reads.
template <int kC>
CONUS_TARGET_AVX2 void tapRowAvx2(const float* pixels, std::size_t stride, const TapRow& row, Float4& acc) {
    std::size_t offset[RowTaps::kMax];
    float fx[RowTaps::kMax], fy[RowTaps::kMax];
    tapPlaces<kC>(stride, row, offset, fx, fy);
    __m256 sum = _mm256_setzero_ps();
    int n = 0;
    for (; n + 1 < row.count; n += 2) {
        const float* p = pixels + offset[n];
        const float* q = pixels + offset[n + 1];
        const __m256 a = _mm256_set_m128(_mm_loadu_ps(q), _mm_loadu_ps(p));
        const __m256 a1 = _mm256_set_m128(_mm_loadu_ps(q + kC), _mm_loadu_ps(p + kC));
        const __m256 b = _mm256_set_m128(_mm_loadu_ps(q + stride), _mm_loadu_ps(p + stride));
        const __m256 b1 = _mm256_set_m128(_mm_loadu_ps(q + stride + kC), _mm_loadu_ps(p + stride + kC));
        const __m256 fxv = _mm256_set_m128(_mm_set1_ps(fx[n + 1]), _mm_set1_ps(fx[n]));
        const __m256 fyv = _mm256_set_m128(_mm_set1_ps(fy[n + 1]), _mm_set1_ps(fy[n]));
        const __m256 wv = _mm256_set_m128(_mm_set1_ps(row.weight[n + 1]), _mm_set1_ps(row.weight[n]));
        const __m256 top = _mm256_fmadd_ps(fxv, _mm256_sub_ps(a1, a), a);
        const __m256 bottom = _mm256_fmadd_ps(fxv, _mm256_sub_ps(b1, b), b);
        sum = _mm256_fmadd_ps(wv, _mm256_fmadd_ps(fyv, _mm256_sub_ps(bottom, top), top), sum);
    }
    __m128 s = _mm_add_ps(_mm256_castps256_ps128(sum), _mm256_extractf128_ps(sum, 1));
    if (n < row.count) {
        const float* p = pixels + offset[n];
        const __m128 a = _mm_loadu_ps(p), a1 = _mm_loadu_ps(p + kC);
        const __m128 b = _mm_loadu_ps(p + stride), b1 = _mm_loadu_ps(p + stride + kC);
        const __m128 fxv = _mm_set1_ps(fx[n]);
        const __m128 top = _mm_fmadd_ps(fxv, _mm_sub_ps(a1, a), a);
        const __m128 bottom = _mm_fmadd_ps(fxv, _mm_sub_ps(b1, b), b);
        s = _mm_fmadd_ps(_mm_set1_ps(row.weight[n]), _mm_fmadd_ps(_mm_set1_ps(fy[n]), _mm_sub_ps(bottom, top), top), s);
    }
    Float4 v;
    std::memcpy(&v, &s, sizeof v);
    acc += v;
}
#endif

}  // namespace conus::codec::detail
