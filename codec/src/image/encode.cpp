// CPU reference encoder (paper section 3.2) and the area-downsample baseline.
//
// Each CoNUS pixel is a box filter over its footprint in the source: the distorted pixel is split
// into na x nb sub-pixels whose centres are carried into the source through the local inverse
// Jacobian, one bilinear fetch each. With the identity map and an integer ratio the sub-pixel
// centres land exactly on source pixel centres, so the result is the exact area average.
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

constexpr int kMaxTapsPerAxis = kEncodeMaxTaps;  // encode.h says why
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

constexpr detail::TapOffsets<kMaxTapsPerAxis> kTapOffsets;

template <int kC>
void encodeRows(const Image& src, const SamplingMap& map, Pyramid& pyramid, Image& dst, int threads,
                int y0, int y1) {
    const int channels = kC > 0 ? kC : src.channelCount();
    const int W = dst.width, H = dst.height;
    std::vector<float> dynamicAcc(kC > 0 ? 0 : channels);
    for (int y = y0; y < y1; ++y) {
        float* out = dst.pixels.data() + static_cast<std::size_t>(y) * W * channels;
        for (int x = 0; x < W; ++x, out += channels) {
            const glm::dvec2 pd((x + 0.5) / W, (y + 0.5) / H);
            const glm::dvec2 p = map.undistort(pd);
            const glm::dmat2 J = map.jacobian(p);
            const double det = glm::determinant(J);
            // The pixel's edges (1/W,0) and (0,1/H) in distorted space, carried back into the
            // source: the columns of J^-1 scaled, in level-0 source pixels.
            glm::dvec2 a(0.0), b(0.0);
            if (std::isfinite(det) && det > 0) {
                const glm::dmat2 Jinv = glm::inverse(J);
                a = Jinv[0] / double(W) * glm::dvec2(src.width, src.height);
                b = Jinv[1] / double(H) * glm::dvec2(src.width, src.height);
            }
            int level = 0;
            double la = glm::length(a), lb = glm::length(b);
            while (std::max(la, lb) > kMaxTapsPerAxis + kTapTolerance && level + 1 < pyramid.levels()) {
                ++level;
                const glm::dvec2 s(double(pyramid.width(level)) / src.width, double(pyramid.height(level)) / src.height);
                la = glm::length(a * s);
                lb = glm::length(b * s);
            }
            const glm::dvec2 scale(double(pyramid.width(level)) / src.width, double(pyramid.height(level)) / src.height);
            const glm::dvec2 aL = a * scale, bL = b * scale;
            const int na = std::clamp(static_cast<int>(std::ceil(la - kTapTolerance)), 1, kMaxTapsPerAxis);
            const int nb = std::clamp(static_cast<int>(std::ceil(lb - kTapTolerance)), 1, kMaxTapsPerAxis);

            const Plane img = pyramid.level(level, threads);
            const double cx = p.x * img.width - 0.5, cy = p.y * img.height - 0.5;
            const float weight = 1.0f / static_cast<float>(na * nb);
            float fixedAcc[kC > 0 ? kC : 1];
            float* acc = kC > 0 ? fixedAcc : dynamicAcc.data();
            for (int c = 0; c < channels; ++c) acc[c] = 0.0f;
            const double* oa = kTapOffsets.at[na];
            const double* ob = kTapOffsets.at[nb];
            // Away from the borders no tap needs clamping: decide once for the whole footprint.
            const double ex = 0.5 * (std::abs(aL.x) + std::abs(bL.x)), ey = 0.5 * (std::abs(aL.y) + std::abs(bL.y));
            const bool inner = cx - ex >= 0 && cx + ex < img.width - 1 && cy - ey >= 0 && cy + ey < img.height - 1;
            const std::size_t stride = static_cast<std::size_t>(img.width) * channels;
            for (int j = 0; j < nb; ++j) {
                const double qx = cx + bL.x * ob[j], qy = cy + bL.y * ob[j];
                for (int i = 0; i < na; ++i) {
                    const double x = qx + aL.x * oa[i], y = qy + aL.y * oa[i];
                    if (inner) detail::addBilinearInterior<kC>(img.data, stride, channels, x, y, weight, acc);
                    else detail::addBilinear<kC>(img.data, img.width, img.height, channels, x, y, weight, acc);
                }
            }
            for (int c = 0; c < channels; ++c) out[c] = acc[c];
        }
    }
}

}  // namespace

Image encodeImage(const Image& source, const SamplingMap& map, const EncodeOptions& options) {
    checkImage(source, "encodeImage");
    detail::checkOutputSize(options.width, options.height, "encodeImage");
    Image out = detail::makeOutput(source, options.width, options.height);
    Pyramid pyramid(source);
    detail::RowProgress progress(options.progress, out.height);
    parallelRows(out.height, options.threads, [&](int y0, int y1) {
        detail::dispatchChannels(source.channelCount(), [&]<int kC>() {
            encodeRows<kC>(source, map, pyramid, out, options.threads, y0, y1);
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
