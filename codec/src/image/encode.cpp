// CPU reference encoder (paper section 3.2); the area-downsample baseline is area_downsample.cpp.
//
// Each CoNUS pixel filters the source over its footprint (encode.h states the rule), by one of two
// kernels (EncodeFilter). The EWA filter: a grid of bilinear taps in the pixel's own units (s,t),
// carried into the source through the local inverse Jacobian (FootprintField), weighted by the unit
// box convolved with a Gaussian along the footprint's major axis; a square footprint has no
// Gaussian, and with the identity map and an integer ratio the taps land exactly on source pixel
// centres, so the result is the exact area average. The anisotropic kernel: the same footprint's
// principal axes, the minor one filtered by the pyramid level it picks, a row of taps along the
// major one; exact at power-of-two ratios.
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <iterator>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "conus/codec/image/encode.h"
#include "area_downsample_pvt.h"
#include "cpu_features_pvt.h"
#include "conus/core/parallel.h"
#include "encode_pvt.h"
#include "encode_pyramid_pvt.h"
#include "encode_taps_pvt.h"
#include "resample_pvt.h"

namespace conus::codec {
namespace {

constexpr int kMaxTapsPerAxis = kEncodeMaxTaps;  // encode.h says why (the minor axis's bound)
constexpr double kTapTolerance = kEncodeTapTolerance;

using detail::areaDownsamplePlane;
using detail::Plane;
using detail::Float4;
using detail::load4;
using detail::Pyramid;
using detail::RowTaps;
using detail::TapRow;

// The footprint filter of encode.h: the unit box in CoNUS pixel units (s,t), convolved with a
// Gaussian of standard deviation `sigma` along the unit direction `major` (sigma 0: the plain box).
struct FootprintFilter {
    double sigma = 0;
    glm::dvec2 major{1.0, 0.0};
    double reach = 0;  // the Gaussian's cut, kEncodeGaussianReach * sigma
};

// a and b are the footprint's edges (source pixels per CoNUS pixel along x and y); the singular
// values of [a b] are the footprint's major and minor lengths, the right singular vectors their
// directions in CoNUS pixel units; `uniform` the uniform image's pixel (encode.h).
FootprintFilter footprintFilter(glm::dvec2 a, glm::dvec2 b, double uniform, double& minor) {
    const double p = glm::dot(a, a), q = glm::dot(a, b), r = glm::dot(b, b);
    const double mean = 0.5 * (p + r), half = std::sqrt(0.25 * (p - r) * (p - r) + q * q);
    const double l1 = mean + half, l2 = std::max(0.0, mean - half);
    minor = std::sqrt(l2);
    FootprintFilter f;
    if (!(l1 > 0)) return f;
    const double ramp = std::min(1.0 - kEncodeBoxAnisotropy * std::sqrt(l2 / l1), 1.0 - uniform / std::sqrt(l1));
    f.sigma = kEncodeAnisotropicSigma * std::max(0.0, ramp);
    f.reach = kEncodeGaussianReach * f.sigma;
    // The eigenvector of [[p q] [q r]] for l1, from whichever row is better conditioned; it only
    // matters where sigma is not negligible, i.e. where l1 and l2 differ.
    const glm::dvec2 e1(q, l1 - p), e2(l1 - r, q);
    const glm::dvec2 e = glm::dot(e1, e1) >= glm::dot(e2, e2) ? e1 : e2;
    const double len = glm::length(e);
    f.major = len > 0 ? e / len : glm::dvec2(1.0, 0.0);
    return f;
}

// Extent of the filter along s and t (CoNUS pixels): the box, widened by the Gaussian's reach.
glm::dvec2 filterExtent(const FootprintFilter& f) {
    return {1.0 + 2.0 * f.reach * std::abs(f.major.x), 1.0 + 2.0 * f.reach * std::abs(f.major.y)};
}

// The continuous pyramid level: where the minor axis is kEncodeMaxTaps texels, or the filter's
// extent along an edge kEncodeMaxAxisTaps, whichever is coarser; 0 at least. Blending the levels
// around it keeps the blur from jumping where a footprint crosses a level.
double footprintLevel(glm::dvec2 a, glm::dvec2 b, double minor, glm::dvec2 extent) {
    const double tol = kTapTolerance;
    const double coarsest = std::max({minor / (kMaxTapsPerAxis + tol),
                                      glm::length(a) * extent.x / (kEncodeMaxAxisTaps + tol),
                                      glm::length(b) * extent.y / (kEncodeMaxAxisTaps + tol), 1.0});
    return std::log2(coarsest);
}

// Functions whose loops vectorize get a copy for x86-64-v3 (AVX2) besides the baseline one; the
// loader picks one by the processor (an ifunc). That copy may fuse multiply-adds, so weights can
// differ in their last bits from one processor to another (~1e-16). Taken off where the
// toolchain may lack it.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && defined(__linux__)
#define CONUS_VECTOR_CLONES __attribute__((target_clones("arch=x86-64-v3", "default")))
#else
#define CONUS_VECTOR_CLONES
#endif

// The footprint's geometry on one level: the tap grid of encode.h and where it lies.
struct TapGrid {
    glm::dvec2 aL, bL;      // the footprint's edges in this level's texels
    double cx = 0, cy = 0;  // its centre, texel coordinates
    int ns = 1, nt = 1;
    double ds = 1, dt = 1, s0 = 0, t0 = 0;
};

// Grid row j of the box filter (sigma 0): the extent is the unit box itself and every tap weighs
// the same.
void boxRow(const TapGrid& g, int j, RowTaps& r) {
    const double t = g.t0 + j * g.dt;
    const double rx = g.cx + g.bL.x * t + g.aL.x * g.s0, ry = g.cy + g.bL.y * t + g.aL.y * g.s0;
    const double w = 1.0f / static_cast<float>(g.ns * g.nt);  // a float, as the taps take it
    r.count = g.ns;
    for (int i = 0; i < g.ns; ++i) {
        r.x[i] = rx + g.aL.x * (i * g.ds);
        r.y[i] = ry + g.aL.y * (i * g.ds);
        r.weight[i] = w;
    }
}

// A tap's weight is the Gaussian's mass over the offsets o along the major axis that keep the tap
// in the unit box: the intersection of its column's slab (from s) and its row's (from t), within
// the reach. erf is monotonic, so erf at the intersection's ends is the max / min of the slabs'
// erf: each column's and each row's two erf are taken once per footprint, not two for every tap.
struct Slabs {
    double lo[RowTaps::kMax], hi[RowTaps::kMax];         // hi <= lo: empty
    double erfLo[RowTaps::kMax], erfHi[RowTaps::kMax];  // erf(k lo), erf(k hi)
};

// The slabs of n grid lines at u = first + i * step: the offsets o for which u - o m lies in
// [-0.5, 0.5] (m the major axis's component along u), within [-reach, reach]. Where m ~ 0 a line
// within the unit box takes the whole reach and any other nothing. Most of the encoder's
// arithmetic (two erf polynomials a line): on a processor with AVX2 a second copy of it takes
// four lines at a time (CONUS_VECTOR_CLONES).
CONUS_VECTOR_CLONES void gaussianSlabs(double first, double step, int n, double m, double reach, double k,
                                       Slabs& out) {
    // (Selects, not std::min/max: those kept the loops from vectorizing.)
    if (std::abs(m) >= 1e-9) {
        const double inverse = 1.0 / m;
        for (int i = 0; i < n; ++i) {
            const double u = first + i * step;
            const double o1 = (u - 0.5) * inverse, o2 = (u + 0.5) * inverse;
            const double lo = o1 < o2 ? o1 : o2, hi = o1 < o2 ? o2 : o1;
            out.lo[i] = lo > -reach ? lo : -reach;
            out.hi[i] = hi < reach ? hi : reach;
        }
    } else {
        for (int i = 0; i < n; ++i) {
            out.lo[i] = -reach;
            out.hi[i] = std::abs(first + i * step) <= 0.5 ? reach : -reach;
        }
    }
    for (int i = 0; i < n; ++i) {
        out.erfLo[i] = detail::erfOnReach(out.lo[i] * k);
        out.erfHi[i] = detail::erfOnReach(out.hi[i] * k);
    }
}

// Grid row j of the Gaussian filter from the grid's column and row slabs: only the taps that can
// weigh anything (count 0 if none).
CONUS_VECTOR_CLONES void gaussianRow(const TapGrid& g, const FootprintFilter& filter, const Slabs& columns,
                                     const Slabs& rows, int j, RowTaps& r) {
    r.count = 0;
    const double rowLo = rows.lo[j], rowHi = rows.hi[j];
    if (rowHi <= rowLo) return;
    const double t = g.t0 + j * g.dt;
    const double rx = g.cx + g.bL.x * t, ry = g.cy + g.bL.y * t;
    const double mx = filter.major.x;
    // Only taps whose s slab meets the row's offsets weigh anything: s within 0.5 of
    // [rowLo, rowHi] * major.x. A diagonal footprint's grid is mostly outside that strip.
    int i0 = 0, i1 = g.ns;
    if (std::abs(mx) >= 1e-9) {
        const double m0 = rowLo * mx, m1 = rowHi * mx;
        const double sLo = std::min(m0, m1) - 0.5, sHi = std::max(m0, m1) + 0.5;
        i0 = std::max(0, static_cast<int>(std::floor((sLo - g.s0) / g.ds)));
        i1 = std::min(g.ns, static_cast<int>(std::ceil((sHi - g.s0) / g.ds)) + 1);
    }
    if (i1 <= i0) return;
    r.count = i1 - i0;
    const double rowErfLo = rows.erfLo[j], rowErfHi = rows.erfHi[j];
    for (int n = 0; n < r.count; ++n) {
        const int i = i0 + n;
        const double lo = rowLo < columns.lo[i] ? columns.lo[i] : rowLo;
        const double hi = columns.hi[i] < rowHi ? columns.hi[i] : rowHi;
        const double erfLo = rowErfLo < columns.erfLo[i] ? columns.erfLo[i] : rowErfLo;
        const double erfHi = columns.erfHi[i] < rowErfHi ? columns.erfHi[i] : rowErfHi;
        r.weight[n] = hi > lo ? 0.5 * (erfHi - erfLo) : 0.0;
        const double s = g.s0 + i * g.ds;
        r.x[n] = rx + g.aL.x * s;
        r.y[n] = ry + g.aL.y * s;
    }
}

// The row's taps, bilinear, weighted, added to acc, their weights to total: detail::
// addBilinearInterior's arithmetic, the same operations in the same order, on all channels at once.
// Each of the 2x2 texels is read as four floats from its first channel: the caller keeps the taps
// a row away from the last one.
template <int kC>
void accumulateRow(const float* pixels, std::size_t stride, const RowTaps& r, Float4& acc, double& total) {
    int xi[RowTaps::kMax], yi[RowTaps::kMax];
    float fx[RowTaps::kMax], fy[RowTaps::kMax];
    for (int n = 0; n < r.count; ++n) {
        xi[n] = static_cast<int>(r.x[n]);
        yi[n] = static_cast<int>(r.y[n]);
        fx[n] = static_cast<float>(r.x[n] - xi[n]);
        fy[n] = static_cast<float>(r.y[n] - yi[n]);
    }
    for (int n = 0; n < r.count; ++n) {
        if (r.weight[n] <= 0) continue;
        total += r.weight[n];
        const float* p0 = pixels + yi[n] * stride + static_cast<std::size_t>(xi[n]) * kC;
        const float* p1 = p0 + stride;
        const Float4 a = load4(p0), b = load4(p1);
        const Float4 top = a + fx[n] * (load4(p0 + kC) - a);
        const Float4 bottom = b + fx[n] * (load4(p1 + kC) - b);
        acc += static_cast<float>(r.weight[n]) * (top + fy[n] * (bottom - top));
    }
}

// detail::forceBaselineEncode: the baseline tap loop even where AVX2 is there (tests compare them).
std::atomic<bool> g_forceBaselineEncode{false};

template <int kC>
void tapRow(const float* pixels, std::size_t stride, const TapRow& row, Float4& acc) {
#if CONUS_HAVE_AVX2_COPY
    static const bool avx2 = detail::cpuHasAvx2();
    if (avx2 && !g_forceBaselineEncode.load(std::memory_order_relaxed)) return detail::tapRowAvx2<kC>(pixels, stride, row, acc);
#endif
    detail::tapRowBaseline<kC>(pixels, stride, row, acc);
}

// The filtered value on one level, normalized, written to out. The taps are encode.h's grid
// (ns x nt, at slice centres over the filter's extent), a row at a time.
template <int kC>
void filterOnLevel(Pyramid& pyramid, int level, int threads, int channels, const Image& src, glm::dvec2 p,
                   glm::dvec2 a, glm::dvec2 b, const FootprintFilter& filter, glm::dvec2 extent, float* out) {
    const Plane img = pyramid.level(level, threads);
    const glm::dvec2 scale(double(img.width) / src.width, double(img.height) / src.height);
    TapGrid g;
    g.aL = a * scale;
    g.bL = b * scale;
    // Taps at most a texel apart along each edge; the cap only bounds rounding and degenerate maps.
    g.ns = std::clamp(static_cast<int>(std::ceil(glm::length(g.aL) * extent.x - kTapTolerance)), 1, RowTaps::kMax);
    g.nt = std::clamp(static_cast<int>(std::ceil(glm::length(g.bL) * extent.y - kTapTolerance)), 1, RowTaps::kMax);
    g.cx = p.x * img.width - 0.5;
    g.cy = p.y * img.height - 0.5;
    g.ds = extent.x / g.ns;
    g.dt = extent.y / g.nt;
    g.s0 = 0.5 * g.ds - 0.5 * extent.x;
    g.t0 = 0.5 * g.dt - 0.5 * extent.y;
    constexpr double kMinSigma = 1e-4;  // below it the filter is the plain box (encode.h)
    const bool box = filter.sigma < kMinSigma;
    const double k = box ? 0.0 : 1.0 / (std::sqrt(2.0) * filter.sigma);
    // Away from the borders no tap needs clamping: decide once for the whole footprint.
    const double ex = 0.5 * (std::abs(g.aL.x) * extent.x + std::abs(g.bL.x) * extent.y);
    const double ey = 0.5 * (std::abs(g.aL.y) * extent.x + std::abs(g.bL.y) * extent.y);
    const bool inner = g.cx - ex >= 0 && g.cx + ex < img.width - 1 && g.cy - ey >= 0 && g.cy + ey < img.height - 1;
    pyramid.ensureRows(level, g.cy - ey, g.cy + ey);
    const std::size_t stride = static_cast<std::size_t>(img.width) * channels;
    RowTaps r;
    Slabs columns, rows;
    if (!box) {
        gaussianSlabs(g.s0, g.ds, g.ns, filter.major.x, filter.reach, k, columns);
        gaussianSlabs(g.t0, g.dt, g.nt, filter.major.y, filter.reach, k, rows);
    }
    double total = 0;  // the sum of the weights taken
    const auto row = [&](int j) {
        if (box) boxRow(g, j, r);
        else gaussianRow(g, filter, columns, rows, j, r);
    };
    // All channels in one register where the footprint stays a row clear of the last one (the
    // four-float reads of the bottom row's texels stay inside the level).
    if constexpr (kC > 0 && kC <= 4) {
        // (One channel on a level two texels wide: the right texel's four floats would reach one
        // past the level's last row, so that case takes the per-channel path.)
        if (inner && g.cy + ey < img.height - 2 && (kC >= 2 || img.width >= 3)) {
            Float4 acc{0.0f, 0.0f, 0.0f, 0.0f};
            for (int j = 0; j < g.nt; ++j) {
                row(j);
                accumulateRow<kC>(img.data, stride, r, acc, total);
            }
            const float norm = box ? 1.0f : total > 0 ? static_cast<float>(1.0 / total) : 0.0f;
            for (int c = 0; c < kC; ++c) out[c] = box ? acc[c] : acc[c] * norm;
            return;
        }
    }
    for (int c = 0; c < channels; ++c) out[c] = 0.0f;
    for (int j = 0; j < g.nt; ++j) {
        row(j);
        for (int n = 0; n < r.count; ++n) {
            const float w = static_cast<float>(r.weight[n]);
            if (r.weight[n] <= 0) continue;
            total += r.weight[n];
            if (inner) detail::addBilinearInterior<kC>(img.data, stride, channels, r.x[n], r.y[n], w, out);
            else detail::addBilinear<kC>(img.data, img.width, img.height, channels, r.x[n], r.y[n], w, out);
        }
    }
    if (box) return;
    const float norm = total > 0 ? static_cast<float>(1.0 / total) : 0.0f;
    for (int c = 0; c < channels; ++c) out[c] *= norm;
}

// The anisotropic kernel's footprint (encode.h, EncodeFilter::Anisotropic): one CoNUS pixel along
// the major and the minor singular directions, carried into level-0 source pixels.
struct PrincipalAxes {
    glm::dvec2 major{0.0}, minor{0.0};
};

PrincipalAxes principalAxes(glm::dvec2 a, glm::dvec2 b, const FootprintFilter& filter) {
    const glm::dvec2 v1 = filter.major, v2(-filter.major.y, filter.major.x);
    return {a * v1.x + b * v1.y, a * v2.x + b * v2.y};
}

// The continuous level of the anisotropic kernel: where the minor axis is
// kEncodeAnisotropicMinorTexels texels, or coarser where the major axis's extent would need more
// than kEncodeAnisotropicMaxTaps taps; 0 at least.
double anisotropicLevel(const PrincipalAxes& axes, const FootprintFilter& filter) {
    const double tol = kTapTolerance;
    const double extent = 1.0 + 2.0 * filter.reach;
    const double coarsest = std::max({glm::length(axes.minor) / (kEncodeAnisotropicMinorTexels + tol),
                                      glm::length(axes.major) * extent / (kEncodeAnisotropicMaxTaps + tol), 1.0});
    return std::log2(coarsest);
}

// The weights of nu taps at u0 + i du along the major axis (u0 = -(nu - 1) du / 2: symmetric about
// the centre): the Gaussian's mass (erf at k times the offset) over the offsets within the reach
// that keep a tap in the unit box. Symmetric, so half of them are computed and mirrored; the
// polynomial erf is most of a footprint's arithmetic, and an AVX2 copy takes four taps at a time.
CONUS_VECTOR_CLONES void majorWeights(double u0, double du, int nu, double reach, double k, float* weight) {
    const int half = (nu + 1) / 2;
    const float u0f = static_cast<float>(u0), duf = static_cast<float>(du);
    const float reachf = static_cast<float>(reach), kf = static_cast<float>(k);
    for (int i = 0; i < half; ++i) {
        const float u = u0f + static_cast<float>(i) * duf;
        const float lo = u - 0.5f > -reachf ? u - 0.5f : -reachf, hi = u + 0.5f < reachf ? u + 0.5f : reachf;
        const float w = detail::erfOnReachFloat(hi * kf) - detail::erfOnReachFloat(lo * kf);
        weight[i] = hi > lo ? w : 0.0f;
    }
    for (int i = half; i < nu; ++i) weight[i] = weight[nu - 1 - i];
}

// The anisotropic kernel on one level, normalized, written to out: nw rows of taps across the
// minor axis (slice centres of the unit box), each of nu taps along the major axis (slice centres
// of the box widened by the Gaussian's reach), taps at most a texel apart. A tap's weight is the
// truncated Gaussian's mass over the offsets that keep it in the unit box, as in the EWA filter.
template <int kC>
void anisotropicOnLevel(Pyramid& pyramid, int level, int threads, int channels, const Image& src, glm::dvec2 p,
                        const PrincipalAxes& axes, const FootprintFilter& filter, float* out) {
    const Plane img = pyramid.level(level, threads);
    const glm::dvec2 scale(double(img.width) / src.width, double(img.height) / src.height);
    const glm::dvec2 major = axes.major * scale, minor = axes.minor * scale;
    const double extent = 1.0 + 2.0 * filter.reach;
    const int nu = std::clamp(static_cast<int>(std::ceil(glm::length(major) * extent - kTapTolerance)), 1, RowTaps::kMax);
    const int nw = std::clamp(static_cast<int>(std::ceil(glm::length(minor) - kTapTolerance)), 1, RowTaps::kMax);
    const double du = extent / nu, dw = 1.0 / nw;
    const double u0 = 0.5 * du - 0.5 * extent, w0 = 0.5 * dw - 0.5;
    constexpr double kMinSigma = 1e-4;  // below it the filter is the plain box (encode.h)
    float weight[RowTaps::kMax];
    if (filter.sigma < kMinSigma) {
        for (int i = 0; i < nu; ++i) weight[i] = 1.0f;
    } else {
        majorWeights(u0, du, nu, filter.reach, 1.0 / (std::sqrt(2.0) * filter.sigma), weight);
    }
    const double cx = p.x * img.width - 0.5, cy = p.y * img.height - 0.5;
    // Away from the borders no tap needs clamping: decide once for the whole footprint.
    const double ex = 0.5 * (std::abs(major.x) * extent + std::abs(minor.x));
    const double ey = 0.5 * (std::abs(major.y) * extent + std::abs(minor.y));
    const bool inner = cx - ex >= 0 && cx + ex < img.width - 1 && cy - ey >= 0 && cy + ey < img.height - 1;
    pyramid.ensureRows(level, cy - ey, cy + ey);
    const std::size_t stride = static_cast<std::size_t>(img.width) * channels;
    RowTaps r;
    double total = 0;
    const auto row = [&](int j) {
        const double w = w0 + j * dw;
        const double rx = cx + minor.x * w + major.x * u0, ry = cy + minor.y * w + major.y * u0;
        r.count = nu;
        for (int i = 0; i < nu; ++i) {
            r.x[i] = rx + major.x * (i * du);
            r.y[i] = ry + major.y * (i * du);
            r.weight[i] = weight[i];
        }
    };
    if constexpr (kC > 0 && kC <= 4) {
        // (The four-float reads of the taps: see filterOnLevel.) Every row has the same weights:
        // the taps that weigh anything (a run about the centre) and their sum are found once.
        if (inner && cy + ey < img.height - 2 && (kC >= 2 || img.width >= 3)) {
            int i0 = 0, i1 = nu;
            while (i0 < i1 && weight[i0] <= 0) ++i0;
            while (i1 > i0 && weight[i1 - 1] <= 0) --i1;
            // (Four partial sums: one running total waited on each add.)
            float part[4] = {0.0f, 0.0f, 0.0f, 0.0f};
            int i = i0;
            for (; i + 4 <= i1; i += 4)
                for (int q = 0; q < 4; ++q) part[q] += weight[i + q];
            for (; i < i1; ++i) part[0] += weight[i];
            const double sum = double(part[0]) + part[1] + part[2] + part[3];
            TapRow tr;
            tr.sx = major.x * du;
            tr.sy = major.y * du;
            tr.count = i1 - i0;
            tr.weight = weight + i0;
            Float4 acc{0.0f, 0.0f, 0.0f, 0.0f};
            for (int j = 0; j < nw && tr.count > 0; ++j) {
                const double w = w0 + j * dw, u = u0 + i0 * du;
                tr.x = cx + minor.x * w + major.x * u;
                tr.y = cy + minor.y * w + major.y * u;
                tapRow<kC>(img.data, stride, tr, acc);
            }
            total = sum * nw;
            const float norm = total > 0 ? static_cast<float>(1.0 / total) : 0.0f;
            for (int c = 0; c < kC; ++c) out[c] = acc[c] * norm;
            return;
        }
    }
    for (int c = 0; c < channels; ++c) out[c] = 0.0f;
    for (int j = 0; j < nw; ++j) {
        row(j);
        for (int n = 0; n < r.count; ++n) {
            if (r.weight[n] <= 0) continue;
            const float w = static_cast<float>(r.weight[n]);
            total += r.weight[n];
            if (inner) detail::addBilinearInterior<kC>(img.data, stride, channels, r.x[n], r.y[n], w, out);
            else detail::addBilinear<kC>(img.data, img.width, img.height, channels, r.x[n], r.y[n], w, out);
        }
    }
    const float norm = total > 0 ? static_cast<float>(1.0 / total) : 0.0f;
    for (int c = 0; c < channels; ++c) out[c] *= norm;
}

template <int kC>
void encodeRows(const Image& src, const SamplingMap& map, const FootprintField& field, Pyramid& pyramid, Image& dst,
                int threads, bool anisotropic, float* share, int y0, int y1) {
    const int channels = kC > 0 ? kC : src.channelCount();
    const int W = dst.width, H = dst.height;
    const double uniform = uniformSpacing(src.width, src.height, W, H);
    std::vector<float> dynamicUpper(kC > 0 ? 0 : channels);
    const auto pixel = [&](int x, int y) {
        float* out = dst.pixels.data() + (static_cast<std::size_t>(y) * W + x) * channels;
        const glm::dvec2 pd((x + 0.5) / W, (y + 0.5) / H);
        const glm::dvec2 p = map.undistort(pd);
        // The pixel's edges (1/W,0) and (0,1/H) in distorted space, carried back into the
        // source: the columns of J^-1 scaled, in level-0 source pixels.
        const glm::dmat2 Jinv = field.inverseJacobian(p);
        const glm::dvec2 a = Jinv[0] / double(W) * glm::dvec2(src.width, src.height);
        const glm::dvec2 b = Jinv[1] / double(H) * glm::dvec2(src.width, src.height);
        double minor = 0;
        const FootprintFilter filter = footprintFilter(a, b, uniform, minor);
        const glm::dvec2 extent = filterExtent(filter);
        if (share) share[static_cast<std::size_t>(y) * W + x] = FootprintPlan{0.0, extent}.lowPassShare();
        const PrincipalAxes axes = principalAxes(a, b, filter);
        const double lambda = anisotropic ? anisotropicLevel(axes, filter) : footprintLevel(a, b, minor, extent);
        const int top = pyramid.levels() - 1;
        const int level = std::min(static_cast<int>(lambda), top);
        const double blend = level < top ? lambda - level : 0.0;
        const auto onLevel = [&](int l, float* to) {
            if (anisotropic) anisotropicOnLevel<kC>(pyramid, l, threads, channels, src, p, axes, filter, to);
            else filterOnLevel<kC>(pyramid, l, threads, channels, src, p, a, b, filter, extent, to);
        };
        onLevel(level, out);
        if (blend > 0) {
            float fixedUpper[kC > 0 ? kC : 1];
            float* upper = kC > 0 ? fixedUpper : dynamicUpper.data();
            onLevel(level + 1, upper);
            const float f = static_cast<float>(blend);
            for (int c = 0; c < channels; ++c) out[c] += f * (upper[c] - out[c]);
        }
    };
    // Tiles of kTileRows x kTileColumns pixels: the source under one tile (with the footprints'
    // reach) stays in the core's cache, where a whole row of long footprints (a band of ~60 rows
    // of a 4096-wide source, 3 MB) did not. Each pixel is computed alone, so the order is free.
    constexpr int kTileRows = 8, kTileColumns = 32;
    for (int ty = y0; ty < y1; ty += kTileRows)
        for (int tx = 0; tx < W; tx += kTileColumns)
            for (int y = ty; y < std::min(y1, ty + kTileRows); ++y)
                for (int x = tx; x < std::min(W, tx + kTileColumns); ++x) pixel(x, y);
}

// Whether every node of the map sits where the identity puts it (to float rounding).
bool isUniform(const SamplingMap& map) {
    for (int j = 0; j < map.rows(); ++j)
        for (int i = 0; i < map.columns(); ++i) {
            const glm::vec2 n = map.node(i, j);
            if (std::abs(n.x - float(i) / float(map.columns() - 1)) > 1e-6f ||
                std::abs(n.y - float(j) / float(map.rows() - 1)) > 1e-6f)
                return false;
        }
    return true;
}

}  // namespace

namespace detail {
bool encodeAvx2Available() { return cpuHasAvx2(); }
void forceBaselineEncode(bool baseline) { g_forceBaselineEncode.store(baseline, std::memory_order_relaxed); }
}  // namespace detail

bool isUniformMap(const SamplingMap& map) { return isUniform(map); }

FootprintPlan planFootprint(glm::dvec2 a, glm::dvec2 b, double uniform) {
    double minor = 0;
    const glm::dvec2 extent = filterExtent(footprintFilter(a, b, uniform, minor));
    return {footprintLevel(a, b, minor, extent), extent};
}

double uniformSpacing(int sourceWidth, int sourceHeight, int width, int height) {
    return std::sqrt(double(sourceWidth) * sourceHeight / (double(width) * height));
}

FootprintField::FootprintField(const SamplingMap& map) : m_columns(map.columns()), m_rows(map.rows()) {
    m_nodes.resize(static_cast<std::size_t>(m_columns) * m_rows);
    for (int j = 0; j < m_rows; ++j)
        for (int i = 0; i < m_columns; ++i) {
            const int i0 = std::max(i - 1, 0), i1 = std::min(i + 1, m_columns - 1);
            const int j0 = std::max(j - 1, 0), j1 = std::min(j + 1, m_rows - 1);
            const glm::dvec2 du = (glm::dvec2(map.node(i1, j)) - glm::dvec2(map.node(i0, j))) *
                                  (double(m_columns - 1) / (i1 - i0));
            const glm::dvec2 dv = (glm::dvec2(map.node(i, j1)) - glm::dvec2(map.node(i, j0))) *
                                  (double(m_rows - 1) / (j1 - j0));
            const glm::dmat2 J(du, dv);
            const double det = glm::determinant(J);
            m_nodes[static_cast<std::size_t>(j) * m_columns + i] =
                std::isfinite(det) && det > 0 ? glm::inverse(J) : glm::dmat2(0.0);
        }
}

glm::dmat2 FootprintField::inverseJacobian(glm::dvec2 p) const {
    const double fu = std::clamp(p.x, 0.0, 1.0) * (m_columns - 1), fv = std::clamp(p.y, 0.0, 1.0) * (m_rows - 1);
    const int i = std::min(static_cast<int>(fu), m_columns - 2), j = std::min(static_cast<int>(fv), m_rows - 2);
    const double s = fu - i, t = fv - j;
    const auto at = [&](int di, int dj) { return m_nodes[static_cast<std::size_t>(j + dj) * m_columns + i + di]; };
    return (at(0, 0) * (1 - s) + at(1, 0) * s) * (1 - t) + (at(0, 1) * (1 - s) + at(1, 1) * s) * t;
}

namespace {

// The encode of a source of `shape`'s size and channels from its pyramid.
Image encodeFrom(const Image& shape, Pyramid& pyramid, const SamplingMap& map, const EncodeOptions& options) {
    detail::checkOutputSize(options.width, options.height, "encodeImage");
    checkEncodeMemory(shape, options.width, options.height);
    Image out = detail::makeOutput(shape, options.width, options.height);
    const FootprintField field(map);
    const bool anisotropic = options.filter == EncodeFilter::Anisotropic && !isUniform(map);  // encode.h says why
    float* share = nullptr;
    if (options.lowPassShare) {
        options.lowPassShare->assign(static_cast<std::size_t>(out.width) * out.height, 0.0f);
        share = options.lowPassShare->data();
    }
    detail::RowProgress progress(options.progress, out.height);
    parallelRows(out.height, options.threads, [&](int y0, int y1) {
        detail::dispatchChannels(shape.channelCount(), [&]<int kC>() {
            encodeRows<kC>(shape, map, field, pyramid, out, options.threads, anisotropic, share, y0, y1);
        });
        progress.add(y1 - y0);
    });
    return out;
}

}  // namespace

Image encodeImage(const Image& source, const SamplingMap& map, const EncodeOptions& options) {
    checkImage(source, "encodeImage");
    Pyramid pyramid(source, options.keptLevels);
    return encodeFrom(source, pyramid, map, options);
}

void buildEncodeLevels(const Image& source, EncodeLevels& kept, int threads) {
    checkImage(source, "buildEncodeLevels");
    Pyramid pyramid(source, &kept);  // hands its levels back to `kept` when it goes
    for (int level = 1; level < pyramid.levels(); ++level) pyramid.level(level, threads);
}

Image encodeImage(const EightBitImage& source, const SamplingMap& map, const EncodeOptions& options) {
    detail::checkCodes(source, "encodeImage");
    const Image shape{source.width, source.height, source.channels, {}};  // sizes and channels only
    Pyramid pyramid(source);
    return encodeFrom(shape, pyramid, map, options);
}

}  // namespace conus::codec
