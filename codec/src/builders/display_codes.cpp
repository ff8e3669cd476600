// The display transform through its table and the 8-bit codes a display shows (display_codes_pvt.h).
#include "display_codes_pvt.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>

#include "conus/core/display.h"
#include "../image/cpu_features_pvt.h"

#if CONUS_HAVE_AVX2_COPY
#include <immintrin.h>
#endif

namespace conus::codec::detail {
namespace {

// The 8-bit code a display shows for a colour value: shown(), then its nearest code, the value of
// the 8-bit sRGB pictures bench/quality.py compares. x is exact and within [0, 255] (the table's
// values lie in [0, 1]), where the only half is 127.5 (0.5f * 255): there rounding to even, as
// adding and taking away 1.5 * 2^52 does, gives round()'s 128 too. (The clamp holds the index
// whatever the table.)
int roundedCode(float v, const std::vector<float>& table) {
    const double x = double(shown(v, true, table)) * 255.0;
    constexpr double kRoundingShift = 6755399441055744.0;
    return std::clamp(static_cast<int>((x + kRoundingShift) - kRoundingShift), 0, 255);
}

// roundedCode through the thresholds between codes: the code at the start of v's step of the table,
// then one more where v reaches the next threshold (a step of the table spans at most 0.8 of a code,
// where sRGB is steepest). The same code for every float (checked over all 2^32 of them), without
// the interpolation, the rounding or a branch on the value: the confirming measure takes three a
// value, over the source's size.
struct CodeThresholds {
    std::array<float, 257> lowest{};                                 // [c]: the least v whose code is c or more
    // [i]: roundedCode(i / kDisplayTableSteps), i <= kDisplayTableSteps; three bytes after, so that
    // a gather of four bytes at the last stays inside.
    std::array<std::uint8_t, kDisplayTableSteps + 4> start{};
};

const CodeThresholds& codeThresholds() {
    static const CodeThresholds thresholds = [] {
        CodeThresholds t;
        const std::vector<float>& table = displayTable();
        for (int c = 1; c <= 255; ++c) {
            // Bisection on the bits of the floats in [0, 1], which order as the integers do.
            std::uint32_t lo = 0, hi = std::bit_cast<std::uint32_t>(1.0f);
            while (hi - lo > 1) {
                const std::uint32_t mid = lo + (hi - lo) / 2;
                (roundedCode(std::bit_cast<float>(mid), table) >= c ? hi : lo) = mid;
            }
            t.lowest[c] = std::bit_cast<float>(hi);
        }
        t.lowest[256] = std::numeric_limits<float>::infinity();
        for (int i = 0; i <= kDisplayTableSteps; ++i) t.start[i] = std::uint8_t(roundedCode(float(i) / kDisplayTableSteps, table));
        return t;
    }();
    return thresholds;
}

// roundedCode(v): NaN, infinities and values up to 0 show as 0 (shown()), 1 and above as 255 (the
// last step's code, below lowest[256]); without a branch on the value.
int fastDisplayCode(float v, const CodeThresholds& t) {
    const float x = v > 0.0f && v != std::numeric_limits<float>::infinity() ? std::min(v, 1.0f) : 0.0f;
    const int c = t.start[static_cast<int>(x * kDisplayTableSteps)];
    return c + (x >= t.lowest[c + 1]);
}

#if CONUS_HAVE_AVX2_COPY
// fastDisplayCode of eight values at a time: the two tables read by gathers.
CONUS_TARGET_AVX2 void displayCodesAvx2(const float* in, std::uint8_t* out, std::size_t n, const CodeThresholds& t) {
    const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f);
    const __m256 infinity = _mm256_set1_ps(std::numeric_limits<float>::infinity());
    const __m256 steps = _mm256_set1_ps(float(kDisplayTableSteps));
    const __m256i byte = _mm256_set1_epi32(0xff), next = _mm256_set1_epi32(1);
    const int* start = reinterpret_cast<const int*>(t.start.data());
    std::size_t i = 0;
    for (; i + 8 <= n; i += 8) {
        const __m256 v = _mm256_loadu_ps(in + i);
        // v where 0 < v < infinity (NaN fails both), at most 1 (minps gives 1 for a NaN: masked off).
        const __m256 shown = _mm256_and_ps(_mm256_cmp_ps(v, zero, _CMP_GT_OQ), _mm256_cmp_ps(v, infinity, _CMP_NEQ_OQ));
        const __m256 x = _mm256_and_ps(_mm256_min_ps(v, one), shown);
        const __m256i step = _mm256_cvttps_epi32(_mm256_mul_ps(x, steps));
        __m256i code = _mm256_and_si256(_mm256_i32gather_epi32(start, step, 1), byte);
        const __m256 threshold = _mm256_i32gather_ps(t.lowest.data(), _mm256_add_epi32(code, next), 4);
        code = _mm256_sub_epi32(code, _mm256_castps_si256(_mm256_cmp_ps(x, threshold, _CMP_GE_OQ)));  // +1 where reached
        const __m128i words = _mm_packus_epi32(_mm256_castsi256_si128(code), _mm256_extracti128_si256(code, 1));
        _mm_storel_epi64(reinterpret_cast<__m128i*>(out + i), _mm_packus_epi16(words, words));
    }
    for (; i < n; ++i) out[i] = std::uint8_t(fastDisplayCode(in[i], t));
}
#endif

}  // namespace

const std::vector<float>& displayTable() {
    static const std::vector<float> table = [] {
        std::vector<float> t(kDisplayTableSteps + 2);
        for (int i = 0; i <= kDisplayTableSteps; ++i) t[i] = linearToSrgbDisplay(float(i) / kDisplayTableSteps);
        t[kDisplayTableSteps + 1] = t[kDisplayTableSteps];
        return t;
    }();
    return table;
}

std::uint8_t displayCode(float v) { return std::uint8_t(fastDisplayCode(v, codeThresholds())); }

void displayCodes(const float* in, std::uint8_t* out, std::size_t n, bool vectors) {
    const CodeThresholds& t = codeThresholds();
#if CONUS_HAVE_AVX2_COPY
    static const bool avx2 = cpuHasAvx2();
    if (vectors && avx2) return displayCodesAvx2(in, out, n, t);
#endif
    for (std::size_t i = 0; i < n; ++i) out[i] = std::uint8_t(fastDisplayCode(in[i], t));
}

}  // namespace conus::codec::detail
