// Private: the decoder as the fit's linear operator D over bands of output rows (DecoderOperator),
// its passes (D, D^T, |D x|^2, the residual s - D x), and the normal equations A = D^T D assembled
// on the CoNUS grid (NormalMatrix, assembleNormal in fit_normal.cpp). Shared by fit.cpp, which
// solves with them, and fit_normal.cpp, which assembles them; fit.cpp's opening comment says how.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "conus/core/parallel.h"
#include "fit_pvt.h"
#include "resample_pvt.h"

namespace conus::codec::detail {
inline namespace fit_operator {

// Output rows per block when the reach of the bands is measured; bands are runs of blocks.
constexpr int kBlockRows = 8;
// Bands: as many whatever the thread count, so that the sums come out the same (32: enough for 16
// threads to balance uneven rows), halved while their buffers would exceed this many CoNUS images
// in all. A band's buffers span every CoNUS row its source rows reach, and where the map bends
// (a focus) the bands' reaches overlap: on codec_bench's two-focus map 32 bands buffered 3.6
// images (about 115 MiB for the normal equations of a 1024x1024 RGB image), zeroed, faulted in
// and summed on every fit; 8 bands there buffer 1.7 and take a quarter off the fit's CPU, at the
// price of using at most 8 threads on such a map (bench/notes/2026-12-08-fit-buffers.md).
constexpr int kBands = 32;
constexpr int kMaxBufferImages = 2;

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
            for (int b = b0; b < b1; ++b) {
                // The block's reach kept in locals, stored once: neighbouring blocks' bounds share a
                // cache line, and the threads take neighbouring blocks.
                int blockLo = hc, blockHi = -1;
                for (int y = b * kBlockRows; y < std::min(rows, (b + 1) * kBlockRows); ++y)
                    m_taps.row(y, scratch, [&](int, const DecoderTap* taps, int count) {
                        for (int k = 0; k < count; ++k) {
                            const TapCorners c = tapCorners(taps[k], m_taps.conusWidth(), hc);
                            blockLo = std::min(blockLo, c.y0);
                            blockHi = std::max(blockHi, c.y1);
                        }
                    });
                lo[b] = blockLo;
                hi[b] = blockHi;
            }
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
                    double& squares);

}  // namespace fit_operator
}  // namespace conus::codec::detail
