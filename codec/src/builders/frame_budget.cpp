// The whole-frame loss, tile loss and ROI gain of a map, predicted by the band model and confirmed by a
// real encode; the searches over it are frame_budget_search.cpp's.
#include "conus/codec/builders/frame_budget.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>

#include "conus/codec/image/decode.h"
#include "conus/codec/image/encode.h"
#include "conus/codec/image/fit.h"
#include "conus/core/error.h"
#include "conus/core/parallel.h"
#include "../image/resize_rows_pvt.h"
#include "display_codes_pvt.h"

namespace conus::codec {
namespace {

// The band model's constants (frame_budget.h: S(sigma) = a * sum_j E_j * R(log2 sigma - j - b),
// R a smoothstep from 0 at t = -c to 1 at t = c; a footprint of axes sigma1 >= sigma2 taken as
// one of sigma1^w sigma2^(1-w)). Fitted by `bench/budget_check.py --fit` on the six photographs of
// bench/quality_targets.PHOTOS (at most 1280 px wide, 8-bit sRGB, one focus per region at k 1.5,
// 2.5, 4 and 6 with --exact-k, fitted and --fast), tile by tile against real encodes and `conus
// uniform`, by least squares on log(e + f), then for the whole-frame and p95 tile losses: the
// uniform image's error is the bands finer than its spacing (b = c = 0.5: at a 1/4 downscale,
// bands 0 and 1, as the box pyramid's arithmetic says); the CoNUS image loses more along a
// stretched footprint than its long axis alone says (w > 1). Per tile the model is within about
// 1.6 dB (uniform) and 3.5 dB (CoNUS, rms); whence the confirming encode (FrameErrorModel::confirmed).
// bench/notes/2026-12-06-budget-model.md.
}  // namespace

struct FrameErrorModel::Confirming {
    std::once_flag once;
    std::vector<double> errors;  // the uniform image's, per tile
    // The source's pyramid levels (encode.h), kept between the confirming encodes (the uniform
    // image's too) so that each level is built once; one encode at a time uses them.
    std::mutex levelsInUse;
    EncodeLevels levels;
};

struct FrameErrorModel::BandFit {
    double scale;    // a
    double shift;    // b
    double stretch;  // w
};

namespace {
using BandFit = FrameErrorModel::BandFit;
constexpr double kHalfWidth = 0.5;                    // c
constexpr BandFit kUniformFit{0.832, 0.5, 0.5};       // area downsample, bilinear resize (isotropic: w moot)
constexpr BandFit kConusFitted{1.0, 1.5, 1.2};        // encode, fit to the decoder, decode
constexpr BandFit kConusFiltered{0.832, 1.5, 1.6};    // encode alone (`--fast`), decode

// Tiles of the tile loss: max(W, H) / kTilesPerSide source pixels a side (bench/quality.py's tiles),
// and the floor added to both errors of a tile and of the frame: on a flat picture a tiny error
// twice as large is no loss. Displayed: bench/quality.py's (2/255)^2 of 8-bit sRGB; linear: about
// that near mid-grey.
constexpr int kTilesPerSide = 32;
constexpr double kDisplayFloor = (2.0 / 255.0) * (2.0 / 255.0);
constexpr double kLinearFloor = (1.5 / 255.0) * (1.5 / 255.0);
// The whole frame's: PSNR as bench/quality.py takes it has none, but its 8-bit pictures carry the
// rounding's error (a uniform error of one code: 1/12 of a code squared) in both images, which a
// prediction of the unrounded errors adds; data keeps the tiles' floor.
constexpr double kDisplayFrameFloor = (1.0 / 255.0) * (1.0 / 255.0) / 12.0;
constexpr double kTilePercentile = 0.95;
constexpr double kWorstTilesPercentile = 0.99;
// Bands of the pyramid: detail up to 2^kMaxLevels source pixels (a 1/256 downscale).
constexpr int kMaxLevels = 9;
// Points a side of each tile where the map's Jacobian is taken, and (at least, at most) where the
// importance is read.
constexpr int kJacobianPoints = 3;
constexpr int kRegionPoints = 16, kMostRegionPoints = 64;
// The most a confirming encode moves a tile's footprints (octaves either way).
constexpr double kMostShift = 3.0;
[[noreturn]] void invalid(const std::string& what) { throw Error(ErrorCode::InvalidArgument, what); }

// The channels a display shows through its transfer curve: colour and grey, not alpha or data.
bool isColourChannel(const std::string& name) { return name == "R" || name == "G" || name == "B" || name == "Y"; }

// Singular values of a 2x2 matrix (largest first).
std::pair<double, double> singularValues(double a, double b, double c, double d) {
    const double s1 = a * a + b * b + c * c + d * d, det = std::abs(a * d - b * c);
    const double root = std::sqrt(std::max(0.0, s1 * s1 - 4 * det * det));
    return {std::sqrt(0.5 * (s1 + root)), std::sqrt(std::max(0.0, 0.5 * (s1 - root)))};
}

}  // namespace

FrameErrorModel::FrameErrorModel(const Image& source, int width, int height, const Image& importance, const FrameModelOptions& options)
    : FrameErrorModel(source, nullptr, width, height, importance, options) {}

FrameErrorModel::FrameErrorModel(const EightBitImage& source, int width, int height, const Image& importance,
                                 const FrameModelOptions& options)
    : FrameErrorModel(Image{source.width, source.height, source.channels, {}}, &source, width, height, importance, options) {}

// `codes`: the picture is those codes, `source` only their size and channels.
FrameErrorModel::FrameErrorModel(const Image& source, const EightBitImage* codes, int width, int height, const Image& importance,
                                 const FrameModelOptions& options)
    : m_options(options) {
    if (source.empty()) invalid("the frame-loss model needs the source picture");
    if (width < 1 || height < 1 || width > source.width || height > source.height)
        invalid("the frame-loss model: CoNUS size " + std::to_string(width) + "x" + std::to_string(height) +
                " is outside 1x1 .. the source's " + std::to_string(source.width) + "x" + std::to_string(source.height));
    const int sw = source.width, sh = source.height;
    m_source = codes ? nullptr : &source;
    if (codes && codes->codes.size() != std::size_t(source.width) * source.height * source.channels.size())
        invalid("the frame-loss model: the 8-bit picture's codes do not fill it");
    m_confirming = std::make_shared<Confirming>();
    m_sourceWidth = sw;
    m_sourceHeight = sh;
    m_conusWidth = width;
    m_conusHeight = height;
    m_floor = options.space == ErrorSpace::Display ? kDisplayFloor : kLinearFloor;
    m_frameFloor = options.space == ErrorSpace::Display ? kDisplayFrameFloor : kLinearFloor;
    m_tile = std::max(1, std::max(sw, sh) / kTilesPerSide);
    m_columns = (sw + m_tile - 1) / m_tile;
    m_rows = (sh + m_tile - 1) / m_tile;
    const std::size_t tiles = std::size_t(m_columns) * m_rows, channels = source.channels.size();
    m_pixels.assign(tiles, 0.0);
    for (int ty = 0; ty < m_rows; ++ty)
        for (int tx = 0; tx < m_columns; ++tx)
            m_pixels[std::size_t(ty) * m_columns + tx] =
                double(std::min(sw, (tx + 1) * m_tile) - tx * m_tile) * double(std::min(sh, (ty + 1) * m_tile) - ty * m_tile);

    // The pyramid: each level's 2x2 cells, their energy about their mean (the channels' mean) spread
    // over the tiles their source pixels cover, their mean the next level.
    m_levels = 0;
    for (int w = sw, h = sh; w >= 2 && h >= 2 && m_levels < kMaxLevels; w /= 2, h /= 2) ++m_levels;
    m_bands.assign(tiles * std::max(1, m_levels), 0.0);
    std::vector<bool> display(channels, false);
    if (options.space == ErrorSpace::Display)
        for (std::size_t c = 0; c < channels; ++c) display[c] = isColourChannel(source.channels[c]);
    const std::vector<float>& table = detail::displayTable();
    std::vector<float> level, next;
    int w = sw, h = sh;
    // 8-bit codes: each channel's shown() of each code's linear value (the same floats as the
    // linear picture's, so the same model).
    std::vector<std::array<float, 256>> codeShown(codes ? channels : 0);
    for (std::size_t c = 0; c < codeShown.size(); ++c)
        for (int v = 0; v < 256; ++v)
            codeShown[c][v] = detail::shown((isColourChannel(source.channels[c]) ? srgbCodeToLinear() : codeToUnit())[v], display[c], table);
    const auto at = [&](int j, int x, int y, std::size_t c) {
        const std::size_t i = (std::size_t(y) * sw + x) * channels + c;
        return j == 0 ? (codes ? codeShown[c][codes->codes[i]] : detail::shown(source.pixels[i], display[c], table))
                      : level[(std::size_t(y) * w + x) * channels + c];
    };
    for (int j = 0; j < m_levels; ++j) {
        const int nw = w / 2, nh = h / 2, cell = 1 << (j + 1);
        next.assign(std::size_t(nw) * nh * channels, 0.0f);
        // Each cell's energy and mean. The rows of tiles are spread over the threads: each walks
        // the rows of cells its tiles cover, in order, and adds each cell's energy to its own
        // tiles, so that every tile's sum is made in the same order whatever the thread count. A
        // row of cells across two threads' tiles is found by both; the one that holds its first
        // source row stores its means.
        parallelRows(
            m_rows, 0,
            [&](int t0, int t1) {
                const int first = t0 * m_tile / cell, last = std::min(nh - 1, (t1 * m_tile - 1) / cell);
                for (int y = first; y <= last; ++y) {
                    const int y0 = y * cell, y1 = std::min(sh, y0 + cell);
                    const int ty0 = std::max(t0, y0 / m_tile), ty1 = std::min(t1 - 1, (y1 - 1) / m_tile);
                    const bool store = y0 / m_tile >= t0;
                    for (int x = 0; x < nw; ++x) {
                        double energy = 0;
                        for (std::size_t c = 0; c < channels; ++c) {
                            const double v00 = at(j, 2 * x, 2 * y, c), v10 = at(j, 2 * x + 1, 2 * y, c);
                            const double v01 = at(j, 2 * x, 2 * y + 1, c), v11 = at(j, 2 * x + 1, 2 * y + 1, c);
                            const double mean = 0.25 * (v00 + v10 + v01 + v11);
                            energy += 0.25 * ((v00 - mean) * (v00 - mean) + (v10 - mean) * (v10 - mean) + (v01 - mean) * (v01 - mean) +
                                              (v11 - mean) * (v11 - mean));
                            if (store) next[(std::size_t(y) * nw + x) * channels + c] = static_cast<float>(mean);
                        }
                        energy /= double(channels);
                        const int x0 = x * cell, x1 = std::min(sw, x0 + cell);
                        for (int ty = ty0; ty <= ty1; ++ty) {
                            const int oy = std::min(y1, (ty + 1) * m_tile) - std::max(y0, ty * m_tile);
                            for (int tx = x0 / m_tile; tx <= (x1 - 1) / m_tile; ++tx) {
                                const int ox = std::min(x1, (tx + 1) * m_tile) - std::max(x0, tx * m_tile);
                                m_bands[(std::size_t(ty) * m_columns + tx) * m_levels + j] += energy * double(ox) * double(oy);
                            }
                        }
                    }
                }
            },
            1);
        level.swap(next);
        w = nw;
        h = nh;
    }
    for (std::size_t t = 0; t < tiles; ++t)
        for (int j = 0; j < m_levels; ++j) m_bands[t * m_levels + j] /= m_pixels[t];

    setRegion(importance);
    // The baseline: the uniform image of the same pixel count, every footprint the same.
    m_uniformError.resize(tiles);
    const double su = double(sw) / width, sv = double(sh) / height;
    for (std::size_t t = 0; t < tiles; ++t)
        m_uniformError[t] = tileError(t, std::max(su, sv), std::min(su, sv), kUniformFit);
    m_shift.assign(tiles, 0.0);
    m_residual.assign(tiles, 0.0);
}

void FrameErrorModel::setRegion(const Image& importance) {
    // The region: where the importance reaches half its peak (nowhere without one: R empty, the
    // whole frame's tiles counted), read at a grid of points of each tile.
    const std::size_t tiles = m_pixels.size();
    const int sw = m_sourceWidth, sh = m_sourceHeight;
    m_roi.assign(tiles, 0.0);
    m_touches.assign(tiles, 0);
    // Points a side: every source pixel of a tile up to kMostRegionPoints (a tile the region
    // touches by a pixel or two is one bench/quality.py leaves out of the tile loss).
    const int points = std::clamp(m_tile, kRegionPoints, kMostRegionPoints);
    if (!importance.empty()) {
        const std::size_t ic = importance.channels.size();
        const auto meanAt = [&](std::size_t i) {
            float v = 0;
            for (std::size_t c = 0; c < ic; ++c) v += importance.pixels[i * ic + c];
            return v / float(ic);
        };
        float peak = 0;
        for (std::size_t i = 0; i < std::size_t(importance.width) * importance.height; ++i) peak = std::max(peak, meanAt(i));
        if (peak > 0)
            for (int ty = 0; ty < m_rows; ++ty)
                for (int tx = 0; tx < m_columns; ++tx) {
                    const double x0 = tx * m_tile, y0 = ty * m_tile;
                    const double tw = std::min<double>(sw, x0 + m_tile) - x0, th = std::min<double>(sh, y0 + m_tile) - y0;
                    int in = 0;
                    for (int j = 0; j < points; ++j)
                        for (int i = 0; i < points; ++i) {
                            const double u = (x0 + (i + 0.5) / points * tw) / sw, v = (y0 + (j + 0.5) / points * th) / sh;
                            const int ix = std::min(importance.width - 1, static_cast<int>(u * importance.width));
                            const int iy = std::min(importance.height - 1, static_cast<int>(v * importance.height));
                            in += meanAt(std::size_t(iy) * importance.width + ix) >= 0.5f * peak ? 1 : 0;
                        }
                    const std::size_t t = std::size_t(ty) * m_columns + tx;
                    m_roi[t] = double(in) / (double(points) * points);
                    m_touches[t] = in > 0;
                }
    }
    if (importance.empty()) {  // R: the whole frame (every tile touches it)
        std::fill(m_roi.begin(), m_roi.end(), 1.0);
        std::fill(m_touches.begin(), m_touches.end(), 1);
    }
}

FrameErrorModel FrameErrorModel::withRegion(const Image& importance) const {
    FrameErrorModel out = *this;
    out.setRegion(importance);
    return out;
}

double FrameErrorModel::tileError(std::size_t tile, double sigma1, double sigma2, const BandFit& fit) const {
    const double* e = &m_bands[tile * m_levels];
    const double l = fit.stretch * std::log2(std::max(sigma1, 1e-6)) + (1 - fit.stretch) * std::log2(std::max(sigma2, 1e-6)) - fit.shift;
    const auto ramp = [](double t) {
        const double x = std::clamp((t + kHalfWidth) / (2 * kHalfWidth), 0.0, 1.0);
        return x * x * (3 - 2 * x);
    };
    double sum = 0;
    for (int j = 0; j < m_levels; ++j) sum += e[j] * ramp(l - j);
    return fit.scale * sum;
}

std::vector<std::pair<double, double>> FrameErrorModel::footprints(const SamplingMap& map) const {
    // J is d(CoNUS normalized)/d(source normalized); in pixels, CoNUS pixels per source pixel; its
    // inverse singular values are the footprint's axes in source pixels.
    std::vector<std::pair<double, double>> out;
    out.reserve(m_pixels.size() * kJacobianPoints * kJacobianPoints);
    const double W = m_conusWidth, H = m_conusHeight, sw = m_sourceWidth, sh = m_sourceHeight;
    for (int ty = 0; ty < m_rows; ++ty)
        for (int tx = 0; tx < m_columns; ++tx) {
            const double x0 = tx * m_tile, y0 = ty * m_tile;
            const double tw = std::min(sw, x0 + m_tile) - x0, th = std::min(sh, y0 + m_tile) - y0;
            for (int j = 0; j < kJacobianPoints; ++j)
                for (int i = 0; i < kJacobianPoints; ++i) {
                    const glm::dvec2 p((x0 + (i + 0.5) / kJacobianPoints * tw) / sw, (y0 + (j + 0.5) / kJacobianPoints * th) / sh);
                    const glm::dmat2 J = map.jacobian(p);
                    const auto [l1, l2] = singularValues(W * J[0][0] / sw, W * J[1][0] / sh, H * J[0][1] / sw, H * J[1][1] / sh);
                    out.emplace_back(1.0 / std::max(l2, 1e-9), 1.0 / std::max(l1, 1e-9));
                }
        }
    return out;
}

double FrameErrorModel::footprintError(std::size_t tile, const std::pair<double, double>* axes, double shift) const {
    const BandFit& fit = m_options.fitIterations > 0 ? kConusFitted : kConusFiltered;
    const double scale = std::exp2(shift);
    double sum = 0;
    for (int p = 0; p < kJacobianPoints * kJacobianPoints; ++p) sum += tileError(tile, axes[p].first * scale, axes[p].second * scale, fit);
    return sum / (kJacobianPoints * kJacobianPoints);
}

std::vector<double> FrameErrorModel::tileErrors(const SamplingMap& map) const {
    const std::vector<std::pair<double, double>> axes = footprints(map);
    std::vector<double> out(m_pixels.size());
    for (std::size_t t = 0; t < out.size(); ++t)
        out[t] = std::max(0.0, footprintError(t, &axes[t * kJacobianPoints * kJacobianPoints], m_shift[t]) + m_residual[t]);
    return out;
}

FramePrediction FrameErrorModel::predict(const SamplingMap& map) const { return measure(tileErrors(map)); }

FrameErrorModel FrameErrorModel::confirmed(const SamplingMap& map) const {
    if (!m_source) invalid("the frame-loss model of 8-bit codes cannot be confirmed: build it from the linear picture");
    const Image& source = *m_source;
    // The real encode (fitted as the encode will be) and decode at the source's size, and the
    // uniform image's, each tile's mean squared error on the values shown; the model then keeps
    // each tile's ratio of measured to predicted (e + f over e + f: a flat tile's tiny errors are
    // not magnified), so that it predicts what this map loses exactly and maps near it by the
    // model's differences.
    FrameErrorModel out = *this;
    // Progress: the encode to kEncodeShare, the fit to kFitShare, then the measure (about their
    // shares of the time at 16 MP with the default fit).
    constexpr double kEncodeShare = 0.3, kFitShare = 0.75;
    const ProgressFn& progress = m_options.confirmProgress;
    const auto part = [&](double from, double to) -> ProgressFn {
        if (!progress) return {};
        return [&progress, from, to](double f) { progress(from + (to - from) * f); };
    };
    if (progress) progress(0.0);
    EncodeOptions encode;
    encode.width = m_conusWidth;
    encode.height = m_conusHeight;
    encode.filter = m_options.filter;
    encode.progress = part(0.0, kEncodeShare);
    // The levels kept by an earlier confirmation; where another thread's confirmation of a copy
    // holds them, this one builds its own.
    std::unique_lock<std::mutex> levels(m_confirming->levelsInUse, std::try_to_lock);
    if (levels.owns_lock()) encode.keptLevels = &m_confirming->levels;
    auto kept = std::make_shared<ModelEncode>();
    std::vector<float> share;
    encode.lowPassShare = &share;
    kept->image = encodeImage(source, map, encode);
    encode.lowPassShare = nullptr;
    encode.progress = {};
    if (m_options.fitIterations > 0) {
        FitOptions fit;
        fit.progress = part(kEncodeShare, kFitShare);
        fit.lowPassShare = &share;
        fit.iterations = m_options.fitIterations;
        fit.holdLowPass = m_options.fitHold;
        fit.method = m_options.fitMethod;
        kept->fit = fitToDecoder(source, map, kept->image, fit);
    }
    // The decoded views are measured a row at a time as they are made, none kept (each would be
    // the source's size again); the uniform image's with the first confirmation's: the uniform
    // image as `conus uniform` makes it (the identity map through the same encoder), shown at the
    // source's size as the bench shows it (bilinear).
    std::vector<double> measured;
    std::call_once(m_confirming->once, [&] {
        const Image uniform = encodeImage(source, SamplingMap::identity(2, 2), encode);
        auto [conus, flat] = shownTileErrors(source, kept->image, map, &uniform, part(kFitShare, 1.0));
        measured = std::move(conus);
        m_confirming->errors = std::move(flat);
    });
    if (measured.empty()) measured = shownTileErrors(source, kept->image, map, nullptr, part(kFitShare, 1.0)).first;
    if (levels.owns_lock()) levels.unlock();
    if (progress) progress(1.0);
    out.m_uniformError = m_confirming->errors;
    // Each tile's footprints scaled by 2^shift so that the model gives what was measured: the
    // error grows with the footprint, so the shift is found by bisection (to 1e-4 octaves, within
    // +-kMostShift: a tile with no detail to lose keeps what it can).
    const std::vector<std::pair<double, double>> axes = footprints(map);
    for (std::size_t t = 0; t < measured.size(); ++t) {
        const std::pair<double, double>* a = &axes[t * kJacobianPoints * kJacobianPoints];
        double lo = -kMostShift, hi = kMostShift;
        while (hi - lo > 1e-4) {
            const double mid = 0.5 * (lo + hi);
            (footprintError(t, a, mid) < measured[t] ? lo : hi) = mid;
        }
        out.m_shift[t] = 0.5 * (lo + hi);
        // What no shift reaches (a tile that loses more than all its detail: the fit's ringing
        // beside an edge, on a flat ground; or less than the least the model gives) is kept as is.
        out.m_residual[t] = measured[t] - footprintError(t, a, out.m_shift[t]);
    }
    out.m_confirmed = true;
    out.m_encode = std::move(kept);
    return out;
}

std::pair<std::vector<double>, std::vector<double>> FrameErrorModel::shownTileErrors(const Image& source, const Image& conus,
                                                                                    const SamplingMap& map,
                                                                                    const Image* uniform,
                                                                                    const ProgressFn& progress) const {
    const std::size_t channels = source.channels.size();
    std::vector<char> display(channels, 0);
    if (m_options.space == ErrorSpace::Display)
        for (std::size_t c = 0; c < channels; ++c) display[c] = isColourChannel(source.channels[c]);
    // The colour channels are compared as the 8-bit codes shown, in integers (exact, and a row of
    // codes stays in the core's first cache); the others (alpha as stored, every channel of
    // ErrorSpace::Linear) as the values shown, in double, only where there are such channels.
    const bool others = std::any_of(display.begin(), display.end(), [](char d) { return !d; });
    const std::vector<float>& table = detail::displayTable();
    // The views at the source's size, never whole: the CoNUS image's decoded a row of tiles at a
    // time (the decoder's view of those rows), the uniform image's bilinear resize a row at a time.
    std::optional<detail::ResizedRows> uniformRows;
    if (uniform) uniformRows.emplace(*uniform, source.width, source.height);
    // Per tile, the sum of squared code differences and of the other channels' squared
    // differences. A row of tiles at a time, the rows of tiles spread over the threads (each
    // tile's sums are taken in the same order whatever the thread count).
    const std::size_t tiles = m_pixels.size();
    std::vector<std::int64_t> codeSum(tiles, 0), flatCodeSum(uniform ? tiles : 0, 0);
    std::vector<double> otherSum(others ? tiles : 0, 0.0), flatOtherSum(others && uniform ? tiles : 0, 0.0);
    std::atomic<int> rowsDone{0};
    parallelRows(
        m_rows, 0,
        [&](int r0, int r1) {
            const std::size_t values = std::size_t(source.width) * channels;
            std::vector<float> resized(uniform ? values : 0);
            // Each row as shown, one array a picture: the colour channels' codes (0 elsewhere), the
            // other channels' values (0 at the colour channels; only where there are others).
            struct Shown {
                std::vector<std::uint8_t> codes;
                std::vector<double> others;
            };
            const auto shownRow = [&](bool wanted) {
                return Shown{std::vector<std::uint8_t>(wanted ? values : 0), std::vector<double>(wanted && others ? values : 0)};
            };
            Shown from = shownRow(true), view = shownRow(true), flat = shownRow(uniform != nullptr);
            const auto onDisplay = [&](const float* in, Shown& out) {
                if (!others) return detail::displayCodes(in, out.codes.data(), values);
                for (std::size_t i = 0; i < values; i += channels)
                    for (std::size_t c = 0; c < channels; ++c) {
                        out.codes[i + c] = display[c] ? detail::displayCode(in[i + c]) : 0;
                        out.others[i + c] = display[c] ? 0.0 : double(detail::shown(in[i + c], false, table));
                    }
            };
            // Over values i0..i1 of a row: the squared code differences (at most 255^2 a value:
            // a tile's row is far from overflowing), and the other channels'.
            const auto codeSquares = [](const std::uint8_t* a, const std::uint8_t* b, std::size_t i0, std::size_t i1) {
                std::int64_t e = 0;
                for (std::size_t i = i0; i < i1; ++i) {
                    const int d = int(a[i]) - int(b[i]);
                    e += d * d;
                }
                return e;
            };
            const auto otherSquares = [](const std::vector<double>& a, const std::vector<double>& b, std::size_t i0, std::size_t i1) {
                double e = 0;
                for (std::size_t i = i0; i < i1; ++i) {
                    const double d = a[i] - b[i];
                    e += d * d;
                }
                return e;
            };
            Image decoded;
            for (int y = r0 * m_tile; y < std::min(source.height, r1 * m_tile); ++y) {
                if (y % m_tile == 0) {
                    DecodeOptions rows;
                    const int y1 = std::min(source.height, y + m_tile);
                    rows.view = {0.0, double(y) / source.height, 1.0, double(y1) / source.height};
                    rows.width = source.width;
                    rows.height = y1 - y;
                    rows.threads = 1;
                    decoded = decodeImage(conus, map, rows);
                }
                onDisplay(decoded.pixels.data() + std::size_t(y % m_tile) * values, view);
                onDisplay(source.pixels.data() + std::size_t(y) * values, from);
                if (uniform) {
                    uniformRows->row(y, resized.data());
                    onDisplay(resized.data(), flat);
                }
                const std::size_t first = std::size_t(y / m_tile) * m_columns;
                for (int tx = 0; tx < m_columns; ++tx) {
                    const std::size_t i0 = std::size_t(tx) * m_tile * channels;
                    const std::size_t i1 = std::min(values, i0 + std::size_t(m_tile) * channels);
                    codeSum[first + tx] += codeSquares(view.codes.data(), from.codes.data(), i0, i1);
                    if (others) otherSum[first + tx] += otherSquares(view.others, from.others, i0, i1);
                    if (uniform) {
                        flatCodeSum[first + tx] += codeSquares(flat.codes.data(), from.codes.data(), i0, i1);
                        if (others) flatOtherSum[first + tx] += otherSquares(flat.others, from.others, i0, i1);
                    }
                }
            }
            const int done = rowsDone.fetch_add(r1 - r0) + (r1 - r0);
            if (progress) progress(double(done) / m_rows);
        },
        1);
    // Each tile's mean over its values: codes as values code / 255.
    const auto means = [&](const std::vector<std::int64_t>& code, const std::vector<double>& other) {
        std::vector<double> out(code.size());
        for (std::size_t t = 0; t < out.size(); ++t)
            out[t] = (double(code[t]) / (255.0 * 255.0) + (others ? other[t] : 0.0)) / (m_pixels[t] * double(channels));
        return out;
    };
    return {means(codeSum, otherSum), uniform ? means(flatCodeSum, flatOtherSum) : std::vector<double>{}};
}

FramePrediction FrameErrorModel::measure(const std::vector<double>& mapped) const {
    const auto db = [](double a, double b) { return 10.0 * std::log10(std::max(a, 1e-30) / std::max(b, 1e-30)); };
    double frameUniform = 0, frameMapped = 0, roiUniform = 0, roiMapped = 0, roiCount = 0, n = 0;
    std::vector<double> losses;
    for (std::size_t t = 0; t < mapped.size(); ++t) {
        const double p = m_pixels[t], r = p * m_roi[t];
        frameUniform += p * m_uniformError[t];
        frameMapped += p * mapped[t];
        roiUniform += r * m_uniformError[t];
        roiMapped += r * mapped[t];
        roiCount += r;
        n += p;
        if (!m_touches[t]) losses.push_back(db(mapped[t] + m_floor, m_uniformError[t] + m_floor));
    }
    const double rest = std::max(1.0, n - roiCount);
    FramePrediction out{db(frameMapped / n + m_frameFloor, frameUniform / n + m_frameFloor), db(roiUniform, roiMapped), 0.0,
                        db((frameMapped - roiMapped) / rest + m_frameFloor, (frameUniform - roiUniform) / rest + m_frameFloor)};
    if (!losses.empty()) {
        const std::size_t at = std::min(losses.size() - 1, static_cast<std::size_t>(kTilePercentile * double(losses.size())));
        std::nth_element(losses.begin(), losses.begin() + static_cast<std::ptrdiff_t>(at), losses.end());
        out.tileLoss = losses[at];
        const std::size_t at99 = std::min(losses.size() - 1, static_cast<std::size_t>(kWorstTilesPercentile * double(losses.size())));
        std::nth_element(losses.begin(), losses.begin() + static_cast<std::ptrdiff_t>(at99), losses.end());
        out.tileLoss99 = losses[at99];
    }
    return out;
}

}  // namespace conus::codec
