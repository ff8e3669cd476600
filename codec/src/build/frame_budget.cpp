// The whole-frame loss, tile loss and ROI gain of a map, measured on a trial encode, and the context floor a loss budget allows.
#include "conus/codec/build/frame_budget.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "conus/codec/image/decode.h"
#include "conus/codec/image/encode.h"
#include "conus/codec/image/fit.h"
#include "conus/core/display.h"
#include "conus/core/error.h"

namespace conus::codec {
namespace {

// The picture trial encodes run on: the source, reduced to at most this many pixels a side (the
// CoNUS size with it, so that the rates relative to the picture are the encode's). 1024: the
// pictures people compare by eye are about that size, and a trial there costs about 60 ms.
constexpr int kTrialSide = 1024;
// Tiles of the tile loss: max(W, H) / kTilesPerSide of the frame a side (bench/quality.py's tiles),
// and the floor added to both errors of a tile and of the frame: on a flat picture a tiny error
// twice as large is no loss. Displayed: bench/quality.py's (2/255)^2 of 8-bit sRGB; linear: about
// that near mid-grey.
constexpr int kTilesPerSide = 32;
constexpr double kDisplayFloor = (2.0 / 255.0) * (2.0 / 255.0);
constexpr double kLinearFloor = (1.5 / 255.0) * (1.5 / 255.0);
constexpr double kTilePercentile = 0.95;
constexpr double kWorstTilesPercentile = 0.99;
constexpr double kLowestFloor = 0.02, kHighestFloor = 0.99;
// Halvings of log floor: the floor to within a factor of (0.99 / 0.02)^(1/256), 1.5%.
constexpr int kBisectionSteps = 8;

[[noreturn]] void invalid(const std::string& what) { throw Error(ErrorCode::InvalidArgument, what); }

// The channels a display shows through its transfer curve: colour and grey, not alpha or data.
bool isColourChannel(const std::string& name) { return name == "R" || name == "G" || name == "B" || name == "Y"; }

}  // namespace

FrameErrorModel::FrameErrorModel(const Image& source, int width, int height, const Image& importance, const FrameModelOptions& options)
    : m_options(options) {
    if (source.empty()) invalid("the frame-loss model needs the source picture");
    if (width < 1 || height < 1 || width > source.width || height > source.height)
        invalid("the frame-loss model: CoNUS size " + std::to_string(width) + "x" + std::to_string(height) +
                " is outside 1x1 .. the source's " + std::to_string(source.width) + "x" + std::to_string(source.height));
    const double shrink = std::min(1.0, double(kTrialSide) / std::max(source.width, source.height));
    const int gw = std::max(1, static_cast<int>(std::lround(source.width * shrink)));
    const int gh = std::max(1, static_cast<int>(std::lround(source.height * shrink)));
    m_picture = shrink < 1 ? areaDownsample(source, gw, gh) : source;
    m_conusWidth = std::clamp(static_cast<int>(std::lround(width * shrink)), 1, gw);
    m_conusHeight = std::clamp(static_cast<int>(std::lround(height * shrink)), 1, gh);
    m_floor = options.space == ErrorSpace::Display ? kDisplayFloor : kLinearFloor;
    const std::size_t pixels = std::size_t(gw) * gh, channels = m_picture.channels.size();
    m_shown.assign(channels, false);
    if (options.space == ErrorSpace::Display)
        for (std::size_t c = 0; c < channels; ++c) m_shown[c] = isColourChannel(m_picture.channels[c]);
    m_reference = shownValues(m_picture);

    // The region: the picture's pixels where the importance reaches half its peak (all of them without one).
    m_roi.assign(pixels, 1);
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
                    m_roi[std::size_t(y) * gw + x] = meanAt(std::size_t(iy) * importance.width + ix) >= 0.5f * peak ? 1 : 0;
                }
        }
    }
    // The baseline: the uniform image of the same pixel count, shown by a bilinear resize.
    m_uniformError = errors(resizeBilinear(areaDownsample(m_picture, m_conusWidth, m_conusHeight), {}, gw, gh));
}

std::vector<float> FrameErrorModel::shownValues(const Image& image) const {
    const std::size_t channels = m_shown.size();
    std::vector<float> out(image.pixels.size());
    for (std::size_t i = 0; i < out.size(); ++i) {
        const float v = image.pixels[i];
        out[i] = m_shown[i % channels] ? linearToSrgbDisplay(v) : v;
    }
    return out;
}

std::vector<float> FrameErrorModel::errors(const Image& view) const {
    const std::vector<float> shown = shownValues(view);
    const std::size_t channels = m_shown.size(), pixels = shown.size() / channels;
    std::vector<float> out(pixels);
    for (std::size_t p = 0; p < pixels; ++p) {
        double sum = 0;
        for (std::size_t c = 0; c < channels; ++c) {
            const double d = double(shown[p * channels + c]) - m_reference[p * channels + c];
            sum += d * d;
        }
        out[p] = static_cast<float>(sum / double(channels));
    }
    return out;
}

FramePrediction FrameErrorModel::predict(const SamplingMap& map) const {
    EncodeOptions encode;
    encode.width = m_conusWidth;
    encode.height = m_conusHeight;
    Image conus = encodeImage(m_picture, map, encode);
    if (m_options.fitIterations > 0) {
        FitOptions fit;
        fit.iterations = m_options.fitIterations;
        fit.holdLowPass = m_options.fitHold;
        fitToDecoder(m_picture, map, conus, fit);
    }
    DecodeOptions decode;
    decode.width = m_picture.width;
    decode.height = m_picture.height;
    return measure(errors(decodeImage(conus, map, decode)));
}

FramePrediction FrameErrorModel::measure(const std::vector<float>& mapped) const {
    const int w = m_picture.width, h = m_picture.height;
    const auto db = [](double a, double b) { return 10.0 * std::log10(std::max(a, 1e-30) / std::max(b, 1e-30)); };
    double frameUniform = 0, frameMapped = 0, roiUniform = 0, roiMapped = 0, roiCount = 0;
    for (std::size_t p = 0; p < mapped.size(); ++p) {
        frameUniform += m_uniformError[p];
        frameMapped += mapped[p];
        if (m_roi[p]) {
            roiUniform += m_uniformError[p];
            roiMapped += mapped[p];
            roiCount += 1;
        }
    }
    const double n = double(mapped.size()), rest = std::max(1.0, n - roiCount);
    FramePrediction out{db(frameMapped / n + m_floor, frameUniform / n + m_floor), db(roiUniform, roiMapped), 0.0,
                        db((frameMapped - roiMapped) / rest + m_floor, (frameUniform - roiUniform) / rest + m_floor)};
    // Tiles of max(W, H) / 32 touching no region: the loss at the 95th percentile.
    const int tile = std::max(1, std::max(w, h) / kTilesPerSide);
    std::vector<double> losses;
    for (int ty = 0; ty < h; ty += tile)
        for (int tx = 0; tx < w; tx += tile) {
            double u = 0, m = 0, count = 0;
            bool touches = false;
            for (int y = ty; y < std::min(h, ty + tile); ++y)
                for (int x = tx; x < std::min(w, tx + tile); ++x) {
                    const std::size_t p = std::size_t(y) * w + x;
                    touches |= m_roi[p] != 0;
                    u += m_uniformError[p];
                    m += mapped[p];
                    count += 1;
                }
            if (!touches) losses.push_back(db(m / count + m_floor, u / count + m_floor));
        }
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
    const auto search = [&]() {
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
    };
    BudgetResult chosen = search();
    if (options.context) {
        // As for foci (foci_budget.cpp): where the context that follows the picture gives the region
        // less (a region softer than the rest, whose factor the max density caps; a context that
        // alone loses the budget) or crowds a few tiles (keepsContext), the uniform context's map is kept.
        options.context = nullptr;
        BudgetResult plain = search();
        if ((within(plain) && !within(chosen)) || (within(plain) == within(chosen) && !keepsContext(chosen.predicted, plain.predicted)))
            return plain;
    }
    return chosen;
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

BudgetResult buildOwnDetailMap(const Image& source, const Image& detail, int width, int height, const AutoMapOptions& options,
                               const FrameModelOptions& model) {
    const FrameErrorModel trials(source, width, height, detail, model);
    return buildAutoMapForBestFrame(detail, trials, kOwnDetailTileLoss, options);
}

DensityField ownDetailContext(const Image& source, const Image& detail, int width, int height, const AutoMapOptions& options,
                              const FrameModelOptions& model) {
    AutoMapOptions at = options;
    at.minDensity = buildOwnDetailMap(source, detail, width, height, options, model).minDensity;
    return importanceToDensity(detail, at);
}

}  // namespace conus::codec
