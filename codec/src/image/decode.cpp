// CPU reference decoder (paper section 4): a conventional view from a CoNUS image, and the plain
// bilinear baseline it is timed against.
//
// Eq. 1 is evaluated by the row stepping of decode_pvt.h, not by SamplingMap::distort: inside a
// span the position advances by a constant step, in 32.32 fixed point where no tap can leave the
// image (four pixels at a time in vector lanes), so a magnified pixel costs about the baseline's
// one bilinear tap with its precomputed per-axis weights. Where
// the view is coarser than the CoNUS image (zoomed out, or a focus seen from afar) the pixel's
// footprint, bounded per map cell, decides how many taps to average over it.
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "conus/codec/image/decode.h"
#include "conus/codec/image/encode.h"
#include "decode_pvt.h"
#include "decode_simd_pvt.h"
#include "conus/core/parallel.h"
#include "resample_pvt.h"

namespace conus::codec {
namespace detail {

ViewColumns viewColumns(int mapColumns, double u0, double u1, int width) {
    ViewColumns c;
    c.cell.resize(width);
    c.s.resize(width);
    c.inside.resize(width);
    const int cells = mapColumns - 1;
    c.firstCell = cells - 1;
    c.lastCell = 0;
    for (int x = 0; x < width; ++x) {
        const double u = u0 + (x + 0.5) / width * (u1 - u0);
        const double uc = std::clamp(u, 0.0, 1.0);
        const double f = uc * cells;
        const int i = std::clamp(static_cast<int>(f), 0, cells - 1);
        c.cell[x] = i;
        c.s[x] = f - i;
        c.inside[x] = (u >= 0.0 && u <= 1.0) ? 1.0 : 0.0;
        c.firstCell = std::min(c.firstCell, i);
        c.lastCell = std::max(c.lastCell, i);
    }
    // s steps by ds per column inside [0,1]; a span restarts where the cell or the clamp changes.
    const double ds = (u1 - u0) / width * cells;
    for (int x = 0; x < width;) {
        ColumnSpan span;
        span.x0 = x;
        span.cell = c.cell[x];
        span.s0 = c.s[x];
        span.inside = c.inside[x] != 0.0;
        span.ds = span.inside ? ds : 0.0;
        while (x < width && c.cell[x] == span.cell && (c.inside[x] != 0.0) == span.inside) ++x;
        span.x1 = x;
        c.spans.push_back(span);
    }
    return c;
}

CellRow cellRow(int mapRows, double v) {
    CellRow r;
    const double vc = std::clamp(v, 0.0, 1.0);
    const double f = vc * (mapRows - 1);
    r.j = std::clamp(static_cast<int>(f), 0, mapRows - 2);
    r.t = f - r.j;
    r.inside = v >= 0.0 && v <= 1.0;
    return r;
}

void rowNodes(const SamplingMap& map, const CellRow& row, int first, int last, glm::dvec2 scale, glm::dvec2 offset,
              RowNodes& out) {
    const std::size_t n = static_cast<std::size_t>(map.columns());
    out.x.resize(n);
    out.y.resize(n);
    out.dx.resize(n);
    out.dy.resize(n);
    for (int i = first; i <= last + 1; ++i) {
        const glm::dvec2 a(map.node(i, row.j)), b(map.node(i, row.j + 1));
        const glm::dvec2 p = a + row.t * (b - a);
        out.x[i] = p.x * scale.x - offset.x;
        out.y[i] = p.y * scale.y - offset.y;
    }
    for (int i = first; i <= last; ++i) {
        out.dx[i] = out.x[i + 1] - out.x[i];
        out.dy[i] = out.y[i + 1] - out.y[i];
    }
}

std::vector<glm::dvec2> distortViewRow(const SamplingMap& map, const View& view, int width, int height, int y) {
    const ViewColumns cols = viewColumns(map.columns(), view.u0, view.u1, width);
    const CellRow row = cellRow(map.rows(), view.v0 + (y + 0.5) / height * (view.v1 - view.v0));
    RowNodes nodes;
    rowNodes(map, row, cols.firstCell, cols.lastCell, glm::dvec2(1.0), glm::dvec2(0.0), nodes);
    std::vector<glm::dvec2> out(width);
    forEachSpan(cols, nodes, [&](const ColumnSpan& span, double px, double py, double sx, double sy) {
        for (int x = span.x0; x < span.x1; ++x, px += sx, py += sy) out[x] = {px, py};
    });
    return out;
}

}  // namespace detail

namespace {

// A footprint longer than this (in CoNUS pixels) on either axis gets several taps.
constexpr double kMultiTapThreshold = kDecodeMultiTap;
constexpr int kMaxTapsPerAxis = kDecodeMaxTaps;
using detail::length;
using detail::tapsFor;
// The pyramid decode's level is 0 (one bilinear tap) up to this footprint: 2^kDecodePyramidBias.
const double kPyramidOneTap = std::exp2(kDecodePyramidBias);

void checkView(const View& v, const char* what) {
    if (!std::isfinite(v.u0) || !std::isfinite(v.u1) || !std::isfinite(v.v0) || !std::isfinite(v.v1) ||
        v.u0 == v.u1 || v.v0 == v.v1 || std::abs(v.u1 - v.u0) > 1e6 || std::abs(v.v1 - v.v0) > 1e6)
        throw Error(ErrorCode::InvalidArgument, std::string(what) + ": view (" + std::to_string(v.u0) + ", " +
                                                    std::to_string(v.v0) + ") - (" + std::to_string(v.u1) + ", " +
                                                    std::to_string(v.v1) + ") is empty or not finite");
}

constexpr detail::TapOffsets<kMaxTapsPerAxis> kTapOffsets;

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
    if constexpr (detail::kLanes<kC> && !kAccumulate) {
        const float* last = pixels + (static_cast<std::size_t>(height) * width - 1) * kC;
        detail::storeLanes<kC>(out, detail::bilinearLanes<kC>(r0, r1, o0, o1, fx, fy, last));
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
[[gnu::always_inline]] inline detail::PixelLanes interiorTapAt(const float* p0, std::size_t stride, float fx,
                                                               float fy) {
    const detail::PixelLanes top = detail::lerpLanes(detail::loadLanes(p0), detail::loadLanes(p0 + kC), fx);
    const detail::PixelLanes bottom =
        detail::lerpLanes(detail::loadLanes(p0 + stride), detail::loadLanes(p0 + stride + kC), fx);
    return detail::lerpLanes(top, bottom, fy);
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
    static_assert(detail::kLanes<kC>);
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
            const detail::PixelLanes v = interiorTapAt<kC>(pixels + go[j], stride, gx[j], gy[j]);
            std::memcpy(o + j * kC, &v, sizeof v);
        }
    }
    // The last one to four pixels, the span's last stored exactly.
    for (int j = 0; k + j < count; ++j) {
        detail::storeLanesInRun<kC>(out + static_cast<std::size_t>(k + j) * kC, tap(j), k + j + 1 < count);
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
        if constexpr (detail::kLanes<kC>) {
            detail::storeLanes<kC>(out, detail::bilinearLanes<kC>(p0, p0 + stride, 0, kC, fx, fy, last));
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

// The levels of a pyramid decode, level 0 first: a biased level-0 coordinate x (see tapBiased)
// is x * sx + ox on a level (pixel edges line up: sx is the level's size over level 0's). Float:
// like the GPU's texture coordinates, 2^-13 pixel or finer on a 4097-pixel side.
struct Level {
    const float* pixels;
    int width, height;
    float sx, sy, ox, oy;
    const float* last;  // the last pixel (bilinearLanes)
};

std::vector<Level> pyramidLevels(const Image& conus, const ImagePyramid* pyramid) {
    const auto last = [](const Image& im) { return im.pixels.data() + im.pixels.size() - im.channels.size(); };
    std::vector<Level> levels{{conus.pixels.data(), conus.width, conus.height, 1.0f, 1.0f, 0.0f, 0.0f, last(conus)}};
    if (!pyramid) return levels;
    for (const Image& l : pyramid->levels) {
        const double sx = double(l.width) / conus.width, sy = double(l.height) / conus.height;
        levels.push_back({l.pixels.data(), l.width, l.height, float(sx), float(sy), float(0.5 - 0.5 * sx),
                          float(0.5 - 0.5 * sy), last(l)});
    }
    return levels;
}

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
inline detail::PixelLanes levelTapLanes(const Level& l, float x, float y) {
    const int xi = static_cast<int>(x), yi = static_cast<int>(y);
    const float fx = x - static_cast<float>(xi), fy = y - static_cast<float>(yi);
    const std::size_t stride = static_cast<std::size_t>(l.width) * kC;
    const float* r0 = l.pixels + static_cast<std::size_t>(std::max(yi - 1, 0)) * stride;
    const float* r1 = l.pixels + static_cast<std::size_t>(std::min(yi, l.height - 1)) * stride;
    return detail::bilinearLanes<kC>(r0, r1, static_cast<std::size_t>(std::max(xi - 1, 0)) * kC,
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
    const Level& a = levels[l];
    detail::PixelLanes value = levelTapLanes<kC>(a, x * a.sx + a.ox, y * a.sy + a.oy);
    if (f > 0.0f) {
        const Level& b = levels[l + 1];
        value = detail::lerpLanes(value, levelTapLanes<kC>(b, x * b.sx + b.ox, y * b.sy + b.oy), f);
    }
    detail::storeLanes<kC>(out, value);
}

// The pyramid decode of a run of pixels in two passes, for 3 and 4 channels: the first plans
// every pixel's taps (level, offsets, weights) 4 or 8 pixels at a time in vector lanes and touches
// no image; the second only loads and blends. One pass per pixel was a chain of ~100 dependent
// cycles (level, coordinates, addresses, then the loads) of which the core overlapped about two
// pixels; split, the second pass has many pixels' loads in flight (bench/README.md, "Decode
// speed"). The operations are trilinearTap's, lane by lane, so the results are the same floats.
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

constexpr int kPlanBlock = 64;  // pixels planned at once (a multiple of 4)

// The taps' rows are prefetched this many output rows ahead. Along an output row the taps follow
// a curve through the CoNUS image that changes row every few pixels where the map bends it, so
// the hardware's stream prefetch rarely locks on (the bilinear baseline reads two rows straight
// through); the next rows' taps lie one footprint b further per output row, and the planner has b.
// Measured on the codec_bench whole frame: 1 and 2 rows ahead alike, 0 (this block) little gain.
constexpr float kPrefetchRows = 2.0f;

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
bool plannable(const Level& level0, int channels) {
    return static_cast<std::int64_t>(level0.width) * level0.height * channels < (std::int64_t{1} << 31);
}

// levelTap's arithmetic on kN pixels of one level (x, y: biased level-0 coordinates).
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
[[gnu::always_inline]] inline detail::PixelLanes plannedTap(const Level& l, const TapPlan& plan, int k) {
    const float* p0 = l.pixels + plan.offset[k];
    const float* p1 = p0 + plan.dy[k];
    return detail::bilinearLanes<kC>(p0, p1, 0, static_cast<std::size_t>(plan.dx[k]), plan.fx[k], plan.fy[k], l.last);
}

// The second pass: loads and blends only.
template <int kC>
[[gnu::always_inline]] inline void decodePlanned(const Level* levels, const PixelPlan& plan, int count, float* out) {
    for (int k = 0; k < count; ++k, out += kC) {
        const int l = plan.level[k];
        detail::PixelLanes value = plannedTap<kC>(levels[l], plan.taps[0], k);
        const float f = plan.blend[k];
        if (f > 0.0f) value = detail::lerpLanes(value, plannedTap<kC>(levels[l + 1], plan.taps[1], k), f);
        detail::storeLanes<kC>(out, value);
    }
}

// plannedTap for a block whose neighbourhoods are all inside: the neighbours are a pixel and a
// row away, so the same loads and operations without the per-pixel steps or the overrun check.
template <int kC>
[[gnu::always_inline]] inline detail::PixelLanes interiorTap(const float* pixels, std::size_t stride,
                                                             const TapPlan& plan, int k) {
    return interiorTapAt<kC>(pixels + plan.offset[k], stride, plan.fx[k], plan.fy[k]);
}

// decodePlanned for a block on one level pair, all inside (PixelPlan::uniform).
template <int kC>
[[gnu::always_inline]] inline void decodeInterior(const Level* levels, const PixelPlan& plan, int count, float* out) {
    const Level& a = levels[plan.uniform];
    const std::size_t sa = static_cast<std::size_t>(a.width) * kC;
    // The block's pixels are written in order, so all but its last may store four lanes.
    const auto store = [&](int k, detail::PixelLanes v) {
        detail::storeLanesInRun<kC>(out + static_cast<std::size_t>(k) * kC, v, k + 1 < count);
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
        const detail::PixelLanes value = interiorTap<kC>(pa, sa, ta, k);
        const detail::PixelLanes blended = detail::lerpLanes(value, interiorTap<kC>(pb, sb, tb, k), f);
        store(k, f > 0.0f ? blended : value);
    }
}

// A block of a span: its plan, then its taps (the arguments are planPixels's, then the output).
template <int kC, int kN>
[[gnu::always_inline]] inline void planAndDecode(const Level* levels, int top, const SpanInputs& in, int k0, int count,
                                                 PixelPlan& plan, float* out) {
    planPixels<kC, kN>(levels, top, in, k0, count, plan);
    if (plan.uniform >= 0) decodeInterior<kC>(levels, plan, count, out);
    else decodePlanned<kC>(levels, plan, count, out);
}

// planAndDecode in two copies, chosen once at run time: the baseline one and, where the compiler
// can make it, one for AVX2 (with FMA and BMI2 it is x86-64-v3; the architecture is kept, so the
// small inline helpers of resample_pvt.h still inline into it). The planner's clamps and selects are then single
// instructions (SSE2 has no 32-bit min, max, blend or multiply), and the tap's addresses come out
// sooner. Floating-point contraction is off for this file (codec/CMakeLists.txt), so the AVX2 copy
// does the same operations in the same order: the same floats (Pyramid.Avx2DecodeMatchesBaseline).
using BlockFn = void (*)(const Level*, int, const SpanInputs&, int, int, PixelPlan&, float*);

template <int kC>
void planAndDecodeBaseline(const Level* levels, int top, const SpanInputs& in, int k0, int count, PixelPlan& plan,
                           float* out) {
    planAndDecode<kC, 4>(levels, top, in, k0, count, plan, out);
}

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define CONUS_DECODE_AVX2 1
template <int kC>
[[gnu::target("avx2,fma,bmi,bmi2")]] void planAndDecodeAvx2(const Level* levels, int top, const SpanInputs& in,
                                                          int k0, int count, PixelPlan& plan, float* out) {
    planAndDecode<kC, 8>(levels, top, in, k0, count, plan, out);
}
#else
#define CONUS_DECODE_AVX2 0
#endif

bool cpuHasAvx2() {
#if CONUS_DECODE_AVX2
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("bmi2");
#else
    return false;
#endif
}

std::atomic<bool> g_forceBaseline{false};

template <int kC>
BlockFn chooseBlockFn() {
#if CONUS_DECODE_AVX2
    static const bool avx2 = cpuHasAvx2();
    if (avx2 && !g_forceBaseline.load(std::memory_order_relaxed)) return &planAndDecodeAvx2<kC>;
#endif
    return &planAndDecodeBaseline<kC>;
}

// kPyramid: zoomed-out pixels take one trilinear tap from `levels` instead of the multi-tap
// average (DecodeOptions::pyramid).
template <int kC, bool kPyramid>
void decodeRows(const Image& src, const SamplingMap& map, const View& view, Image& dst,
                const detail::ViewColumns& cols, const std::vector<Level>& levels, int y0, int y1) {
    const int channels = kC > 0 ? kC : src.channelCount();
    const int W = dst.width, H = dst.height, Wc = src.width, Hc = src.height;
    const int n = map.columns(), m = map.rows();
    const double du = std::abs(view.u1 - view.u0) / W, dv = std::abs(view.v1 - view.v0) / H;
    const std::size_t stride = static_cast<std::size_t>(Wc) * channels;
    detail::RowNodes nodes;
    // Per node column: d(position)/dv over one output pixel, CoNUS pixels. Per cell: footprint
    // along u over one output pixel, and whether any pixel of the cell may need several taps.
    std::vector<double> bx(n), by(n), ax(n), ay(n);
    std::vector<char> multi(n);
    std::vector<float> dynamicAcc(kC > 0 ? 0 : channels);
    float fixedScratch[kC > 0 ? kC : 1];
    std::vector<float> dynamicScratch(kC > 0 ? 0 : channels);
    float* const scratch = kC > 0 ? fixedScratch : dynamicScratch.data();
    const float* pixels = src.pixels.data();
    const float* const last = levels[0].last;
    const bool lanes = detail::kLanes<kC> && lanesFit(Wc, Hc, channels);
    // The pyramid decode's planned blocks (3 and 4 channels).
    const bool planned = kPyramid && detail::kLanes<kC> && plannable(levels[0], channels);
    std::unique_ptr<PixelPlan> plan(planned ? new PixelPlan : nullptr);
    [[maybe_unused]] BlockFn blockFn = nullptr;
    if constexpr (detail::kLanes<kC>) blockFn = chooseBlockFn<kC>();

    for (int y = y0; y < y1; ++y) {
        const detail::CellRow row = detail::cellRow(m, view.v0 + (y + 0.5) / H * (view.v1 - view.v0));
        // CoNUS pixel coordinates plus one (see tapBiased).
        detail::rowNodes(map, row, cols.firstCell, cols.lastCell, glm::dvec2(Wc, Hc), glm::dvec2(-0.5), nodes);
        const double rowInside = row.inside ? 1.0 : 0.0;
        for (int i = cols.firstCell; i <= cols.lastCell + 1; ++i) {
            const glm::dvec2 d = glm::dvec2(map.node(i, row.j + 1)) - glm::dvec2(map.node(i, row.j));
            bx[i] = d.x * (m - 1) * dv * Wc * rowInside;
            by[i] = d.y * (m - 1) * dv * Hc * rowInside;
        }
        for (int i = cols.firstCell; i <= cols.lastCell; ++i) {
            ax[i] = nodes.dx[i] * (n - 1) * du;
            ay[i] = nodes.dy[i] * (n - 1) * du;
            // |b| is convex along the cell, so its larger end bounds it.
            const double lb = std::max(length(bx[i], by[i]), length(bx[i + 1], by[i + 1]));
            multi[i] = std::max(length(ax[i], ay[i]), lb) > (kPyramid ? kPyramidOneTap : kMultiTapThreshold);
        }

        float* const rowOut = dst.pixels.data() + static_cast<std::size_t>(y) * W * channels;
        detail::forEachSpan(cols, nodes, [&](const detail::ColumnSpan& span, double px, double py, double sx,
                                             double sy) {
            const int i = span.cell;
            float* out = rowOut + static_cast<std::size_t>(span.x0) * channels;
            const int count = span.x1 - span.x0;
            if (!multi[i]) {
                // The common case (magnifying): one tap, the position stepped along the span.
                const double pxEnd = px + (count - 1) * sx, pyEnd = py + (count - 1) * sy;
                const double ylo = std::min(py, pyEnd), yhi = std::max(py, pyEnd);
                if (interior(std::min(px, pxEnd), std::max(px, pxEnd), ylo, yhi, Wc, Hc)) {
                    const FixedSteps steps{toFixed(px), toFixed(py), toFixed(sx), toFixed(sy)};
                    // Above the last row, no 4-float read of a 3-channel pixel passes the array's end.
                    if constexpr (detail::kLanes<kC>) {
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
                return;
            }
            const double inside = span.inside ? 1.0 : 0.0;
            const double axp = ax[i] * inside, ayp = ay[i] * inside;
            double s = span.s0;
            if constexpr (kPyramid) {
                // The span's positions, and b along it, in float as the GPU has them.
                const SpanInputs in{static_cast<float>(px),
                                    static_cast<float>(py),
                                    static_cast<float>(sx),
                                    static_cast<float>(sy),
                                    static_cast<float>(axp * axp + ayp * ayp),
                                    static_cast<float>(bx[i] + s * (bx[i + 1] - bx[i])),
                                    static_cast<float>(by[i] + s * (by[i + 1] - by[i])),
                                    static_cast<float>(span.ds * (bx[i + 1] - bx[i])),
                                    static_cast<float>(span.ds * (by[i + 1] - by[i]))};
                const int top = static_cast<int>(levels.size()) - 1;
                if constexpr (detail::kLanes<kC>) {
                    if (planned) {
                        for (int k0 = 0; k0 < count; k0 += kPlanBlock) {
                            const int n = std::min(kPlanBlock, count - k0);
                            blockFn(levels.data(), top, in, k0, n, *plan, out);
                            out += static_cast<std::size_t>(n) * kC;
                        }
                        return;
                    }
                }
                for (int k = 0; k < count; ++k, out += channels) {
                    if constexpr (detail::kLanes<kC>)
                        trilinearTapLanes<kC>(levels.data(), top, in.xAt(k), in.yAt(k), in.rho2At(k), out);
                    else
                        trilinearTap<kC>(levels.data(), top, channels, in.xAt(k), in.yAt(k), in.rho2At(k), out,
                                         scratch);
                }
                return;
            }
            const int na = tapsFor(length(axp, ayp));
            for (int k = 0; k < count; ++k, px += sx, py += sy, s += span.ds, out += channels) {
                const double bxp = bx[i] + s * (bx[i + 1] - bx[i]), byp = by[i] + s * (by[i + 1] - by[i]);
                const int nb = tapsFor(length(bxp, byp));
                if (na == 1 && nb == 1) {
                    tapBiased<kC, true, false>(pixels, Wc, Hc, channels, px, py, 1.0f, out);
                    continue;
                }
                // Average na x nb taps over the footprint parallelogram of the output pixel.
                const float weight = 1.0f / static_cast<float>(na * nb);
                float fixedAcc[kC > 0 ? kC : 1];
                float* acc = kC > 0 ? fixedAcc : dynamicAcc.data();
                for (int c = 0; c < channels; ++c) acc[c] = 0.0f;
                const double* oa = kTapOffsets.at[na];
                const double* ob = kTapOffsets.at[nb];
                const double ex = std::abs(axp) * 0.5 + std::abs(bxp) * 0.5, ey = std::abs(ayp) * 0.5 + std::abs(byp) * 0.5;
                const bool inner = interior(px - ex, px + ex, py - ey, py + ey, Wc, Hc);
                for (int jb = 0; jb < nb; ++jb) {
                    const double qx = px + bxp * ob[jb], qy = py + byp * ob[jb];
                    for (int ia = 0; ia < na; ++ia) {
                        const double tx = qx + axp * oa[ia], ty = qy + ayp * oa[ia];
                        if (inner) tapBiased<kC, false, true>(pixels, Wc, Hc, channels, tx, ty, weight, acc);
                        else
                            tapBiased<kC, true, true>(pixels, Wc, Hc, channels, std::clamp(tx, 0.5, Wc + 0.5),
                                                      std::clamp(ty, 0.5, Hc + 0.5), weight, acc);
                    }
                }
                for (int c = 0; c < channels; ++c) out[c] = acc[c];
            }
        });
    }
}

// Per-axis bilinear taps of the baseline, precomputed like the decoder's view columns.
struct AxisTaps {
    std::vector<int> i0, i1;
    std::vector<float> f;
};

AxisTaps axisTaps(int size, double a0, double a1, int count) {
    AxisTaps t;
    t.i0.resize(count);
    t.i1.resize(count);
    t.f.resize(count);
    for (int k = 0; k < count; ++k) {
        const double a = std::clamp(a0 + (k + 0.5) / count * (a1 - a0), 0.0, 1.0);
        const double p = a * size - 0.5;
        const int i = detail::floorToInt(p);
        t.f[k] = static_cast<float>(p - i);
        t.i0[k] = std::max(i, 0);
        t.i1[k] = std::min(i + 1, size - 1);
    }
    return t;
}

template <int kC>
void bilinearRows(const Image& src, Image& dst, const AxisTaps& tx, const AxisTaps& ty, int y0,
                  int y1) {
    const int channels = kC > 0 ? kC : src.channelCount();
    const std::size_t stride = static_cast<std::size_t>(src.width) * channels;
    for (int y = y0; y < y1; ++y) {
        const float* r0 = src.pixels.data() + ty.i0[y] * stride;
        const float* r1 = src.pixels.data() + ty.i1[y] * stride;
        const float fy = ty.f[y];
        float* out = dst.pixels.data() + static_cast<std::size_t>(y) * dst.width * channels;
        if constexpr (detail::kLanes<kC>) {
            // As the decoder's magnified spans: every pixel but the row's last stores four lanes (the
            // next pixel overwrites the fourth).
            const float* last = src.pixels.data() + src.pixels.size() - kC;
            const int wide = kC == 4 ? dst.width : dst.width - 1;
            for (int x = 0; x < wide; ++x, out += kC) {
                const detail::PixelLanes v = detail::bilinearLanes<kC>(r0, r1, std::size_t(tx.i0[x]) * kC,
                                                                       std::size_t(tx.i1[x]) * kC, tx.f[x], fy, last);
                std::memcpy(out, &v, sizeof v);
            }
            for (int x = wide; x < dst.width; ++x, out += kC)
                detail::storeLanes<kC>(out, detail::bilinearLanes<kC>(r0, r1, std::size_t(tx.i0[x]) * kC,
                                                                      std::size_t(tx.i1[x]) * kC, tx.f[x], fy, last));
            continue;
        }
        for (int x = 0; x < dst.width; ++x, out += channels) {
            const int o0 = tx.i0[x] * channels, o1 = tx.i1[x] * channels;
            const float fx = tx.f[x];
            for (int k = 0; k < channels; ++k) {
                const float top = r0[o0 + k] + fx * (r0[o1 + k] - r0[o0 + k]);
                const float bottom = r1[o0 + k] + fx * (r1[o1 + k] - r1[o0 + k]);
                out[k] = top + fy * (bottom - top);
            }
        }
    }
}

// The run [first, last) of the indices k < count whose centre a0 + (k + 0.5) / count * (a1 - a0)
// lies in [0, 1]: one run, as the centres are monotone in k (empty: first == last).
std::pair<int, int> insideRun(double a0, double a1, int count) {
    const auto inside = [&](int k) {
        const double a = a0 + (k + 0.5) / count * (a1 - a0);
        return a >= 0.0 && a <= 1.0;
    };
    int first = 0;
    while (first < count && !inside(first)) ++first;
    int last = first;
    while (last < count && inside(last)) ++last;
    return {first, last};
}

// Pixels whose centre lies outside the image ([0,1]^2 undistorted) show the background, 0 in every
// channel, instead of the edge pixels smeared outward. Only those pixels are touched: a view
// inside the image costs nothing here.
void clearOutside(Image& out, const View& view) {
    const std::size_t c = out.channels.size();
    const std::size_t rowValues = static_cast<std::size_t>(out.width) * c;
    const auto [x0, x1] = insideRun(view.u0, view.u1, out.width);
    const auto [y0, y1] = insideRun(view.v0, view.v1, out.height);
    for (int y = 0; y < out.height; ++y) {
        float* row = out.pixels.data() + y * rowValues;
        if (y < y0 || y >= y1 || x0 == x1) {
            std::fill(row, row + rowValues, 0.0f);
            continue;
        }
        std::fill(row, row + x0 * c, 0.0f);
        std::fill(row + x1 * c, row + rowValues, 0.0f);
    }
}

}  // namespace

namespace detail {

bool decodeAvx2Available() { return cpuHasAvx2(); }
void forceBaselineDecode(bool baseline) { g_forceBaseline.store(baseline, std::memory_order_relaxed); }

}  // namespace detail

float pyramidLevel(float rhoSquared) {
    if (!(rhoSquared > 1.0f)) return 0.0f;  // magnified (or NaN): level 0

    std::uint32_t bits;
    std::memcpy(&bits, &rhoSquared, sizeof bits);
    const int exponent = static_cast<int>(bits >> 23) - 127;
    const std::uint32_t mantissaBits = (bits & 0x7fffffu) | 0x3f800000u;
    float mantissa;
    std::memcpy(&mantissa, &mantissaBits, sizeof mantissa);
    const float t = mantissa - 1.0f;  // log2(1 + t) ~ t (1.3465553 - 0.3465553 t), exact at t = 0 and 1
    return std::max(0.0f, 0.5f * (static_cast<float>(exponent) + t * (1.3465553f - 0.3465553f * t)) -
                              static_cast<float>(kDecodePyramidBias));
}

bool viewZoomsOut(const Image& conus, const SamplingMap& map, const View& view, int width, int height) {
    checkView(view, "viewZoomsOut");
    detail::checkOutputSize(width, height, "viewZoomsOut");
    const int n = map.columns(), m = map.rows();
    // Output pixels per map cell along u and v; the cells the view covers (clamped like Eq. 1).
    const double du = std::abs(view.u1 - view.u0) / width * (n - 1), dv = std::abs(view.v1 - view.v0) / height * (m - 1);
    const auto cells = [](double a, double b, int count) {
        const double lo = std::clamp(std::min(a, b), 0.0, 1.0), hi = std::clamp(std::max(a, b), 0.0, 1.0);
        return std::pair{std::clamp(static_cast<int>(lo * count), 0, count - 1),
                         std::clamp(static_cast<int>(hi * count), 0, count - 1)};
    };
    const auto [i0, i1] = cells(view.u0, view.u1, n - 1);
    const auto [j0, j1] = cells(view.v0, view.v1, m - 1);
    const glm::dvec2 scale(conus.width, conus.height);
    double longest2 = 0;  // the longest footprint edge, squared: |a| and |b| are largest on a cell's edges
    for (int j = j0; j <= j1 + 1; ++j)
        for (int i = i0; i <= i1 + 1; ++i) {
            const glm::dvec2 p = glm::dvec2(map.node(i, j)) * scale;
            if (i <= i1) {
                const glm::dvec2 a = (glm::dvec2(map.node(i + 1, j)) * scale - p) * du;
                longest2 = std::max(longest2, a.x * a.x + a.y * a.y);
            }
            if (j <= j1) {
                const glm::dvec2 b = (glm::dvec2(map.node(i, j + 1)) * scale - p) * dv;
                longest2 = std::max(longest2, b.x * b.x + b.y * b.y);
            }
        }
    return longest2 > kPyramidOneTap * kPyramidOneTap;
}

void checkPyramid(const Image& conus, const ImagePyramid& pyramid) {
    int w = conus.width, h = conus.height;
    for (const Image& level : pyramid.levels) {
        w = std::max(1, w / 2);
        h = std::max(1, h / 2);
        if (level.width != w || level.height != h || level.channels != conus.channels ||
            level.pixels.size() != static_cast<std::size_t>(w) * h * conus.channels.size())
            throw Error(ErrorCode::InvalidArgument, "decode: the pyramid was not built from a " +
                                                        std::to_string(conus.width) + "x" +
                                                        std::to_string(conus.height) + " image with these channels");
    }
    if (w != 1 || h != 1)
        throw Error(ErrorCode::InvalidArgument, "decode: the pyramid stops before 1x1");
}

ImagePyramid buildPyramid(const Image& conus, int threads) {
    checkImage(conus, "buildPyramid");
    ImagePyramid pyramid;
    const Image* previous = &conus;
    while (previous->width > 1 || previous->height > 1) {
        pyramid.levels.push_back(
            areaDownsample(*previous, std::max(1, previous->width / 2), std::max(1, previous->height / 2), threads));
        previous = &pyramid.levels.back();
    }
    return pyramid;
}

void checkDecodeMemory(const Image& conus, int width, int height, std::int64_t maxBytes, bool withPyramid,
                       std::int64_t extraBytes) {
    const std::int64_t channels = conus.channelCount();
    const std::int64_t image = std::int64_t{conus.width} * conus.height;
    const std::int64_t bytes = (image + (withPyramid ? image / 3 : 0) + std::int64_t{width} * height) * channels *
                                   std::int64_t(sizeof(float)) +
                               extraBytes;
    if (bytes > maxBytes) {
        throw Error(ErrorCode::LimitExceeded,
                    "decoding a " + std::to_string(conus.width) + "x" + std::to_string(conus.height) + " image to " +
                        std::to_string(width) + "x" + std::to_string(height) + " pixels of " + std::to_string(channels) +
                        " channels" + (withPyramid ? std::string(" with its pyramid") : std::string()) +
                        (extraBytes > 0 ? " and the picture writer's copies" : "") + " takes " +
                        std::to_string(bytes) + " bytes, beyond the decode memory limit of " +
                        std::to_string(maxBytes));
    }
}

Image decodeImage(const Image& conus, const SamplingMap& map, const DecodeOptions& options) {
    checkImage(conus, "decodeImage");
    detail::checkOutputSize(options.width, options.height, "decodeImage");
    checkDecodeMemory(conus, options.width, options.height, kMaxDecodeBytes, options.pyramid != nullptr);
    checkView(options.view, "decodeImage");
    if (options.pyramid) checkPyramid(conus, *options.pyramid);
    const std::vector<Level> levels = pyramidLevels(conus, options.pyramid);
    Image out = detail::makeOutput(conus, options.width, options.height);
    const detail::ViewColumns cols = detail::viewColumns(map.columns(), options.view.u0, options.view.u1, out.width);
    detail::RowProgress progress(options.progress, out.height);
    parallelRows(
        out.height, options.threads,
        [&](int y0, int y1) {
            detail::dispatchChannels(conus.channelCount(), [&]<int kC>() {
                if (options.pyramid) decodeRows<kC, true>(conus, map, options.view, out, cols, levels, y0, y1);
                else decodeRows<kC, false>(conus, map, options.view, out, cols, levels, y0, y1);
            });
            progress.add(y1 - y0);
        },
        16);
    clearOutside(out, options.view);
    return out;
}

Image resizeBilinear(const Image& image, const View& view, int width, int height, int threads) {
    checkImage(image, "resizeBilinear");
    detail::checkOutputSize(width, height, "resizeBilinear");
    checkDecodeMemory(image, width, height);
    checkView(view, "resizeBilinear");
    Image out = detail::makeOutput(image, width, height);
    const AxisTaps tx = axisTaps(image.width, view.u0, view.u1, width);
    const AxisTaps ty = axisTaps(image.height, view.v0, view.v1, height);
    parallelRows(
        height, threads,
        [&](int y0, int y1) {
            detail::dispatchChannels(image.channelCount(),
                                     [&]<int kC>() { bilinearRows<kC>(image, out, tx, ty, y0, y1); });
        },
        16);
    clearOutside(out, view);
    return out;
}

}  // namespace conus::codec
