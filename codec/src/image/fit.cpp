// The encoder fitted to its decoder (fit.h): Jacobi-preconditioned CGLS through the decoder's taps.
//
// Each pass walks the output rows in bands, one thread per band at a time. A gather (D) reads the
// CoNUS image; a splat (D^T) writes into the band's own buffer, which spans only the CoNUS rows
// its taps reach (found once, up front), and the buffers are summed row by row afterwards: no
// locks, no per-source-pixel storage, and the same sums whatever the thread count. The residual
// s - D x is recomputed from x in every pass instead of being stored (a 4096^2 source would need
// 192 MiB per vector), which also keeps it from drifting; after the last step only its norm is
// wanted (the PSNR reported), and that follows from the step's own sums without a pass.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
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

// Adds the taps' weights times value into a band's buffer (rows from `lo`).
template <int kC>
inline void splat(float* buffer, int lo, int width, int height, int c, const DecoderTap* taps, int count,
                  const float* value) {
    const int channels = kC > 0 ? kC : c;
    for (int t = 0; t < count; ++t) {
        const TapCorners q = tapCorners(taps[t], width, height);
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

}  // namespace

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
            for (std::size_t i = 0; i < values; ++i) {
                const float d = x[i] - x0[i], w = hold[i / channels] * diag[i / channels];
                penalty += double(w) * d * d;
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
        for (std::size_t i = 0; i < values; ++i) out[i] = precondition[i / channels] * z[i];
    };

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
