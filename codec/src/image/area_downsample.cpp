// The area-downsample baseline: each output pixel the exact area average of the source pixels it
// covers (the uniform image's encode, and the encoder's pyramid levels).
#include <algorithm>
#include <functional>
#include <string>
#include <vector>

#include "area_downsample_pvt.h"
#include "conus/codec/image/encode.h"
#include "conus/core/parallel.h"
#include "encode_pvt.h"
#include "resample_pvt.h"

namespace conus::codec {
namespace detail {
namespace {

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
// once per output row it touches and the row buffer stays in cache. sourceRow(k): source row k.
template <int kC, class SourceRow>
void areaRows(const SourceRow& sourceRow, int srcWidth, float* dst, int dstWidth, int c, const AxisWeights& wx,
              const AxisWeights& wy, int y0, int y1) {
    const int channels = kC > 0 ? kC : c;
    const std::size_t rowValues = static_cast<std::size_t>(srcWidth) * channels;
    std::vector<float> row(rowValues);
    std::vector<float> dynamicAcc(kC > 0 ? 0 : channels);
    for (int y = y0; y < y1; ++y) {
        std::fill(row.begin(), row.end(), 0.0f);
        for (int k = 0; k < wy.count[y]; ++k) {
            const float w = wy.weight[wy.offset[y] + k];
            const float* s = sourceRow(wy.first[y] + k);
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

}  // namespace

void areaDownsamplePlane(Plane src, float* dst, int width, int height, int channels, int threads) {
    const AxisWeights wx = areaWeights(src.width, width);
    const AxisWeights wy = areaWeights(src.height, height);
    const std::size_t rowValues = static_cast<std::size_t>(src.width) * channels;
    const auto sourceRow = [&](int k) { return src.data + k * rowValues; };
    parallelRows(height, threads, [&](int y0, int y1) {
        detail::dispatchChannels(channels, [&]<int kC>() { areaRows<kC>(sourceRow, src.width, dst, width, channels, wx, wy, y0, y1); });
    });
}

void areaDownsampleRows(int srcWidth, int srcHeight, int channels, const std::function<void(int, float*)>& fill, float* dst,
                        int width, int height, int threads) {
    const AxisWeights wx = areaWeights(srcWidth, width);
    const AxisWeights wy = areaWeights(srcHeight, height);
    const std::size_t rowValues = static_cast<std::size_t>(srcWidth) * channels;
    parallelRows(height, threads, [&](int y0, int y1) {
        // A few output rows at a time (one thread may be handed all of them), and the source rows
        // they cover (the intervals rise with the row) made once for them.
        constexpr int kOutputRows = 8;
        std::vector<float> band;
        for (int a = y0; a < y1; a += kOutputRows) {
            const int b = std::min(y1, a + kOutputRows);
            const int s0 = wy.first[a], s1 = wy.first[b - 1] + wy.count[b - 1];
            band.resize(static_cast<std::size_t>(std::max(0, s1 - s0)) * rowValues);
            for (int k = s0; k < s1; ++k) fill(k, band.data() + (k - s0) * rowValues);
            const auto sourceRow = [&](int k) { return band.data() + (k - s0) * rowValues; };
            detail::dispatchChannels(channels, [&]<int kC>() { areaRows<kC>(sourceRow, srcWidth, dst, width, channels, wx, wy, a, b); });
        }
    });
}

}  // namespace detail

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
    detail::areaDownsamplePlane({source.pixels.data(), source.width, source.height}, out.pixels.data(), width, height,
                                source.channelCount(), threads);
    return out;
}

}  // namespace conus::codec
