// The encoder fitted to its decoder (fit.h): Jacobi-preconditioned conjugate gradients on the
// normal equations D^T D c = D^T s.
//
// Usually they are assembled on the CoNUS grid in one walk of the decoder's taps over the source
// (assemblePass, fit_normal.cpp): D^T s, |s|^2, and A = D^T D as a 3x3 stencil per CoNUS pixel
// (an output pixel's taps reach one 2x2 block of CoNUS pixels wherever the view magnifies), with
// the few output pixels whose taps reach wider (where it minifies) kept as rows of D. Every
// iteration is then a few stencil products on the CoNUS image, a sixteenth of the source's pixels
// at the default encode's 1/16, instead of two walks over the source. Where the view minifies much
// of the image (more wide rows than kWideEntriesPerPixel allows) the fit walks the taps every
// iteration (CGLS):
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
#include "fit_operator_pvt.h"
#include "fit_pvt.h"
#include "resample_pvt.h"

namespace conus::codec {
namespace detail {
namespace {

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
                share[static_cast<std::size_t>(y) * width + x] = plan.lowPassShare();
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
                const double share = plan.lowPassShare();
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
        const bool given = options.lowPassShare && options.lowPassShare->size() == pixels;
        const std::vector<float> found =
            given ? std::vector<float>{}
                  : detail::lowPassShare(map, source.width, source.height, conus.width, conus.height, options.threads);
        const std::vector<float>& share = given ? *options.lowPassShare : found;
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

    // The image the damping holds x near, x as it starts: the encode's own, which `conus` keeps
    // until finish() (a copy of the packed channels where only some are fitted).
    const std::vector<float> packedX0 = damped && !all ? x : std::vector<float>{};
    const float* x0 = all ? conus.pixels.data() : packedX0.data();
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
    // The next conjugate direction: zp = M z, p = zp + beta p with beta = <z, zp> / gamma; gamma
    // becomes <z, zp>.
    const auto nextDirection = [&](std::vector<float>& zp, double& gamma) {
        applyPreconditioner(zp);
        const double next = detail::dot(z, zp);
        const float beta = static_cast<float>(next / gamma);
        for (std::size_t i = 0; i < values; ++i) p[i] = zp[i] + beta * p[i];
        gamma = next;
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
            nextDirection(zp, gamma);
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
        nextDirection(zp, gamma);
    }

    return finish();
}

}  // namespace conus::codec
