// The plain baseline the decoder is timed and compared against: the same view of a uniform image
// by bilinear resampling, its per-axis taps precomputed (the image is separable, a CoNUS image's
// map is not), the pixel's channels in lanes and stored as the decoder's magnified spans store
// theirs, so that the baseline stays an optimised resize.
#include <algorithm>
#include <cstddef>
#include <cstring>
#include <vector>

#include "conus/codec/image/decode.h"
#include "conus/core/parallel.h"
#include "decode_pvt.h"
#include "resample_pvt.h"
#include "resize_rows_pvt.h"

namespace conus::codec {
namespace {

detail::AxisTaps axisTaps(int size, double a0, double a1, int count) {
    detail::AxisTaps t;
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

// Output row y (width pixels) into out.
template <int kC>
void bilinearRow(const Image& src, float* out, int width, const detail::AxisTaps& tx, const detail::AxisTaps& ty, int y) {
    const int channels = kC > 0 ? kC : src.channelCount();
    const std::size_t stride = static_cast<std::size_t>(src.width) * channels;
    const float* r0 = src.pixels.data() + ty.i0[y] * stride;
    const float* r1 = src.pixels.data() + ty.i1[y] * stride;
    const float fy = ty.f[y];
    if constexpr (detail::kLanes<kC>) {
        // As the decoder's magnified spans: every pixel but the row's last stores four lanes (the
        // next pixel overwrites the fourth).
        const float* last = src.pixels.data() + src.pixels.size() - kC;
        const int wide = kC == 4 ? width : width - 1;
        for (int x = 0; x < wide; ++x, out += kC) {
            const detail::PixelLanes v = detail::bilinearLanes<kC>(r0, r1, std::size_t(tx.i0[x]) * kC,
                                                                   std::size_t(tx.i1[x]) * kC, tx.f[x], fy, last);
            std::memcpy(out, &v, sizeof v);
        }
        for (int x = wide; x < width; ++x, out += kC)
            detail::storeLanes<kC>(out, detail::bilinearLanes<kC>(r0, r1, std::size_t(tx.i0[x]) * kC,
                                                                  std::size_t(tx.i1[x]) * kC, tx.f[x], fy, last));
        return;
    }
    for (int x = 0; x < width; ++x, out += channels) {
        const int o0 = tx.i0[x] * channels, o1 = tx.i1[x] * channels;
        const float fx = tx.f[x];
        for (int k = 0; k < channels; ++k) {
            const float top = r0[o0 + k] + fx * (r0[o1 + k] - r0[o0 + k]);
            const float bottom = r1[o0 + k] + fx * (r1[o1 + k] - r1[o0 + k]);
            out[k] = top + fy * (bottom - top);
        }
    }
}

}  // namespace

Image resizeBilinear(const Image& image, const View& view, int width, int height, int threads) {
    checkImage(image, "resizeBilinear");
    detail::checkOutputSize(width, height, "resizeBilinear");
    checkDecodeMemory(image, width, height);
    detail::checkView(view, "resizeBilinear");
    Image out = detail::makeOutput(image, width, height);
    const detail::AxisTaps tx = axisTaps(image.width, view.u0, view.u1, width);
    const detail::AxisTaps ty = axisTaps(image.height, view.v0, view.v1, height);
    parallelRows(
        height, threads,
        [&](int y0, int y1) {
            detail::dispatchChannels(image.channelCount(), [&]<int kC>() {
                for (int y = y0; y < y1; ++y)
                    bilinearRow<kC>(image, out.pixels.data() + static_cast<std::size_t>(y) * width * image.channelCount(), width,
                                    tx, ty, y);
            });
        },
        16);
    detail::clearOutside(out, view);
    return out;
}

namespace detail {

ResizedRows::ResizedRows(const Image& image, int width, int height)
    : m_image(image), m_width(width), m_tx(axisTaps(image.width, 0.0, 1.0, width)), m_ty(axisTaps(image.height, 0.0, 1.0, height)) {}

void ResizedRows::row(int y, float* out) const {
    dispatchChannels(m_image.channelCount(), [&]<int kC>() { bilinearRow<kC>(m_image, out, m_width, m_tx, m_ty, y); });
}

}  // namespace detail

}  // namespace conus::codec
