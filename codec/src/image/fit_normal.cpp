// The normal equations A = D^T D of the fit (fit_operator_pvt.h), assembled on the CoNUS grid in
// one walk of the decoder's taps over the source.
#include <cstdint>
#include <vector>

#include "fit_operator_pvt.h"

namespace conus::codec::detail {
inline namespace fit_operator {
namespace {

// Adds d d^T of a d within the 2x2 block at (bx, by): a at (bx, by), b to its right, c below, e
// below right (b and e are 0 where bx is the last column, c and e where by is the band's last row).
inline void addBlock(float* stencil, int lo, int hi, int wc, int bx, int by, float a, float b, float c, float e) {
    float* p00 = stencil + ((static_cast<std::size_t>(by - lo) * wc) + bx) * kStencil;
    p00[kOwn] += a * a;
    p00[kRight] += a * b;
    p00[kBelow] += a * c;
    p00[kBelowRight] += a * e;
    const bool right = bx + 1 < wc, below = by + 1 <= hi;
    if (right) {
        float* p01 = p00 + kStencil;
        p01[kOwn] += b * b;
        p01[kBelow] += b * e;
        p01[kBelowLeft] += b * c;
    }
    if (below) {
        float* p10 = p00 + static_cast<std::size_t>(wc) * kStencil;
        p10[kOwn] += c * c;
        p10[kRight] += c * e;
        if (right) p10[kStencil + kOwn] += e * e;
    }
}

// A tap's corner weights on the 2x2 block at its top-left corner (x0, y0), a clamped corner's
// weight merged into the one it fell on.
inline void blockWeights(const TapCorners& q, float w[4]) {
    w[0] = q.w00;
    w[1] = q.w01;
    w[2] = q.w10;
    w[3] = q.w11;
    if (q.x1 == q.x0) {
        w[0] += w[1];
        w[2] += w[3];
        w[1] = w[3] = 0.0f;
    }
    if (q.y1 == q.y0) {
        w[0] += w[2];
        w[1] += w[3];
        w[2] = w[3] = 0.0f;
    }
}

// Adds one output pixel's d d^T: into the stencil, or as a wide row of the band (false when the
// wide rows' allowance `wideLeft` is spent: the assembly is then abandoned).
inline bool addOuter(Band& band, int wc, int hc, const DecoderTap* taps, int count,
                     std::vector<std::pair<std::int32_t, float>>& entries, std::atomic<std::int64_t>& wideLeft) {
    if (count == 1) {
        const TapCorners q = tapCorners(taps[0], wc, hc);
        float w[4];
        blockWeights(q, w);
        addBlock(band.stencil.data(), band.lo, band.hi, wc, q.x0, q.y0, w[0], w[1], w[2], w[3]);
        return true;
    }
    int x0 = wc, y0 = hc, x1 = -1, y1 = -1;
    TapCorners corners[DecoderTaps::kMaxTaps];
    for (int t = 0; t < count; ++t) {
        const TapCorners& q = corners[t] = tapCorners(taps[t], wc, hc);
        x0 = std::min(x0, q.x0);
        y0 = std::min(y0, q.y0);
        x1 = std::max(x1, q.x1);
        y1 = std::max(y1, q.y1);
    }
    if (x1 - x0 <= 1 && y1 - y0 <= 1) {
        float block[4] = {0, 0, 0, 0};
        for (int t = 0; t < count; ++t) {
            const TapCorners& q = corners[t];
            block[(q.y0 - y0) * 2 + (q.x0 - x0)] += q.w00;
            block[(q.y0 - y0) * 2 + (q.x1 - x0)] += q.w01;
            block[(q.y1 - y0) * 2 + (q.x0 - x0)] += q.w10;
            block[(q.y1 - y0) * 2 + (q.x1 - x0)] += q.w11;
        }
        addBlock(band.stencil.data(), band.lo, band.hi, wc, x0, y0, block[0], block[1], block[2], block[3]);
        return true;
    }
    entries.clear();
    for (int t = 0; t < count; ++t) {
        const TapCorners& q = corners[t];
        entries.push_back({q.y0 * wc + q.x0, q.w00});
        entries.push_back({q.y0 * wc + q.x1, q.w01});
        entries.push_back({q.y1 * wc + q.x0, q.w10});
        entries.push_back({q.y1 * wc + q.x1, q.w11});
    }
    std::sort(entries.begin(), entries.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    std::size_t kept = 0;
    for (std::size_t k = 0; k < entries.size(); ++k) {
        if (kept > 0 && entries[kept - 1].first == entries[k].first) entries[kept - 1].second += entries[k].second;
        else entries[kept++] = entries[k];
    }
    if (wideLeft.fetch_sub(static_cast<std::int64_t>(kept), std::memory_order_relaxed) < static_cast<std::int64_t>(kept))
        return false;
    band.wideStart.push_back(static_cast<std::int32_t>(band.wideIndex.size()));
    for (std::size_t k = 0; k < kept; ++k) {
        band.wideIndex.push_back(entries[k].first);
        band.wideWeight.push_back(entries[k].second);
    }
    return true;
}

// One walk of the taps for the normal equations: each band's sum of |source|^2, D^T source
// splatted into its buffer and A into its stencil and wide rows. False where the wide rows
// outgrew their allowance.
template <int kC>
bool assemblePass(DecoderOperator& op, const float* source, int c) {
    const DecoderTaps& taps = op.taps();
    const int channels = kC > 0 ? kC : c, wc = taps.conusWidth(), hc = taps.conusHeight();
    std::atomic<std::int64_t> wideLeft{kWideEntriesPerPixel * wc * hc};
    std::atomic<bool> abandoned{false};
    op.forEachBand([&](Band& band, DecoderTaps::Scratch& scratch) {
        std::vector<std::pair<std::int32_t, float>> entries;
        band.wideStart.clear();
        band.wideIndex.clear();
        band.wideWeight.clear();
        double sum = 0;
        for (int y = band.y0; y < band.y1 && !abandoned.load(std::memory_order_relaxed); ++y) {
            const float* row = source + static_cast<std::size_t>(y) * taps.width() * channels;
            taps.row(y, scratch, [&](int x, const DecoderTap* t, int count) {
                const float* value = row + static_cast<std::size_t>(x) * channels;
                for (int k = 0; k < channels; ++k) sum += double(value[k]) * value[k];
                if (count == 1) {  // most pixels: the corners found once for both
                    const TapCorners q = tapCorners(t[0], wc, hc);
                    splatCorners<kC>(band.buffer.data(), band.lo, wc, channels, q, value);
                    float w[4];
                    blockWeights(q, w);
                    addBlock(band.stencil.data(), band.lo, band.hi, wc, q.x0, q.y0, w[0], w[1], w[2], w[3]);
                    return;
                }
                splat<kC>(band.buffer.data(), band.lo, wc, hc, channels, t, count, value);
                if (!addOuter(band, wc, hc, t, count, entries, wideLeft)) abandoned.store(true, std::memory_order_relaxed);
            });
        }
        band.sum = sum;
    });
    return !abandoned.load();
}

// A band's part of the assembly (its stencil, kStencil values a CoNUS pixel, and its wide rows),
// freed once summed into A or abandoned.
void releaseAssembly(Band& band) {
    std::vector<float>().swap(band.stencil);
    std::vector<std::int32_t>().swap(band.wideStart);
    std::vector<std::int32_t>().swap(band.wideIndex);
    std::vector<float>().swap(band.wideWeight);
}

}  // namespace

// The normal equations of `op` for `source` (`channels` values a pixel): A, D^T source into b and
// |source|^2 into squares; false (nothing assembled) where the view minifies too much of the image.
bool assembleNormal(DecoderOperator& op, const float* source, int channels, NormalMatrix& a, std::vector<float>& b,
                    double& squares) {
    const int wc = op.taps().conusWidth(), hc = op.taps().conusHeight();
    if (std::int64_t{wc} * hc * kStencil >= (std::int64_t{1} << 31)) return false;
    op.clearBuffers(channels);
    op.clearBuffers(kStencil, &Band::stencil);
    bool assembled = false;
    dispatchChannels(channels, [&]<int kC>() { assembled = assemblePass<kC>(op, source, channels); });
    if (!assembled) {
        // The walk that follows needs only the bands' buffers.
        for (Band& band : op.bands()) releaseAssembly(band);
        return false;
    }
    squares = op.bandSum();
    a.width = wc;
    a.height = hc;
    a.stencil.resize(static_cast<std::size_t>(wc) * hc * kStencil);
    op.sumBuffers(a.stencil.data(), kStencil, &Band::stencil);
    b.resize(static_cast<std::size_t>(wc) * hc * channels);
    op.sumBuffers(b.data(), channels);
    a.start.clear();
    for (Band& band : op.bands()) {
        const std::int32_t base = static_cast<std::int32_t>(a.index.size());
        for (const std::int32_t s : band.wideStart) a.start.push_back(base + s);
        a.index.insert(a.index.end(), band.wideIndex.begin(), band.wideIndex.end());
        a.weight.insert(a.weight.end(), band.wideWeight.begin(), band.wideWeight.end());
        releaseAssembly(band);
        std::vector<float>().swap(band.buffer);
    }
    a.start.push_back(static_cast<std::int32_t>(a.index.size()));
    return true;
}

}  // namespace fit_operator
}  // namespace conus::codec::detail
