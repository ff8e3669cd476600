// CPU reference encoder (paper section 3.2) and the area-downsample baseline.
//
// Each CoNUS pixel filters the source over its footprint (encode.h states the rule): a grid of
// bilinear taps in the pixel's own units (s,t), carried into the source through the local inverse
// Jacobian (FootprintField), weighted by the unit box convolved with a Gaussian along the
// footprint's major axis. A square footprint has no Gaussian: with the identity map and an integer
// ratio the taps land exactly on source pixel centres, so the result is the exact area average.
#include <array>
#include <memory>
#include <cmath>
#include <mutex>
#include <vector>

#include "conus/codec/image/encode.h"
#include "conus/core/parallel.h"
#include "resample_pvt.h"

namespace conus::codec {
namespace {

constexpr int kMaxTapsPerAxis = kEncodeMaxTaps;  // encode.h says why (the minor axis's bound)
constexpr double kTapTolerance = kEncodeTapTolerance;

// Source-pixel intervals covered by each output pixel along one axis, with exact overlap weights.
struct AxisWeights {
    std::vector<int> first, count, offset;
    std::vector<float> weight;
};

AxisWeights areaWeights(int source, int target) {
    AxisWeights w;
    w.first.resize(target);
    w.count.resize(target);
    w.offset.resize(target);
    const double scale = static_cast<double>(source) / target;
    for (int i = 0; i < target; ++i) {
        const double lo = i * scale, hi = (i + 1) * scale;
        const int k0 = std::min(source - 1, static_cast<int>(std::floor(lo)));
        const int k1 = std::min(source, static_cast<int>(std::ceil(hi)));
        w.first[i] = k0;
        w.offset[i] = static_cast<int>(w.weight.size());
        for (int k = k0; k < k1; ++k) {
            const double overlap = std::min(hi, k + 1.0) - std::max(lo, static_cast<double>(k));
            if (overlap > 0) w.weight.push_back(static_cast<float>(overlap / scale));
            else if (k == k0) ++w.first[i];  // a zero-width sliver at the start: skip it
        }
        w.count[i] = static_cast<int>(w.weight.size()) - w.offset[i];
    }
    return w;
}

// Vertical pass into a row of source width, then the horizontal pass: each source value is read
// once per output row it touches and the row buffer stays in cache.
// A pixel array without its channel names: the pyramid's levels are not format::Images so they
// are never zero-filled before being written.
struct Plane {
    const float* data = nullptr;
    int width = 0, height = 0;
};

template <int kC>
void areaRows(Plane src, float* dst, int dstWidth, int c, const AxisWeights& wx, const AxisWeights& wy, int y0,
              int y1) {
    const int channels = kC > 0 ? kC : c;
    const std::size_t rowValues = static_cast<std::size_t>(src.width) * channels;
    std::vector<float> row(rowValues);
    std::vector<float> dynamicAcc(kC > 0 ? 0 : channels);
    for (int y = y0; y < y1; ++y) {
        std::fill(row.begin(), row.end(), 0.0f);
        for (int k = 0; k < wy.count[y]; ++k) {
            const float w = wy.weight[wy.offset[y] + k];
            const float* s = src.data + (wy.first[y] + k) * rowValues;
            for (std::size_t i = 0; i < rowValues; ++i) row[i] += w * s[i];
        }
        float* out = dst + static_cast<std::size_t>(y) * dstWidth * channels;
        for (int x = 0; x < dstWidth; ++x, out += channels) {
            float fixedAcc[kC > 0 ? kC : 1];
            float* a = kC > 0 ? fixedAcc : dynamicAcc.data();
            for (int c = 0; c < channels; ++c) a[c] = 0.0f;
            const float* s = row.data() + static_cast<std::size_t>(wx.first[x]) * channels;
            const float* w = wx.weight.data() + wx.offset[x];
            for (int k = 0; k < wx.count[x]; ++k, s += channels)
                for (int c = 0; c < channels; ++c) a[c] += w[k] * s[c];
            for (int c = 0; c < channels; ++c) out[c] = a[c];
        }
    }
}

void areaDownsamplePlane(Plane src, float* dst, int width, int height, int channels, int threads) {
    const AxisWeights wx = areaWeights(src.width, width);
    const AxisWeights wy = areaWeights(src.height, height);
    parallelRows(height, threads, [&](int y0, int y1) {
        detail::dispatchChannels(channels, [&]<int kC>() { areaRows<kC>(src, dst, width, channels, wx, wy, y0, y1); });
    });
}

// Box-filtered mip levels of the source, each built the first time a footprint needs it.
class Pyramid {
public:
    static constexpr int kMaxLevels = 40;

    explicit Pyramid(const Image& source) : m_source(source), m_channels(source.channelCount()) {
        int w = source.width, h = source.height;
        m_sizes.push_back({w, h});
        while ((w > 1 || h > 1) && static_cast<int>(m_sizes.size()) < kMaxLevels) {
            w = std::max(1, (w + 1) / 2);
            h = std::max(1, (h + 1) / 2);
            m_sizes.push_back({w, h});
        }
    }
    int levels() const { return static_cast<int>(m_sizes.size()); }
    int width(int level) const { return m_sizes[level][0]; }
    int height(int level) const { return m_sizes[level][1]; }
    // The first worker to need a level builds it with all threads while the others wait for it.
    Plane level(int level, int threads) {
        if (level == 0) return {m_source.pixels.data(), m_source.width, m_source.height};
        std::call_once(m_once[level], [&] {
            const Plane below = this->level(level - 1, threads);
            m_levels[level].reset(new float[static_cast<std::size_t>(width(level)) * height(level) * m_channels]);
            areaDownsamplePlane(below, m_levels[level].get(), width(level), height(level), m_channels, threads);
        });
        return {m_levels[level].get(), width(level), height(level)};
    }

private:
    const Image& m_source;
    int m_channels;
    std::vector<std::array<int, 2>> m_sizes;
    std::array<std::unique_ptr<float[]>, kMaxLevels> m_levels;
    std::array<std::once_flag, kMaxLevels> m_once;
};

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

// erf on a table with linear interpolation: the weights need erf at two points per tap, and the
// library's erf was most of the encoder's time. The Gaussian is cut at kEncodeGaussianReach
// standard deviations, so arguments never pass kReach / sqrt(2); the table's error (~1e-6) is far
// below the GPU's own erf approximation's effect on the 45 dB agreement.
class ErfTable {
public:
    static constexpr int kSize = 2048;
    ErfTable() {
        for (int i = 0; i <= kSize; ++i) m_value[i] = std::erf(kMax * i / kSize);
    }
    double operator()(double x) const {
        const double u = std::min(std::abs(x), kMax) * (kSize / kMax);
        const int i = std::min(static_cast<int>(u), kSize - 1);
        const double v = m_value[i] + (u - i) * (m_value[i + 1] - m_value[i]);
        return x < 0 ? -v : v;
    }

private:
    static constexpr double kMax = kEncodeGaussianReach / 1.4142135623730951 + 1e-9;
    std::array<double, kSize + 1> m_value{};
};
const ErfTable kErf;

// The offsets o along `major` for which x - o * d lies in [-0.5, 0.5], intersected with [lo, hi].
inline void narrowSlab(double x, double d, double& lo, double& hi) {
    if (std::abs(d) < 1e-9) {
        if (std::abs(x) > 0.5) hi = lo;
        return;
    }
    const double o1 = (x - 0.5) / d, o2 = (x + 0.5) / d;
    lo = std::max(lo, std::min(o1, o2));
    hi = std::min(hi, std::max(o1, o2));
}

// The filtered value on one level, normalized, written to out. The taps are encode.h's grid
// (ns x nt, at slice centres over the filter's extent); positions step
// by a constant per tap, and a box-only filter (sigma 0) needs no weights at all.
template <int kC>
void filterOnLevel(Pyramid& pyramid, int level, int threads, int channels, const Image& src, glm::dvec2 p,
                   glm::dvec2 a, glm::dvec2 b, const FootprintFilter& filter, glm::dvec2 extent, float* out) {
    const Plane img = pyramid.level(level, threads);
    const glm::dvec2 scale(double(img.width) / src.width, double(img.height) / src.height);
    const glm::dvec2 aL = a * scale, bL = b * scale;
    // Taps at most a texel apart along each edge; the cap only bounds rounding and degenerate maps.
    const int ns = std::clamp(static_cast<int>(std::ceil(glm::length(aL) * extent.x - kTapTolerance)), 1,
                              2 * kEncodeMaxAxisTaps);
    const int nt = std::clamp(static_cast<int>(std::ceil(glm::length(bL) * extent.y - kTapTolerance)), 1,
                              2 * kEncodeMaxAxisTaps);
    const double cx = p.x * img.width - 0.5, cy = p.y * img.height - 0.5;
    for (int c = 0; c < channels; ++c) out[c] = 0.0f;
    // Away from the borders no tap needs clamping: decide once for the whole footprint.
    const double ex = 0.5 * (std::abs(aL.x) * extent.x + std::abs(bL.x) * extent.y);
    const double ey = 0.5 * (std::abs(aL.y) * extent.x + std::abs(bL.y) * extent.y);
    const bool inner = cx - ex >= 0 && cx + ex < img.width - 1 && cy - ey >= 0 && cy + ey < img.height - 1;
    const std::size_t stride = static_cast<std::size_t>(img.width) * channels;
    const auto add = [&](double tx, double ty, float w) {
        if (inner) detail::addBilinearInterior<kC>(img.data, stride, channels, tx, ty, w, out);
        else detail::addBilinear<kC>(img.data, img.width, img.height, channels, tx, ty, w, out);
    };
    const double ds = extent.x / ns, dt = extent.y / nt;
    const double s0 = 0.5 * ds - 0.5 * extent.x, t0 = 0.5 * dt - 0.5 * extent.y;
    constexpr double kMinSigma = 1e-4;  // below it the filter is the plain box (encode.h)
    if (filter.sigma < kMinSigma) {
        // The extent is the unit box itself: every tap weighs the same.
        const float w = 1.0f / static_cast<float>(ns * nt);
        for (int j = 0; j < nt; ++j) {
            const double t = t0 + j * dt;
            const double rx = cx + bL.x * t + aL.x * s0, ry = cy + bL.y * t + aL.y * s0;
            for (int i = 0; i < ns; ++i) add(rx + aL.x * (i * ds), ry + aL.y * (i * ds), w);
        }
        return;
    }
    const double k = 1.0 / (std::sqrt(2.0) * filter.sigma);
    double total = 0;
    for (int j = 0; j < nt; ++j) {
        const double t = t0 + j * dt;
        // The row's slab along t is the same for every tap in it.
        double rowLo = -filter.reach, rowHi = filter.reach;
        narrowSlab(t, filter.major.y, rowLo, rowHi);
        if (rowHi <= rowLo) continue;
        const double rx = cx + bL.x * t, ry = cy + bL.y * t;
        // Only taps whose s slab meets the row's offsets weigh anything: s within 0.5 of
        // [rowLo, rowHi] * major.x. A diagonal footprint's grid is mostly outside that strip.
        int i0 = 0, i1 = ns;
        if (std::abs(filter.major.x) >= 1e-9) {
            const double m0 = rowLo * filter.major.x, m1 = rowHi * filter.major.x;
            const double sLo = std::min(m0, m1) - 0.5, sHi = std::max(m0, m1) + 0.5;
            i0 = std::max(0, static_cast<int>(std::floor((sLo - s0) / ds)));
            i1 = std::min(ns, static_cast<int>(std::ceil((sHi - s0) / ds)) + 1);
        }
        for (int i = i0; i < i1; ++i) {
            const double s = s0 + i * ds;
            double lo = rowLo, hi = rowHi;
            narrowSlab(s, filter.major.x, lo, hi);
            if (hi <= lo) continue;
            const double w = 0.5 * (kErf(hi * k) - kErf(lo * k));
            if (w <= 0) continue;
            total += w;
            add(rx + aL.x * s, ry + aL.y * s, float(w));
        }
    }
    const float norm = total > 0 ? static_cast<float>(1.0 / total) : 0.0f;
    for (int c = 0; c < channels; ++c) out[c] *= norm;
}

template <int kC>
void encodeRows(const Image& src, const SamplingMap& map, const FootprintField& field, Pyramid& pyramid, Image& dst,
                int threads,
                int y0, int y1) {
    const int channels = kC > 0 ? kC : src.channelCount();
    const int W = dst.width, H = dst.height;
    const double uniform = uniformSpacing(src.width, src.height, W, H);
    std::vector<float> dynamicUpper(kC > 0 ? 0 : channels);
    for (int y = y0; y < y1; ++y) {
        float* out = dst.pixels.data() + static_cast<std::size_t>(y) * W * channels;
        for (int x = 0; x < W; ++x, out += channels) {
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
            const double lambda = footprintLevel(a, b, minor, extent);
            const int top = pyramid.levels() - 1;
            const int level = std::min(static_cast<int>(lambda), top);
            const double blend = level < top ? lambda - level : 0.0;
            filterOnLevel<kC>(pyramid, level, threads, channels, src, p, a, b, filter, extent, out);
            if (blend > 0) {
                float fixedUpper[kC > 0 ? kC : 1];
                float* upper = kC > 0 ? fixedUpper : dynamicUpper.data();
                filterOnLevel<kC>(pyramid, level + 1, threads, channels, src, p, a, b, filter, extent, upper);
                const float f = static_cast<float>(blend);
                for (int c = 0; c < channels; ++c) out[c] += f * (upper[c] - out[c]);
            }
        }
    }
}

}  // namespace

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

Image encodeImage(const Image& source, const SamplingMap& map, const EncodeOptions& options) {
    checkImage(source, "encodeImage");
    detail::checkOutputSize(options.width, options.height, "encodeImage");
    Image out = detail::makeOutput(source, options.width, options.height);
    Pyramid pyramid(source);
    const FootprintField field(map);
    detail::RowProgress progress(options.progress, out.height);
    parallelRows(out.height, options.threads, [&](int y0, int y1) {
        detail::dispatchChannels(source.channelCount(), [&]<int kC>() {
            encodeRows<kC>(source, map, field, pyramid, out, options.threads, y0, y1);
        });
        progress.add(y1 - y0);
    });
    return out;
}

// Downsample only: growing an axis has no area to average over, and the decoder's bilinear
// baseline (resizeBilinear) is the tool for that.
Image areaDownsample(const Image& source, int width, int height, int threads) {
    checkImage(source, "areaDownsample");
    detail::checkOutputSize(width, height, "areaDownsample");
    if (width > source.width || height > source.height)
        throw Error(ErrorCode::InvalidArgument,
                    "areaDownsample: " + std::to_string(source.width) + "x" + std::to_string(source.height) + " -> " +
                        std::to_string(width) + "x" + std::to_string(height) +
                        " grows the image; it only shrinks (use resizeBilinear)");
    Image out = detail::makeOutput(source, width, height);
    areaDownsamplePlane({source.pixels.data(), source.width, source.height}, out.pixels.data(), width, height,
                        source.channelCount(), threads);
    return out;
}

}  // namespace conus::codec
