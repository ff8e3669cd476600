// Predicted whole-frame loss and ROI gain of a density, and the context floor a loss budget allows.
#include "conus/codec/build/frame_budget.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "conus/codec/image/decode.h"
#include "conus/codec/image/encode.h"
#include "conus/core/error.h"

namespace conus::codec {
namespace {

// The grid the errors are measured on: the source, reduced to at most this many pixels a side, or
// to twice the CoNUS image's side where that is larger (so that a CoNUS pixel spans at least two
// of its pixels: finer detail than it holds is under-predicted).
constexpr int kModelSide = 1024;
constexpr int kModelSideOverConus = 2;
// The blocks a prediction visits: the grid's errors pooled to at most this many a side. The loss
// of a block at a rate is the mean of its pixels' (e is linear in them at each rate), so only the
// rate's variation within a block is lost: a focus's transition spans several blocks.
constexpr int kPoolSide = 256;
// Tiles of the tile loss: max(W, H) / kTilesPerSide of the frame a side (bench/quality.py's tiles),
// and the floor added to both errors of a tile and of the frame (about (2/255)^2 of 8-bit sRGB near
// mid-grey, in linear light): on a flat picture a tiny error twice as large is no loss.
constexpr int kTilesPerSide = 32;
constexpr double kTileFloor = (1.5 / 255.0) * (1.5 / 255.0);
constexpr double kTilePercentile = 0.95;
// The lowest density the model covers (a floor below it costs the rate of this one).
constexpr double kLowestDensity = 0.01;
constexpr double kLowestFloor = 0.02, kHighestFloor = 0.99;
// Halvings of log floor: the floor to within a factor of (0.99 / 0.02)^(1/256), 1.5%.
constexpr int kBisectionSteps = 8;

[[noreturn]] void invalid(const std::string& what) { throw Error(ErrorCode::InvalidArgument, what); }

// Nearest sample of a cell-centred field of w x h at p in [0,1]^2.
template <class Field>
auto nearest(const Field& field, int w, int h, double u, double v) {
    const int x = std::clamp(static_cast<int>(u * w), 0, w - 1), y = std::clamp(static_cast<int>(v * h), 0, h - 1);
    return field[std::size_t(y) * w + x];
}

}  // namespace

FrameErrorModel::FrameErrorModel(const Image& source, int width, int height, const Image& importance) {
    if (source.empty()) invalid("the frame-loss model needs the source picture");
    if (width < 1 || height < 1 || width > source.width || height > source.height)
        invalid("the frame-loss model: CoNUS size " + std::to_string(width) + "x" + std::to_string(height) +
                " is outside 1x1 .. the source's " + std::to_string(source.width) + "x" + std::to_string(source.height));
    const int side = std::max(kModelSide, kModelSideOverConus * std::max(width, height));
    const double shrink = std::min(1.0, double(side) / std::max(source.width, source.height));
    const int gw = std::max(1, static_cast<int>(std::lround(source.width * shrink)));
    const int gh = std::max(1, static_cast<int>(std::lround(source.height * shrink)));
    const Image grid = shrink < 1 ? areaDownsample(source, gw, gh) : source;
    m_aspect = double(source.width) / source.height;
    const std::size_t pixels = std::size_t(gw) * gh, channels = grid.channels.size();
    const double pool = std::min(1.0, double(kPoolSide) / std::max(gw, gh));
    m_width = std::max(1, static_cast<int>(std::lround(gw * pool)));
    m_height = std::max(1, static_cast<int>(std::lround(gh * pool)));
    const std::size_t blocks = std::size_t(m_width) * m_height;
    std::vector<std::size_t> blockOf(pixels);
    m_count.assign(blocks, 0.0f);
    for (int y = 0; y < gh; ++y)
        for (int x = 0; x < gw; ++x) {
            const std::size_t b = std::size_t(std::min(m_height - 1, y * m_height / gh)) * m_width + std::min(m_width - 1, x * m_width / gw);
            blockOf[std::size_t(y) * gw + x] = b;
            m_count[b] += 1.0f;
        }

    // The region: the grid's pixels where the importance reaches half its peak (all of them without one).
    std::vector<unsigned char> roi(pixels, 1);
    if (!importance.empty()) {
        const std::size_t ic = importance.channels.size();
        const auto meanAt = [&](std::size_t i) {
            float v = 0;
            for (std::size_t c = 0; c < ic; ++c) v += importance.pixels[i * ic + c];
            return v / float(ic);
        };
        float peak = 0;
        for (std::size_t i = 0; i < std::size_t(importance.width) * importance.height; ++i) peak = std::max(peak, meanAt(i));
        if (peak > 0) {
            for (int y = 0; y < gh; ++y)
                for (int x = 0; x < gw; ++x) {
                    const int ix = std::min(importance.width - 1, static_cast<int>((x + 0.5) / gw * importance.width));
                    const int iy = std::min(importance.height - 1, static_cast<int>((y + 0.5) / gh * importance.height));
                    roi[std::size_t(y) * gw + x] = meanAt(std::size_t(iy) * importance.width + ix) >= 0.5f * peak ? 1 : 0;
                }
        }
    }
    m_roiAny.assign(blocks, 0);
    for (std::size_t p = 0; p < pixels; ++p) m_roiAny[blockOf[p]] |= roi[p];

    // Rates in samples per grid pixel: the uniform CoNUS image's, down to the lowest density's.
    m_baseRate = std::sqrt(double(width) * height / (double(source.width) * source.height)) / shrink;
    const double lowest = m_baseRate * std::sqrt(kLowestDensity);
    std::vector<double> rates;
    for (double s = std::min(lowest, 1.0); s < 1.0; s *= std::sqrt(2.0)) rates.push_back(s);
    for (double s : rates) {
        const int w = std::max(1, static_cast<int>(std::lround(gw * s))), h = std::max(1, static_cast<int>(std::lround(gh * s)));
        const Image back = resizeBilinear(areaDownsample(grid, w, h), {}, gw, gh);
        std::vector<float> all(blocks, 0.0f), inRoi(blocks, 0.0f);
        for (std::size_t p = 0; p < pixels; ++p) {
            double sum = 0;
            for (std::size_t c = 0; c < channels; ++c) {
                const double d = double(back.pixels[p * channels + c]) - grid.pixels[p * channels + c];
                sum += d * d;
            }
            const float e = static_cast<float>(sum / double(channels));
            all[blockOf[p]] += e;
            if (roi[p]) inRoi[blockOf[p]] += e;
        }
        m_logRates.push_back(std::log(std::sqrt(double(w) * h / pixels)));
        m_error.push_back(std::move(all));
        m_roiError.push_back(std::move(inRoi));
    }
    m_logRates.push_back(0.0);
    m_error.emplace_back(blocks, 0.0f);
    m_roiError.emplace_back(blocks, 0.0f);
}

FramePrediction FrameErrorModel::predictAxes(const std::function<glm::dvec2(double u, double v)>& scales) const {
    const double logBase = std::log(m_baseRate);
    const std::size_t blocks = std::size_t(m_width) * m_height;
    // Error sums of a block at a log rate, interpolated between the rates held.
    const auto errorAt = [&](const std::vector<std::vector<float>>& table, std::size_t b, double logRate) {
        if (logRate >= 0.0) return 0.0;
        if (logRate <= m_logRates.front()) return double(table.front()[b]);
        const std::size_t i = std::upper_bound(m_logRates.begin(), m_logRates.end(), logRate) - m_logRates.begin();
        const double t = (logRate - m_logRates[i - 1]) / (m_logRates[i] - m_logRates[i - 1]);
        return (1 - t) * table[i - 1][b] + t * table[i][b];
    };
    std::vector<double> uniform(blocks), mapped(blocks);
    double frameUniform = 0, frameMapped = 0, roiUniform = 0, roiMapped = 0;
    for (int y = 0; y < m_height; ++y)
        for (int x = 0; x < m_width; ++x) {
            const std::size_t b = std::size_t(y) * m_width + x;
            const glm::dvec2 k = glm::max(scales((x + 0.5) / m_width, (y + 0.5) / m_height), glm::dvec2(1e-6));
            // Sampled at different rates along two axes: about the mean of the errors of the two
            // isotropic rates (exact for a separable spectrum whose two halves lose alike).
            uniform[b] = errorAt(m_error, b, logBase);
            mapped[b] = 0.5 * (errorAt(m_error, b, logBase + std::log(k.x)) + errorAt(m_error, b, logBase + std::log(k.y)));
            frameUniform += uniform[b];
            frameMapped += mapped[b];
            roiUniform += errorAt(m_roiError, b, logBase);
            roiMapped += 0.5 * (errorAt(m_roiError, b, logBase + std::log(k.x)) + errorAt(m_roiError, b, logBase + std::log(k.y)));
        }
    const auto db = [](double a, double b) { return 10.0 * std::log10(std::max(a, 1e-30) / std::max(b, 1e-30)); };
    // The frame's loss with the tiles' floor: a difference under what 8 bits show is no loss.
    double total = 0;
    for (float n : m_count) total += n;
    FramePrediction out{db(frameMapped / total + kTileFloor, frameUniform / total + kTileFloor), db(roiUniform, roiMapped), 0.0};
    // Tiles of max(W, H) / 32 touching no region: the loss at the 95th percentile.
    const int tile = std::max(1, std::max(m_width, m_height) / kTilesPerSide);
    std::vector<double> losses;
    for (int ty = 0; ty < m_height; ty += tile)
        for (int tx = 0; tx < m_width; tx += tile) {
            double u = 0, m = 0, n = 0;
            bool touches = false;
            for (int y = ty; y < std::min(m_height, ty + tile); ++y)
                for (int x = tx; x < std::min(m_width, tx + tile); ++x) {
                    const std::size_t b = std::size_t(y) * m_width + x;
                    touches |= m_roiAny[b] != 0;
                    u += uniform[b];
                    m += mapped[b];
                    n += m_count[b];
                }
            if (!touches && n > 0) losses.push_back(db(m / n + kTileFloor, u / n + kTileFloor));
        }
    if (!losses.empty()) {
        const std::size_t at = std::min(losses.size() - 1, static_cast<std::size_t>(kTilePercentile * double(losses.size())));
        std::nth_element(losses.begin(), losses.begin() + static_cast<std::ptrdiff_t>(at), losses.end());
        out.tileLoss = losses[at];
    }
    return out;
}

FramePrediction FrameErrorModel::predict(const std::function<double(double, double)>& density) const {
    return predictAxes([&](double u, double v) { return glm::dvec2(std::sqrt(std::max(density(u, v), 1e-12))); });
}

FramePrediction FrameErrorModel::predict(const SamplingMap& map) const {
    const double aspect = m_aspect;
    return predictAxes([&](double u, double v) {
        // The singular values of the Jacobian in pixel units (map_measures.h's anisotropy): the
        // linear rate along the footprint's two axes, relative to the uniform image's.
        const glm::dmat2 j = map.jacobian({u, v});
        const double a = j[0][0], b = j[1][0] * aspect, c = j[0][1] / aspect, d = j[1][1];
        const double sumSquares = a * a + b * b + c * c + d * d, det = std::abs(a * d - b * c);
        const double large = std::sqrt(0.5 * (sumSquares + std::sqrt(std::max(0.0, sumSquares * sumSquares - 4.0 * det * det))));
        const double small = det / std::max(large, 1e-300);
        // The encoder's Gaussian along the footprint's long axis (encode.h), where the rate is the
        // small one: a box of one CoNUS pixel (variance 1/12) widened by it samples as a box that
        // much wider would, at that much lower a rate.
        const double sigma = kEncodeAnisotropicSigma * (1.0 - kEncodeBoxAnisotropy * small / std::max(large, 1e-300));
        const double widen = sigma > 0.0 ? std::sqrt(1.0 + 12.0 * sigma * sigma) : 1.0;
        return glm::dvec2(large, small / widen);
    });
}

FramePrediction FrameErrorModel::predict(const DensityField& field) const {
    return predict([&](double u, double v) { return double(nearest(field.values, field.width, field.height, u, v)); });
}

BudgetResult buildAutoMapForFrameLoss(const Image& importance, const FrameErrorModel& model, double frameLossDb,
                                      AutoMapOptions options, double tileLossDb) {
    if (!(frameLossDb >= 0) || !std::isfinite(frameLossDb))
        invalid("the frame-loss budget " + std::to_string(frameLossDb) + " dB must be finite and >= 0");
    // A higher floor leaves the context more samples: the loss falls as the floor rises. Bisect in
    // log floor, on what each built map is predicted to lose (its target alone predicts too little:
    // the grid cannot follow a steep rise, and stretched footprints lose along their long axis),
    // for the lowest floor within the budget.
    options.refuseBounds = false;
    const auto build = [&](double floor) {
        options.minDensity = floor;
        BudgetResult r{buildAutoMap(importance, options), floor, {}, true};
        r.predicted = model.predict(r.map);
        return r;
    };
    const auto within = [&](const BudgetResult& r) { return r.predicted.frameLoss <= frameLossDb && r.predicted.tileLoss <= tileLossDb; };
    BudgetResult low = build(kLowestFloor);
    if (within(low)) {
        low.budgetBinds = false;
        return low;
    }
    BudgetResult high = build(kHighestFloor);
    if (!within(high)) return high;  // the closest to the budget there is
    for (int i = 0; i < kBisectionSteps; ++i) {
        BudgetResult mid = build(std::sqrt(low.minDensity * high.minDensity));
        (within(mid) ? high : low) = std::move(mid);
    }
    return high;
}

BudgetResult buildAutoMapForBestFrame(const Image& importance, const FrameErrorModel& model, double tileLossDb,
                                      AutoMapOptions options) {
    // Floors a quarter octave of density apart, from half the uniform rate to nearly uniform: the
    // whole-frame loss is not monotone in the floor (too low starves the flat parts, too high leaves
    // the detail nothing), so each is built and predicted.
    constexpr double kFloors[] = {0.25, 0.35, 0.5, 0.6, 0.7, 0.85};
    options.refuseBounds = false;
    std::optional<BudgetResult> best;
    for (double floor : kFloors) {
        options.minDensity = floor;
        BudgetResult r{buildAutoMap(importance, options), floor, {}, true};
        r.predicted = model.predict(r.map);
        const bool fits = r.predicted.tileLoss <= tileLossDb, bestFits = best && best->predicted.tileLoss <= tileLossDb;
        if (!best || (fits && !bestFits) || (fits == bestFits && (fits ? r.predicted.frameLoss < best->predicted.frameLoss
                                                                        : r.predicted.tileLoss < best->predicted.tileLoss)))
            best = std::move(r);
    }
    best->budgetBinds = best->predicted.tileLoss <= tileLossDb;
    return std::move(*best);
}

BudgetResult buildOwnDetailMap(const Image& source, const Image& detail, int width, int height, const AutoMapOptions& options) {
    const FrameErrorModel model(source, width, height, detail);
    return buildAutoMapForBestFrame(detail, model, kOwnDetailTileLoss, options);
}

}  // namespace conus::codec
