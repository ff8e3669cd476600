// The encoder fitted to its decoder (fit.h): Jacobi-preconditioned conjugate gradients on the
// normal equations D^T D c = D^T s.
//
// Usually they are assembled on the CoNUS grid in one walk of the decoder's taps over the source
// (assemblePass): D^T s, |s|^2, and A = D^T D as a 3x3 stencil per CoNUS pixel (an output pixel's
// taps reach one 2x2 block of CoNUS pixels wherever the view magnifies), with the few output
// pixels whose taps reach wider (where it minifies) kept as rows of D. Every iteration is then a
// few stencil products on the CoNUS image, a sixteenth of the source's pixels at the default
// encode's 1/16, instead of two walks over the source. Where the view minifies much of the image
// (more wide rows than kWideEntriesPerPixel allows) the fit walks the taps every iteration (CGLS):
//
// Each pass walks the output rows in bands, one thread per band at a time. A gather (D) reads the
// CoNUS image; a splat (D^T) writes into the band's own buffer, which spans only the CoNUS rows
// its taps reach (found once, up front), and the buffers are summed row by row afterwards: no
// locks, no per-source-pixel storage, and the same sums whatever the thread count. The residual
// s - D x is recomputed from x in every pass instead of being stored (a 4096^2 source would need
// 192 MiB per vector), which also keeps it from drifting; after the last step only its norm is
// wanted (the PSNR reported), and that follows from the step's own sums without a pass. The
// assembly walks the same bands into buffers of the same rows.
#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cmath>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "conus/codec/image/encode.h"
#include "conus/codec/image/fit.h"
#include "conus/core/parallel.h"
#include "fit_pvt.h"
#include "resample_pvt.h"

namespace conus::codec {
namespace detail {
namespace {

// Output rows per block when the reach of the bands is measured; bands are runs of blocks.
constexpr int kBlockRows = 8;
// Bands: as many whatever the thread count, so that the sums come out the same (enough for 16
// threads to balance uneven rows), unless their buffers would exceed this many CoNUS images in
// all (a map that bends a band of rows across the whole image).
constexpr int kBands = 32;
constexpr int kMaxBufferImages = 4;

struct Band {
    int y0 = 0, y1 = 0;   // output rows [y0, y1)
    int lo = 0, hi = -1;  // CoNUS rows its taps reach
    std::vector<float> buffer;
    std::vector<float> squares;  // the taps' squared corner weights (diag(D^T D)), one value a CoNUS pixel
    std::vector<float> stencil;  // the normal equations' assembly: kStencil values a CoNUS pixel
    std::vector<std::int32_t> wideStart, wideIndex;  // the wide rows of D (WideRows), in walk order
    std::vector<float> wideWeight;
    double sum = 0;       // the pass's sum over the band (sums of squares)
};

class DecoderOperator {
public:
    DecoderOperator(const SamplingMap& map, int conusWidth, int conusHeight, int width, int height, int threads)
        : m_taps(map, conusWidth, conusHeight, width, height), m_threads(threadCount(threads)) {
        planBands();
    }

    const DecoderTaps& taps() const { return m_taps; }
    std::vector<Band>& bands() { return m_bands; }

    // Runs fn(band, scratch) for every band, bands spread over the threads.
    template <typename Fn>
    void forEachBand(Fn&& fn) {
        parallelRows(
            static_cast<int>(m_bands.size()), m_threads,
            [&](int b0, int b1) {
                DecoderTaps::Scratch scratch;
                for (int b = b0; b < b1; ++b) fn(m_bands[b], scratch);
            },
            1);
    }

    // Zeroes every band's buffer (`which` of them) for a splat of `channels` values per pixel.
    void clearBuffers(int channels, std::vector<float> Band::*which = &Band::buffer) {
        forEachBand([&](Band& band, DecoderTaps::Scratch&) {
            (band.*which).assign(static_cast<std::size_t>(band.hi - band.lo + 1) * m_taps.conusWidth() * channels, 0.0f);
        });
    }

    // out (CoNUS size, `channels` values a pixel) = the sum of the bands' buffers (`which` of them).
    void sumBuffers(float* out, int channels, std::vector<float> Band::*which = &Band::buffer) {
        const int wc = m_taps.conusWidth();
        const std::size_t rowValues = static_cast<std::size_t>(wc) * channels;
        parallelRows(m_taps.conusHeight(), m_threads, [&](int r0, int r1) {
            std::fill(out + r0 * rowValues, out + r1 * rowValues, 0.0f);
            for (const Band& band : m_bands) {
                const int a = std::max(r0, band.lo), b = std::min(r1 - 1, band.hi);
                for (int r = a; r <= b; ++r) {
                    const float* from = (band.*which).data() + (r - band.lo) * rowValues;
                    float* to = out + r * rowValues;
                    for (std::size_t k = 0; k < rowValues; ++k) to[k] += from[k];
                }
            }
        });
    }

    double bandSum() const {
        double total = 0;
        for (const Band& band : m_bands) total += band.sum;
        return total;
    }

private:
    void planBands() {
        const int rows = m_taps.height(), hc = m_taps.conusHeight();
        const int blocks = (rows + kBlockRows - 1) / kBlockRows;
        std::vector<int> lo(blocks, hc), hi(blocks, -1);
        parallelRows(blocks, m_threads, [&](int b0, int b1) {
            DecoderTaps::Scratch scratch;
            for (int b = b0; b < b1; ++b)
                for (int y = b * kBlockRows; y < std::min(rows, (b + 1) * kBlockRows); ++y)
                    m_taps.row(y, scratch, [&](int, const DecoderTap* taps, int count) {
                        for (int k = 0; k < count; ++k) {
                            const TapCorners c = tapCorners(taps[k], m_taps.conusWidth(), hc);
                            lo[b] = std::min(lo[b], c.y0);
                            hi[b] = std::max(hi[b], c.y1);
                        }
                    });
        });
        // kBands bands, halved while their buffers hold too much.
        for (int count = std::min(blocks, kBands);; count = std::max(1, count / 2)) {
            m_bands.assign(count, Band{});
            std::int64_t buffered = 0;
            for (int i = 0; i < count; ++i) {
                Band& band = m_bands[i];
                const int first = static_cast<int>(std::int64_t{blocks} * i / count);
                const int last = static_cast<int>(std::int64_t{blocks} * (i + 1) / count);
                band.y0 = first * kBlockRows;
                band.y1 = std::min(rows, last * kBlockRows);
                band.lo = hc;
                for (int b = first; b < last; ++b) {
                    band.lo = std::min(band.lo, lo[b]);
                    band.hi = std::max(band.hi, hi[b]);
                }
                band.hi = std::max(band.hi, band.lo);  // a band with no taps keeps one row
                buffered += band.hi - band.lo + 1;
            }
            if (count == 1 || buffered <= std::int64_t{kMaxBufferImages} * hc) break;
        }
    }

    DecoderTaps m_taps;
    int m_threads;
    std::vector<Band> m_bands;
};

template <int kC>
inline void gather(const float* image, int width, int height, int c, const DecoderTap* taps, int count, float* out) {
    const int channels = kC > 0 ? kC : c;
    for (int k = 0; k < channels; ++k) out[k] = 0.0f;
    for (int t = 0; t < count; ++t) {
        const TapCorners q = tapCorners(taps[t], width, height);
        const float* p00 = image + (static_cast<std::size_t>(q.y0) * width + q.x0) * channels;
        const float* p01 = image + (static_cast<std::size_t>(q.y0) * width + q.x1) * channels;
        const float* p10 = image + (static_cast<std::size_t>(q.y1) * width + q.x0) * channels;
        const float* p11 = image + (static_cast<std::size_t>(q.y1) * width + q.x1) * channels;
        for (int k = 0; k < channels; ++k) out[k] += q.w00 * p00[k] + q.w01 * p01[k] + q.w10 * p10[k] + q.w11 * p11[k];
    }
}

// Adds one tap's corner weights times value into a band's buffer (rows from `lo`).
template <int kC>
inline void splatCorners(float* buffer, int lo, int width, int c, const TapCorners& q, const float* value) {
    const int channels = kC > 0 ? kC : c;
    float* p00 = buffer + (static_cast<std::size_t>(q.y0 - lo) * width + q.x0) * channels;
    float* p01 = buffer + (static_cast<std::size_t>(q.y0 - lo) * width + q.x1) * channels;
    float* p10 = buffer + (static_cast<std::size_t>(q.y1 - lo) * width + q.x0) * channels;
    float* p11 = buffer + (static_cast<std::size_t>(q.y1 - lo) * width + q.x1) * channels;
    for (int k = 0; k < channels; ++k) {
        p00[k] += q.w00 * value[k];
        p01[k] += q.w01 * value[k];
        p10[k] += q.w10 * value[k];
        p11[k] += q.w11 * value[k];
    }
}

// Adds the taps' weights times value into a band's buffer (rows from `lo`).
template <int kC>
inline void splat(float* buffer, int lo, int width, int height, int c, const DecoderTap* taps, int count,
                  const float* value) {
    for (int t = 0; t < count; ++t) splatCorners<kC>(buffer, lo, width, c, tapCorners(taps[t], width, height), value);
}

// Adds the taps' squared corner weights into a band's `squares` (rows from `lo`): diag(D^T D)
// approximated per CoNUS pixel (exact where no two taps of one output pixel share a CoNUS pixel,
// i.e. wherever the view magnifies).
inline void splatSquares(float* squares, int lo, int width, int height, const DecoderTap* taps, int count) {
    for (int k = 0; k < count; ++k) {
        const TapCorners q = tapCorners(taps[k], width, height);
        squares[(q.y0 - lo) * width + q.x0] += q.w00 * q.w00;
        squares[(q.y0 - lo) * width + q.x1] += q.w01 * q.w01;
        squares[(q.y1 - lo) * width + q.x0] += q.w10 * q.w10;
        squares[(q.y1 - lo) * width + q.x1] += q.w11 * q.w11;
    }
}

// view = D image (view: width x height, the operator's channels).
template <int kC>
void forwardPass(DecoderOperator& op, const float* image, int c, float* view) {
    const DecoderTaps& taps = op.taps();
    const int channels = kC > 0 ? kC : c;
    op.forEachBand([&](Band& band, DecoderTaps::Scratch& scratch) {
        for (int y = band.y0; y < band.y1; ++y) {
            float* row = view + static_cast<std::size_t>(y) * taps.width() * channels;
            taps.row(y, scratch, [&](int x, const DecoderTap* t, int count) {
                gather<kC>(image, taps.conusWidth(), taps.conusHeight(), channels, t, count, row + x * channels);
            });
        }
    });
}

// Each band's sum of |D image|^2 (ops.bandSum() totals them).
template <int kC>
void normPass(DecoderOperator& op, const float* image, int c) {
    const DecoderTaps& taps = op.taps();
    const int channels = kC > 0 ? kC : c;
    op.forEachBand([&](Band& band, DecoderTaps::Scratch& scratch) {
        std::vector<float> value(channels);
        double sum = 0;
        for (int y = band.y0; y < band.y1; ++y)
            taps.row(y, scratch, [&](int, const DecoderTap* t, int count) {
                gather<kC>(image, taps.conusWidth(), taps.conusHeight(), channels, t, count, value.data());
                for (int k = 0; k < channels; ++k) sum += double(value[k]) * value[k];
            });
        band.sum = sum;
    });
}

// r = source - D image per pixel; each band's sum of |r|^2, and (when `adjoint`) r splatted into
// the band buffers (D^T r once summed), and (when `diagonal`) the squared weights into `squares`
// (diag(D^T D) once summed): the same walk of the taps. With a null image, r = source.
template <int kC>
void residualPass(DecoderOperator& op, const float* image, const float* source, int c, bool adjoint,
                  bool diagonal = false) {
    const DecoderTaps& taps = op.taps();
    const int channels = kC > 0 ? kC : c;
    op.forEachBand([&](Band& band, DecoderTaps::Scratch& scratch) {
        std::vector<float> value(channels);
        double sum = 0;
        for (int y = band.y0; y < band.y1; ++y) {
            const float* row = source + static_cast<std::size_t>(y) * taps.width() * channels;
            taps.row(y, scratch, [&](int x, const DecoderTap* t, int count) {
                if (image) gather<kC>(image, taps.conusWidth(), taps.conusHeight(), channels, t, count, value.data());
                else std::fill(value.begin(), value.end(), 0.0f);
                for (int k = 0; k < channels; ++k) {
                    value[k] = row[x * channels + k] - value[k];
                    sum += double(value[k]) * value[k];
                }
                if (adjoint)
                    splat<kC>(band.buffer.data(), band.lo, taps.conusWidth(), taps.conusHeight(), channels, t, count,
                              value.data());
                if (diagonal) splatSquares(band.squares.data(), band.lo, taps.conusWidth(), taps.conusHeight(), t, count);
            });
        }
        band.sum = sum;
    });
}

// The normal equations' matrix A = D^T D, assembled on the CoNUS grid in one walk of the taps.
// An output pixel's row d of D (its taps' corner weights, merged where two fall on one CoNUS
// pixel) adds d d^T to A. Where d lies within one 2x2 block of CoNUS pixels (every magnified output
// pixel, and minified ones whose taps stay that close) that is a 3x3 stencil, kept per CoNUS
// pixel as its upper half: the pixel's own coefficient and those with its right, lower,
// lower-right and lower-left neighbours (kStencil values). A wider d is kept as it is (a wide
// row), and A applied through it as d (d . x).
constexpr int kStencil = 5;
enum StencilEntry { kOwn, kRight, kBelow, kBelowRight, kBelowLeft };
// The wide rows' entries the assembly may keep, per CoNUS pixel. Where the view minifies by f
// along both axes an output pixel's row of D has about (f + 1)^2 entries for f^2 CoNUS pixels
// (its taps' corners, merged): at most 2.25 a CoNUS pixel there (f = 2). Beyond this many (a map
// that minifies almost everywhere, taps far apart) the fit walks the taps every iteration instead.
constexpr std::int64_t kWideEntriesPerPixel = 4;

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

// A = D^T D as assembled (assemblePass), summed over the bands: the stencil of every CoNUS pixel
// and the wide rows in walk order (CSR: row r's entries are start[r] .. start[r + 1]).
struct NormalMatrix {
    int width = 0, height = 0;
    std::vector<float> stencil;
    std::vector<std::int32_t> start{0}, index;
    std::vector<float> weight;

    // A's diagonal.
    std::vector<float> diagonal() const {
        std::vector<float> d(static_cast<std::size_t>(width) * height);
        for (std::size_t i = 0; i < d.size(); ++i) d[i] = stencil[i * kStencil + kOwn];
        for (std::size_t k = 0; k < index.size(); ++k) d[index[k]] += weight[k] * weight[k];
        return d;
    }

    // out = A x (`channels` values a pixel).
    void apply(const float* x, float* out, int channels, int threads) const {
        const int wc = width, hc = height;
        parallelRows(hc, threads, [&](int y0, int y1) {
            for (int y = y0; y < y1; ++y)
                for (int xi = 0; xi < wc; ++xi) {
                    const std::size_t i = static_cast<std::size_t>(y) * wc + xi;
                    const float* s = stencil.data() + i * kStencil;
                    const std::size_t row = static_cast<std::size_t>(wc) * kStencil;
                    float* o = out + i * channels;
                    const float* xc = x + i * channels;
                    const std::ptrdiff_t step = std::ptrdiff_t(wc) * channels;  // signed: rows above are at -step
                    const bool left = xi > 0, right = xi + 1 < wc, up = y > 0, down = y + 1 < hc;
                    for (int k = 0; k < channels; ++k) {
                        float v = s[kOwn] * xc[k];
                        if (right) v += s[kRight] * xc[channels + k];
                        if (left) v += s[kRight - kStencil] * xc[k - channels];
                        if (down) {
                            v += s[kBelow] * xc[step + k];
                            if (right) v += s[kBelowRight] * xc[step + channels + k];
                            if (left) v += s[kBelowLeft] * xc[step - channels + k];
                        }
                        if (up) {
                            v += (s - row)[kBelow] * xc[k - step];
                            if (left) (v += (s - row - kStencil)[kBelowRight] * xc[k - step - channels]);
                            if (right) v += (s - row + kStencil)[kBelowLeft] * xc[k - step + channels];
                        }
                        o[k] = v;
                    }
                }
        });
        // The wide rows, in order (a few, where the view minifies): d (d . x).
        std::vector<double> along(channels);
        for (std::size_t r = 0; r + 1 < start.size(); ++r) {
            std::fill(along.begin(), along.end(), 0.0);
            for (std::int32_t k = start[r]; k < start[r + 1]; ++k)
                for (int c = 0; c < channels; ++c) along[c] += double(weight[k]) * x[std::size_t(index[k]) * channels + c];
            for (std::int32_t k = start[r]; k < start[r + 1]; ++k)
                for (int c = 0; c < channels; ++c) out[std::size_t(index[k]) * channels + c] += float(weight[k] * along[c]);
        }
    }
};

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
    if (!assembled) return false;
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
        std::vector<float>().swap(band.stencil);
        std::vector<float>().swap(band.buffer);
    }
    a.start.push_back(static_cast<std::int32_t>(a.index.size()));
    return true;
}

double dot(const std::vector<float>& a, const std::vector<float>& b) {
    double sum = 0;
    for (std::size_t i = 0; i < a.size(); ++i) sum += double(a[i]) * b[i];
    return sum;
}

void checkChannels(const Image& a, const Image& b, const char* what) {
    if (a.channels != b.channels)
        throw Error(ErrorCode::InvalidArgument, std::string(what) + ": the CoNUS image and the source have different channels");
}

// The fitted channels' values of `image`, packed (every channel but Z).
std::vector<float> pack(const Image& image, const std::vector<int>& fitted) {
    const std::size_t pixels = static_cast<std::size_t>(image.width) * image.height, c = image.channels.size();
    std::vector<float> out(pixels * fitted.size());
    for (std::size_t p = 0; p < pixels; ++p)
        for (std::size_t k = 0; k < fitted.size(); ++k) out[p * fitted.size() + k] = image.pixels[p * c + fitted[k]];
    return out;
}

// Per CoNUS pixel, how far the encoder low-passed its footprint's long axis (encode.h's rule): the
// filter's extent beyond the unit box, in CoNUS pixels, at most 1; 0 where it kept the box.
std::vector<float> lowPassShare(const SamplingMap& map, int sourceWidth, int sourceHeight, int width, int height,
                                int threads) {
    std::vector<float> share(static_cast<std::size_t>(width) * height);
    const FootprintField field(map);
    const double uniform = uniformSpacing(sourceWidth, sourceHeight, width, height);
    const glm::dvec2 scale(sourceWidth, sourceHeight);
    parallelRows(height, threads, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y)
            for (int x = 0; x < width; ++x) {
                const glm::dmat2 inverse = field.inverseJacobian(map.undistort({(x + 0.5) / width, (y + 0.5) / height}));
                const FootprintPlan plan =
                    planFootprint(inverse[0] / double(width) * scale, inverse[1] / double(height) * scale, uniform);
                share[static_cast<std::size_t>(y) * width + x] =
                    static_cast<float>(std::clamp(std::max(plan.extent.x, plan.extent.y) - 1.0, 0.0, 1.0));
            }
    });
    return share;
}

// Per CoNUS pixel, how much of the Local fit's correction it takes: 1 / (1 + damping + hold *
// low-pass share), times min(1, short axis in source pixels)^2 (fit.h).
std::vector<float> localWeights(const SamplingMap& map, int sourceWidth, int sourceHeight, int width, int height,
                                const FitOptions& options) {
    std::vector<float> weight(static_cast<std::size_t>(width) * height);
    const FootprintField field(map);
    const double uniform = uniformSpacing(sourceWidth, sourceHeight, width, height);
    const glm::dvec2 scale(sourceWidth, sourceHeight);
    parallelRows(height, options.threads, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y)
            for (int x = 0; x < width; ++x) {
                const glm::dmat2 inverse = field.inverseJacobian(map.undistort({(x + 0.5) / width, (y + 0.5) / height}));
                const glm::dvec2 a = inverse[0] / double(width) * scale, b = inverse[1] / double(height) * scale;
                const FootprintPlan plan = planFootprint(a, b, uniform);
                const double share = std::clamp(std::max(plan.extent.x, plan.extent.y) - 1.0, 0.0, 1.0);
                // The short axis: |det| / long axis, from the singular values of [a b].
                const double p = glm::dot(a, a), q = glm::dot(a, b), r = glm::dot(b, b);
                const double mean = 0.5 * (p + r), half = std::sqrt(0.25 * (p - r) * (p - r) + q * q);
                const double minor = std::sqrt(std::max(0.0, mean - half));
                const double fade = std::min(1.0, minor * minor);
                weight[static_cast<std::size_t>(y) * width + x] =
                    static_cast<float>(fade / (1.0 + options.damping + options.holdLowPass * share));
            }
    });
    return weight;
}

// The Local fit's inverse kernel along one axis: K = [q, 1 - 2q, q] has the inverse
// h[n] = p^|n| / sqrt(1 - 4q) with p = (sqrt(1 - 4q) - (1 - 2q)) / (2q), the root of
// q z^2 + (1 - 2q) z + q inside the unit circle; cut where |h| < 1e-3 and scaled to sum to 1.
std::vector<float> localInverse(double q) {
    const double root = std::sqrt(1.0 - 4.0 * q);
    const double pole = (root - (1.0 - 2.0 * q)) / (2.0 * q);
    std::vector<float> h;
    std::vector<double> taps;
    for (double v = 1.0 / root; std::abs(v) >= 1e-3 && taps.size() < 16; v *= pole) taps.push_back(v);
    // The cut series, scaled so that a constant stays that constant.
    double sum = taps[0];
    for (std::size_t n = 1; n < taps.size(); ++n) sum += 2.0 * taps[n];
    for (const double v : taps) h.push_back(static_cast<float>(v / sum));
    return h;
}

// x (width x height, `channels` values a pixel) convolved with the symmetric kernel h along rows
// (step = channels) or columns (step = a row), clamped at the edges, into out.
void convolveAxis(const float* x, float* out, int width, int height, int channels, const std::vector<float>& h,
                  bool alongRows, int threads) {
    const int radius = static_cast<int>(h.size()) - 1;
    parallelRows(height, threads, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y)
            for (int xi = 0; xi < width; ++xi) {
                float* o = out + (static_cast<std::size_t>(y) * width + xi) * channels;
                const auto at = [&](int dx, int dy) {
                    const int cx = std::clamp(xi + dx, 0, width - 1), cy = std::clamp(y + dy, 0, height - 1);
                    return x + (static_cast<std::size_t>(cy) * width + cx) * channels;
                };
                for (int c = 0; c < channels; ++c) o[c] = h[0] * at(0, 0)[c];
                for (int n = 1; n <= radius; ++n) {
                    const float* lo = alongRows ? at(-n, 0) : at(0, -n);
                    const float* hi = alongRows ? at(n, 0) : at(0, n);
                    for (int c = 0; c < channels; ++c) o[c] += h[n] * (lo[c] + hi[c]);
                }
            }
    });
}

// The Local fit (fit.h) on the packed fitted channels x of a width x height CoNUS image.
void localFit(std::vector<float>& x, int width, int height, int channels, const std::vector<float>& weight,
              double side, int threads) {
    const std::vector<float> h = localInverse(side);
    std::vector<float> across(x.size()), both(x.size());
    convolveAxis(x.data(), across.data(), width, height, channels, h, true, threads);
    convolveAxis(across.data(), both.data(), width, height, channels, h, false, threads);
    parallelRows(height, threads, [&](int y0, int y1) {
        for (std::size_t i = std::size_t(y0) * width; i < std::size_t(y1) * width; ++i)
            for (int c = 0; c < channels; ++c) {
                const std::size_t k = i * channels + c;
                x[k] += weight[i] * (both[k] - x[k]);
            }
    });
}

std::atomic<bool> g_forcePasses{false};

}  // namespace

void forceFitPasses(bool passes) { g_forcePasses.store(passes, std::memory_order_relaxed); }
bool fitPassesForced() { return g_forcePasses.load(std::memory_order_relaxed); }

Image fitForward(const Image& conus, const SamplingMap& map, int width, int height, int threads) {
    checkImage(conus, "fitForward");
    checkOutputSize(width, height, "fitForward");
    DecoderOperator op(map, conus.width, conus.height, width, height, threads);
    Image view = makeOutput(conus, width, height);
    dispatchChannels(conus.channelCount(), [&]<int kC>() {
        forwardPass<kC>(op, conus.pixels.data(), conus.channelCount(), view.pixels.data());
    });
    return view;
}

Image fitAdjoint(const Image& view, const SamplingMap& map, int conusWidth, int conusHeight, int threads) {
    checkImage(view, "fitAdjoint");
    checkOutputSize(conusWidth, conusHeight, "fitAdjoint");
    DecoderOperator op(map, conusWidth, conusHeight, view.width, view.height, threads);
    Image out = makeOutput(view, conusWidth, conusHeight);
    op.clearBuffers(view.channelCount());
    dispatchChannels(view.channelCount(), [&]<int kC>() {
        residualPass<kC>(op, nullptr, view.pixels.data(), view.channelCount(), true);
    });
    op.sumBuffers(out.pixels.data(), view.channelCount());
    return out;
}

Image fitNormalProduct(const Image& x, const SamplingMap& map, int width, int height, std::size_t* wideRows, int threads) {
    checkImage(x, "fitNormalProduct");
    checkOutputSize(width, height, "fitNormalProduct");
    DecoderOperator op(map, x.width, x.height, width, height, threads);
    const std::vector<float> zeros(static_cast<std::size_t>(width) * height * x.channelCount(), 0.0f);
    NormalMatrix a;
    std::vector<float> b;
    double squares = 0;
    if (!assembleNormal(op, zeros.data(), x.channelCount(), a, b, squares))
        throw Error(ErrorCode::InvalidArgument, "fitNormalProduct: the view minifies too much of the image to assemble");
    if (wideRows) *wideRows = a.start.size() - 1;
    Image out = makeOutput(x, x.width, x.height);
    a.apply(x.pixels.data(), out.pixels.data(), x.channelCount(), threads);
    return out;
}

}  // namespace detail

FitResult fitToDecoder(const Image& source, const SamplingMap& map, Image& conus, const FitOptions& options) {
    checkImage(source, "fitToDecoder");
    checkImage(conus, "fitToDecoder");
    detail::checkChannels(source, conus, "fitToDecoder");
    if (options.iterations < 0 || options.iterations > 1000)
        throw Error(ErrorCode::InvalidArgument,
                    "fitToDecoder: " + std::to_string(options.iterations) + " iterations (0 .. 1000 allowed)");
    for (const double d : {options.damping, options.holdLowPass})
        if (!(d >= 0.0) || !std::isfinite(d))
            throw Error(ErrorCode::InvalidArgument, "fitToDecoder: damping " + std::to_string(d) +
                                                        " must be finite and at least 0");
    if (!(options.localSide > 0.0 && options.localSide < 0.25))
        throw Error(ErrorCode::InvalidArgument,
                    "fitToDecoder: the local fit's side weight " + std::to_string(options.localSide) + " must be in (0, 0.25)");

    std::vector<int> fitted;
    for (int c = 0; c < conus.channelCount(); ++c)
        if (conus.channels[c] != "Z") fitted.push_back(c);
    FitResult result;
    if (fitted.empty()) return result;
    const int channels = static_cast<int>(fitted.size());
    const bool all = channels == conus.channelCount();
    // Work on packed copies of the fitted channels unless they are all of them.
    std::vector<float> x = all ? conus.pixels : detail::pack(conus, fitted);
    const auto finish = [&] {
        result.minimum = x.empty() ? 0.0f : x[0];
        result.maximum = result.minimum;
        for (float v : x) {
            result.negatives += v < 0.0f;
            result.minimum = std::min(result.minimum, v);
            result.maximum = std::max(result.maximum, v);
        }
        if (all) {
            conus.pixels = std::move(x);
        } else {
            const std::size_t c = conus.channels.size();
            for (std::size_t px = 0; px < std::size_t(conus.width) * conus.height; ++px)
                for (int k = 0; k < channels; ++k) conus.pixels[px * c + fitted[k]] = x[px * channels + k];
        }
        if (options.progress) options.progress(1.0);
        return result;
    };
    if (options.method == FitMethod::Local) {
        const std::vector<float> weight =
            detail::localWeights(map, source.width, source.height, conus.width, conus.height, options);
        detail::localFit(x, conus.width, conus.height, channels, weight, options.localSide, options.threads);
        return finish();
    }
    std::vector<float> packedSource;
    if (!all) packedSource = detail::pack(source, fitted);
    const float* s = all ? source.pixels.data() : packedSource.data();

    detail::DecoderOperator op(map, conus.width, conus.height, source.width, source.height, options.threads);
    const std::size_t pixels = static_cast<std::size_t>(conus.width) * conus.height;
    const std::size_t values = pixels * channels;
    const double samples = double(source.width) * source.height * channels;
    // Per CoNUS pixel: the damping, plus holdLowPass where the encoder low-passed a long axis.
    std::vector<float> hold(pixels, static_cast<float>(options.damping));
    if (options.holdLowPass > 0) {
        const std::vector<float> share =
            detail::lowPassShare(map, source.width, source.height, conus.width, conus.height, options.threads);
        for (std::size_t i = 0; i < pixels; ++i) hold[i] += static_cast<float>(options.holdLowPass) * share[i];
    }
    const bool damped = std::any_of(hold.begin(), hold.end(), [](float h) { return h > 0; });
    const int passes = 1 + 2 * options.iterations;  // a residual (with the diagonal), per iteration a norm and a residual
    int passesDone = 0;
    const auto passDone = [&] {
        if (options.progress) options.progress(double(++passesDone) / passes);
    };

    // Jacobi preconditioner: 1 / diag(D^T D) (with the damping, (1 + lambda) diag); 0 where no tap
    // reaches, so those pixels never move. diag comes with the first residual's pass.
    std::vector<float> diag(pixels), precondition(pixels);
    const auto findPreconditioner = [&] {
        op.sumBuffers(diag.data(), 1, &detail::Band::squares);
        float largest = 0;
        for (float d : diag) largest = std::max(largest, d);
        for (std::size_t i = 0; i < pixels; ++i)
            precondition[i] = diag[i] > 1e-6f * largest ? 1.0f / ((1.0f + hold[i]) * diag[i]) : 0.0f;
    };

    const std::vector<float> x0 = damped ? x : std::vector<float>{};
    std::vector<float> z(values), p(values);
    // r = s - D x with sum |r|^2, and z = D^T r - lambda diag (x - x0) when asked; returns the objective.
    double lastData = 0;  // |s - D x|^2 for the x of the last step recorded
    const auto record = [&](double data, double penalty) {
        lastData = data;
        const double mse = data / samples;
        const int iteration = static_cast<int>(result.steps.size());
        result.steps.push_back({iteration, std::sqrt(mse), 10 * std::log10(1.0 / std::max(mse, 1e-30)), data + penalty});
        passDone();
    };
    const auto penaltyOf = [&] {
        double penalty = 0;
        if (damped)
            for (std::size_t px = 0, i = 0; px < pixels; ++px) {
                const float w = hold[px] * diag[px];
                for (int k = 0; k < channels; ++k, ++i) {
                    const float d = x[i] - x0[i];
                    penalty += double(w) * d * d;
                }
            }
        return penalty;
    };
    const auto residual = [&](bool adjoint, bool diagonal) {
        if (adjoint) op.clearBuffers(channels);
        if (diagonal) op.clearBuffers(1, &detail::Band::squares);
        detail::dispatchChannels(channels, [&]<int kC>() {
            detail::residualPass<kC>(op, x.data(), s, channels, adjoint, diagonal);
        });
        const double data = op.bandSum();
        if (diagonal) findPreconditioner();
        if (adjoint) op.sumBuffers(z.data(), channels);
        if (damped && adjoint)
            for (std::size_t i = 0; i < values; ++i) z[i] -= hold[i / channels] * diag[i / channels] * (x[i] - x0[i]);
        record(data, penaltyOf());
    };
    const auto applyPreconditioner = [&](std::vector<float>& out) {
        for (std::size_t px = 0, i = 0; px < pixels; ++px)
            for (int k = 0; k < channels; ++k, ++i) out[i] = precondition[px] * z[i];
    };

    // The normal equations assembled on the CoNUS grid in one walk of the taps (A = D^T D, b =
    // D^T s): the same iterations then cost a few stencil products on the CoNUS image instead of
    // two walks over the source each. |s - D x|^2 = |s|^2 - 2 <x, b> + <x, A x>, in double.
    detail::NormalMatrix normal;
    std::vector<float> b;
    double squares = 0;
    if (options.iterations > 0 && !detail::fitPassesForced() && detail::assembleNormal(op, s, channels, normal, b, squares)) {
        diag = normal.diagonal();
        float largest = 0;
        for (float d : diag) largest = std::max(largest, d);
        for (std::size_t i = 0; i < pixels; ++i)
            precondition[i] = diag[i] > 1e-6f * largest ? 1.0f / ((1.0f + hold[i]) * diag[i]) : 0.0f;
        // zp holds A p as well, until the preconditioner needs it (every vector here is a fresh
        // CoNUS image's worth of pages).
        std::vector<float> zp(values);
        // z = b - A x - lambda diag (x - x0) (A x made in z), and the step recorded.
        const auto residualOfX = [&] {
            normal.apply(x.data(), z.data(), channels, options.threads);
            double xb = 0, xax = 0;
            for (std::size_t px = 0, i = 0; px < pixels; ++px) {
                const float w = damped ? hold[px] * diag[px] : 0.0f;
                for (int k = 0; k < channels; ++k, ++i) {
                    xb += double(x[i]) * b[i];
                    xax += double(x[i]) * z[i];
                    z[i] = b[i] - z[i] - (damped ? w * (x[i] - x0[i]) : 0.0f);
                }
            }
            record(std::max(0.0, squares - 2.0 * xb + xax), penaltyOf());
        };
        residualOfX();
        applyPreconditioner(p);
        double gamma = detail::dot(z, p);
        for (int it = 1; it <= options.iterations && gamma > 0; ++it) {
            normal.apply(p.data(), zp.data(), channels, options.threads);
            double delta = detail::dot(p, zp);  // |D p|^2
            if (damped)
                for (std::size_t px = 0, i = 0; px < pixels; ++px) {
                    const double w = double(hold[px]) * diag[px];
                    for (int k = 0; k < channels; ++k, ++i) delta += w * p[i] * p[i];
                }
            if (!(delta > 0)) break;
            const float alpha = static_cast<float>(gamma / delta);
            for (std::size_t i = 0; i < values; ++i) x[i] += alpha * p[i];
            residualOfX();
            if (it == options.iterations) break;
            applyPreconditioner(zp);
            const double next = detail::dot(z, zp);
            const float beta = static_cast<float>(next / gamma);
            for (std::size_t i = 0; i < values; ++i) p[i] = zp[i] + beta * p[i];
            gamma = next;
        }
        return finish();
    }

    residual(options.iterations > 0, options.iterations > 0);
    applyPreconditioner(p);
    double gamma = detail::dot(z, p);
    std::vector<float> zp(values);
    for (int it = 1; it <= options.iterations && gamma > 0; ++it) {
        detail::dispatchChannels(channels, [&]<int kC>() { detail::normPass<kC>(op, p.data(), channels); });
        const double dataDelta = op.bandSum();  // |D p|^2
        double delta = dataDelta;
        if (damped)
            for (std::size_t i = 0; i < values; ++i)
                delta += double(hold[i / channels]) * diag[i / channels] * p[i] * p[i];
        passDone();
        if (!(delta > 0)) break;
        const float alpha = static_cast<float>(gamma / delta);
        const bool last = it == options.iterations;
        // After the last step no adjoint is needed, only |s - D x|^2 to report: along the step it
        // is |r|^2 - 2 alpha <D p, r> + alpha^2 |D p|^2, with <D p, r> = <p, D^T r> and
        // D^T r = z + lambda diag (x - x0), all on the CoNUS image: no pass over the source.
        double pDtr = 0;
        if (last)
            for (std::size_t i = 0; i < values; ++i)
                pDtr += double(p[i]) * (z[i] + (damped ? hold[i / channels] * diag[i / channels] * (x[i] - x0[i]) : 0.0f));
        for (std::size_t i = 0; i < values; ++i) x[i] += alpha * p[i];
        if (last) {
            record(std::max(0.0, lastData - 2.0 * alpha * pDtr + double(alpha) * alpha * dataDelta), penaltyOf());
            break;
        }
        residual(true, false);
        applyPreconditioner(zp);
        const double next = detail::dot(z, zp);
        const float beta = static_cast<float>(next / gamma);
        for (std::size_t i = 0; i < values; ++i) p[i] = zp[i] + beta * p[i];
        gamma = next;
    }

    return finish();
}

}  // namespace conus::codec
