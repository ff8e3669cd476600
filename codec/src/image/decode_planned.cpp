// The pyramid decode's planned pass (decode_planned_pvt.h), one source built twice: planAndDecode
// is a template over the planner's lane count, instantiated as the baseline copy (4 pixels a
// planning step in SSE2 registers) and, under CONUS_TARGET_AVX2, as the AVX2 copy (8 pixels a
// step in 256-bit registers, where the 32-bit clamps, selects and the row multiply are single
// instructions: SSE2 has no 32-bit min, max, blend or multiply). The architecture is kept, so
// the small inline helpers of resample_pvt.h still inline into the AVX2 copy. Floating-point
// contraction is off for this file (codec/CMakeLists.txt), so both copies do the same operations
// in the same order and give the same floats (Pyramid.Avx2DecodeMatchesBaseline).
//
// Why two passes: one pass per pixel was a chain of ~100 dependent cycles (level, coordinates,
// addresses, then the loads) of which the core overlapped about two pixels; split, the second
// pass has many pixels' loads in flight (bench/notes/2026-11-24-decode-pyramid.md).
#include <atomic>
#include <cstdint>
#include <cstring>
#include <optional>

#include "conus/core/check.h"
#include "cpu_features_pvt.h"
#include "decode_magnify_pvt.h"
#include "decode_planned_pvt.h"
#include "decode_simd_pvt.h"
#include "pyramid_pvt.h"
#include "resample_pvt.h"

namespace conus::codec::detail {
namespace {

// The planner's lanes: kN pixels at a time (4: an SSE2 register, the baseline copy; 8: an AVX2
// register, the AVX2 copy). Lane by lane the same operations either way.
template <int kN>
struct PlanLanes;
template <>
struct PlanLanes<4> {
    typedef float F __attribute__((vector_size(16)));
    typedef std::int32_t I __attribute__((vector_size(16)));
};
template <>
struct PlanLanes<8> {
    typedef float F __attribute__((vector_size(32)));
    typedef std::int32_t I __attribute__((vector_size(32)));
};



// The taps' rows are prefetched this many output rows ahead. Along an output row the taps follow
// a curve through the CoNUS image that changes row every few pixels where the map bends it, so
// the hardware's stream prefetch rarely locks on (the bilinear baseline reads two rows straight
// through); the next rows' taps lie one footprint b further per output row, and the planner has b.
// Measured on the codec_bench whole frame: 1 and 2 rows ahead alike, 0 (this block) little gain.
constexpr float kPrefetchRows = 2.0f;

template <int kC, int kN, typename F = typename PlanLanes<kN>::F, typename I = typename PlanLanes<kN>::I>
[[gnu::always_inline]] inline void planTaps(const Level& l, F x, F y, TapPlan& plan, int at) {
    const F lx = x * l.sx + l.ox, ly = y * l.sy + l.oy;
    const I xi = __builtin_convertvector(lx, I), yi = __builtin_convertvector(ly, I);
    const F fx = lx - __builtin_convertvector(xi, F);
    const F fy = ly - __builtin_convertvector(yi, F);
    const I zero = {};
    const I xm = xi - 1, ym = yi - 1, wLast = zero + (l.width - 1), hLast = zero + (l.height - 1);
    const I x0 = xm > zero ? xm : zero, x1 = xi < wLast ? xi : wLast;
    const I y0 = ym > zero ? ym : zero, y1 = yi < hLast ? yi : hLast;
    const std::int32_t stride = l.width * kC;
    // x1 - x0 and y1 - y0 are 0 or 1: the steps by masks, not multiplies (SSE2 has no 32-bit one).
    const I offset = y0 * stride + x0 * kC, dx = (x0 - x1) & kC, dy = (y0 - y1) & stride;
    std::memcpy(plan.offset + at, &offset, sizeof offset);
    std::memcpy(plan.dx + at, &dx, sizeof dx);
    std::memcpy(plan.dy + at, &dy, sizeof dy);
    std::memcpy(plan.fx + at, &fx, sizeof fx);
    std::memcpy(plan.fy + at, &fy, sizeof fy);
}

// pyramidLevel on a vector of footprints (the same operations as the scalar one; the result by
// reference: a 32-byte vector returned by value changes the ABI without AVX, and GCC says so).
template <typename F, typename I>
[[gnu::always_inline]] inline void pyramidLevels(const F& rho2, F& out) {
    I bits;
    std::memcpy(&bits, &rho2, sizeof bits);
    const I exponent = ((bits >> 23) & 0xff) - 127;
    const I mantissaBits = (bits & 0x7fffff) | 0x3f800000;
    F mantissa;
    std::memcpy(&mantissa, &mantissaBits, sizeof mantissa);
    const F t = mantissa - 1.0f;
    const F zero = {};
    const F lambda =
        0.5f * (__builtin_convertvector(exponent, F) + t * (1.3465553f - 0.3465553f * t)) -
        static_cast<float>(kDecodePyramidBias);
    const F positive = zero < lambda ? lambda : zero;
    out = rho2 > 1.0f ? positive : zero;
}

// Whether every lane of a comparison's result is set.
template <typename I>
[[gnu::always_inline]] inline bool allLanes(const I& mask) {
    std::uint64_t words[sizeof(I) / 8];
    std::memcpy(words, &mask, sizeof mask);
    std::uint64_t all = ~std::uint64_t{0};
    for (const std::uint64_t w : words) all &= w;
    return all == ~std::uint64_t{0};
}

// A level's constants in lanes, loaded once per block (the plan's stores could alias a Level).
template <int kC, typename F, typename I>
struct LevelLanes {
    F sx, ox, sy, oy;
    I wLast, hLast, stride;
    explicit LevelLanes(const Level& l)
        : sx(F{} + l.sx), ox(F{} + l.ox), sy(F{} + l.sy), oy(F{} + l.oy), wLast(I{} + (l.width - 1)),
          hLast(I{} + (l.height - 1)), stride(I{} + l.width * kC) {}
};

// planTaps for a block expected to lie inside the level: the top-left pixel and the weights only
// (the neighbours are a pixel and a row away), and the lanes for which that holds (`inside`, by
// reference: see pyramidLevels).
template <int kC, typename F, typename I>
[[gnu::always_inline]] inline void planInteriorTaps(const LevelLanes<kC, F, I>& l, F x, F y, TapPlan& plan, int at,
                                                    I& inside) {
    const F lx = x * l.sx + l.ox, ly = y * l.sy + l.oy;
    const I xi = __builtin_convertvector(lx, I), yi = __builtin_convertvector(ly, I);
    const F fx = lx - __builtin_convertvector(xi, F);
    const F fy = ly - __builtin_convertvector(yi, F);
    const I offset = (yi - 1) * l.stride + (xi - 1) * kC;
    std::memcpy(plan.offset + at, &offset, sizeof offset);
    std::memcpy(plan.fx + at, &fx, sizeof fx);
    std::memcpy(plan.fy + at, &fy, sizeof fy);
    inside = (xi >= 1) & (xi <= l.wLast) & (yi >= 1) & (yi < l.hLast);
}

// The top-left pixel's offset on a level at biased level-0 coordinates (x, y), clamped into the
// level, stored at `to`: for prefetching only.
template <int kC, typename F, typename I>
[[gnu::always_inline]] inline void clampedOffset(const LevelLanes<kC, F, I>& l, F x, F y, std::int32_t* to) {
    const F lx = x * l.sx + l.ox, ly = y * l.sy + l.oy;
    const F one = F{} + 1.0f, right = __builtin_convertvector(l.wLast, F), bottom = __builtin_convertvector(l.hLast, F);
    // In float first: a position far outside would overflow the conversion.
    const F cx = lx < one ? one : (lx > right ? right : lx), cy = ly < one ? one : (ly > bottom ? bottom : ly);
    const I xi = __builtin_convertvector(cx, I), yi = __builtin_convertvector(cy, I);
    const I offset = (yi - 1) * l.stride + (xi - 1) * kC;
    std::memcpy(to, &offset, sizeof offset);
}

// Prefetches the rows of the taps recorded in plan.ahead (two pixels share most lines).
template <int kC>
[[gnu::always_inline]] inline void prefetchAhead(const float* pixels, std::size_t stride, const PixelPlan& plan,
                                                 int count) {
    for (int k = 0; k < count; k += 2) {
        const float* p = pixels + plan.ahead[k];
        __builtin_prefetch(p, 0, 2);
        __builtin_prefetch(p + stride, 0, 2);
    }
}

// Plans pixels k0 .. k0 + count - 1 (count <= kPlanBlock) of a span, kN at a time: each pixel's
// level and blend and, while every pixel so far is on the first one's level (the common case:
// the level changes slowly along a span), both levels' taps with the levels' constants fixed for
// the block. A block that leaves its level or its levels' interior is planned again pixel group
// by pixel group, each on its own levels and with the clamps.
template <int kC, int kN>
[[gnu::always_inline]] inline void planPixels(const Level* levels, int top, const SpanInputs& in, int k0, int count,
                                              PixelPlan& plan) {
    using F = typename PlanLanes<kN>::F;
    using I = typename PlanLanes<kN>::I;
    const F zero = {};
    I lane;
    for (int j = 0; j < kN; ++j) lane[j] = j;
    const F topLevel = zero + static_cast<float>(top);
    I blended = lane != lane;  // lanes with a blend above 0 (the second tap counts)
    const auto positions = [&](int at, F& x, F& y, F& k) {
        k = __builtin_convertvector(lane + (k0 + at), F);
        x = in.x0 + k * in.sx;
        y = in.y0 + k * in.sy;
    };
    // The first group's levels decide the block's (a padding lane's level does not count).
    int uniform = -1;
    std::optional<LevelLanes<kC, F, I>> a, b;
    bool interior = true;
    for (int at = 0; at < count; at += kN) {
        F x, y, k;
        positions(at, x, y, k);
        const F bx = in.bx0 + k * in.dbx, by = in.by0 + k * in.dby;
        const F b2 = bx * bx + by * by;
        const F r = in.a2 < b2 ? b2 : zero + in.a2;  // std::max(a2, b2)
        F level;
        pyramidLevels<F, I>(r, level);
        const F lambda = topLevel < level ? topLevel : level;  // std::min(level, top)
        const I l = __builtin_convertvector(lambda, I);
        const F f = lambda - __builtin_convertvector(l, F);
        std::memcpy(plan.level + at, &l, sizeof l);
        std::memcpy(plan.blend + at, &f, sizeof f);
        blended |= f > zero;
        if (!interior) continue;
        if (at == 0) {
            uniform = l[0];
            a.emplace(levels[uniform]);
            if (uniform < top) b.emplace(levels[uniform + 1]);
        }
        const I padding = lane >= count - at;
        if (!allLanes((l == uniform) | padding)) {
            interior = false;
            continue;
        }
        I inside, insideB;
        planInteriorTaps<kC>(*a, x, y, plan.taps[0], at, inside);
        clampedOffset<kC>(*a, x + kPrefetchRows * bx, y + kPrefetchRows * by, plan.ahead + at);
        if (b) {
            planInteriorTaps<kC>(*b, x, y, plan.taps[1], at, insideB);
            inside &= insideB;
        }
        interior = allLanes(inside | padding);
    }
    if (interior) {
        plan.uniform = uniform;
        plan.oneTap = uniform == top || allLanes(blended == 0);
        return;
    }
    plan.uniform = -1;
    for (int at = 0; at < count; at += kN) {
        F x, y, k;
        positions(at, x, y, k);
        I l;
        std::memcpy(&l, plan.level + at, sizeof l);
        if (allLanes(l == l[0])) {
            planTaps<kC, kN>(levels[l[0]], x, y, plan.taps[0], at);
            if (l[0] < top) planTaps<kC, kN>(levels[l[0] + 1], x, y, plan.taps[1], at);
            continue;
        }
        // Lanes on different levels: each lane's levels in turn (the other lanes' entries are
        // overwritten by their own).
        for (int j = 0; j < kN; ++j) {
            TapPlan scratch[2];
            planTaps<kC, kN>(levels[l[j]], x, y, scratch[0], 0);
            const int taps = l[j] < top ? 2 : 1;
            if (taps == 2) planTaps<kC, kN>(levels[l[j] + 1], x, y, scratch[1], 0);
            for (int t = 0; t < taps; ++t) {
                plan.taps[t].offset[at + j] = scratch[t].offset[j];
                plan.taps[t].dx[at + j] = scratch[t].dx[j];
                plan.taps[t].dy[at + j] = scratch[t].dy[j];
                plan.taps[t].fx[at + j] = scratch[t].fx[j];
                plan.taps[t].fy[at + j] = scratch[t].fy[j];
            }
        }
    }
}

template <int kC>
[[gnu::always_inline]] inline PixelLanes plannedTap(const Level& l, const TapPlan& plan, int k) {
    const float* p0 = l.pixels + plan.offset[k];
    const float* p1 = p0 + plan.dy[k];
    return bilinearLanes<kC>(p0, p1, 0, static_cast<std::size_t>(plan.dx[k]), plan.fx[k], plan.fy[k], l.last);
}

// The second pass: loads and blends only.
template <int kC>
[[gnu::always_inline]] inline void decodePlanned(const Level* levels, const PixelPlan& plan, int count, float* out) {
    for (int k = 0; k < count; ++k, out += kC) {
        const int l = plan.level[k];
        PixelLanes value = plannedTap<kC>(levels[l], plan.taps[0], k);
        const float f = plan.blend[k];
        if (f > 0.0f) value = lerpLanes(value, plannedTap<kC>(levels[l + 1], plan.taps[1], k), f);
        storeLanes<kC>(out, value);
    }
}

// plannedTap for a block whose neighbourhoods are all inside: the neighbours are a pixel and a
// row away, so the same loads and operations without the per-pixel steps or the overrun check.
template <int kC>
[[gnu::always_inline]] inline PixelLanes interiorTap(const float* pixels, std::size_t stride,
                                                             const TapPlan& plan, int k) {
    return interiorTapAt<kC>(pixels + plan.offset[k], stride, plan.fx[k], plan.fy[k]);
}

// decodePlanned for a block on one level pair, all inside (PixelPlan::uniform).
template <int kC>
[[gnu::always_inline]] inline void decodeInterior(const Level* levels, const PixelPlan& plan, int count, float* out) {
    const Level& a = levels[plan.uniform];
    const std::size_t sa = static_cast<std::size_t>(a.width) * kC;
    // The block's pixels are written in order, so all but its last may store four lanes.
    const auto store = [&](int k, PixelLanes v) {
        storeLanesInRun<kC>(out + static_cast<std::size_t>(k) * kC, v, k + 1 < count);
    };
    if (plan.oneTap) {
        prefetchAhead<kC>(a.pixels, sa, plan, count);
        for (int k = 0; k < count; ++k) store(k, interiorTap<kC>(a.pixels, sa, plan.taps[0], k));
        return;
    }
    const Level& b = levels[plan.uniform + 1];
    const std::size_t sb = static_cast<std::size_t>(b.width) * kC;
    const float* const pa = a.pixels;  // locals: the stores to `out` cannot move them
    const float* const pb = b.pixels;
    const TapPlan& ta = plan.taps[0];
    const TapPlan& tb = plan.taps[1];
    prefetchAhead<kC>(pa, sa, plan, count);
    for (int k = 0; k < count; ++k) {
        const float f = plan.blend[k];
        const PixelLanes value = interiorTap<kC>(pa, sa, ta, k);
        const PixelLanes blended = lerpLanes(value, interiorTap<kC>(pb, sb, tb, k), f);
        store(k, f > 0.0f ? blended : value);
    }
}

// A block of a span: its plan, then its taps (the arguments are planPixels's, then the output).
template <int kC, int kN>
[[gnu::always_inline]] inline void planAndDecode(const Level* levels, int top, const SpanInputs& in, int k0, int count,
                                                 PixelPlan& plan, float* out) {
    CONUS_DCHECK(count > 0 && count <= kPlanBlock);
    planPixels<kC, kN>(levels, top, in, k0, count, plan);
    // decodeInterior blends level uniform + 1 unless every pixel takes one tap.
    CONUS_DCHECK(plan.uniform < 0 || plan.oneTap || plan.uniform < top);
    if (plan.uniform >= 0) decodeInterior<kC>(levels, plan, count, out);
    else decodePlanned<kC>(levels, plan, count, out);
}

// planAndDecode in two copies, chosen once at run time: the baseline one and, where the compiler
// can make it, one for AVX2 (with FMA and BMI2 it is x86-64-v3; the architecture is kept, so the
// small inline helpers of resample_pvt.h still inline into it). The planner's clamps and selects are then single
// instructions (SSE2 has no 32-bit min, max, blend or multiply), and the tap's addresses come out
// sooner. Floating-point contraction is off for this file (codec/CMakeLists.txt), so the AVX2 copy
// does the same operations in the same order: the same floats (Pyramid.Avx2DecodeMatchesBaseline).

template <int kC>
void planAndDecodeBaseline(const Level* levels, int top, const SpanInputs& in, int k0, int count, PixelPlan& plan,
                           float* out) {
    planAndDecode<kC, 4>(levels, top, in, k0, count, plan, out);
}

#if CONUS_HAVE_AVX2_COPY
template <int kC>
CONUS_TARGET_AVX2 void planAndDecodeAvx2(const Level* levels, int top, const SpanInputs& in, int k0, int count,
                                         PixelPlan& plan, float* out) {
    planAndDecode<kC, 8>(levels, top, in, k0, count, plan, out);
}
#endif

std::atomic<bool> g_forceBaseline{false};

}  // namespace

bool plannable(const Level& level0, int channels) {
    return static_cast<std::int64_t>(level0.width) * level0.height * channels < (std::int64_t{1} << 31);
}

template <int kC>
BlockFn chooseBlockFn() {
#if CONUS_HAVE_AVX2_COPY
    static const bool avx2 = cpuHasAvx2();
    if (avx2 && !g_forceBaseline.load(std::memory_order_relaxed)) return &planAndDecodeAvx2<kC>;
#endif
    return &planAndDecodeBaseline<kC>;
}
template BlockFn chooseBlockFn<3>();
template BlockFn chooseBlockFn<4>();

bool decodeAvx2Available() { return cpuHasAvx2(); }
void forceBaselineDecode(bool baseline) { g_forceBaseline.store(baseline, std::memory_order_relaxed); }

}  // namespace conus::codec::detail
