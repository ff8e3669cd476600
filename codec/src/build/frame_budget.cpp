// Predicted whole-frame loss and ROI gain of a density, and the context floor a loss budget allows.
#include "conus/codec/build/frame_budget.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "conus/codec/image/decode.h"
#include "conus/codec/image/encode.h"
#include "conus/core/error.h"

namespace conus::codec {
namespace {

// The model's grid: detail finer than this is not held (the error of the finest rates is
// under-predicted on larger pictures), and every prediction visits each of its pixels.
constexpr int kModelSide = 1024;
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
    const double shrink = std::min(1.0, double(kModelSide) / std::max(source.width, source.height));
    m_width = std::max(1, static_cast<int>(std::lround(source.width * shrink)));
    m_height = std::max(1, static_cast<int>(std::lround(source.height * shrink)));
    const Image grid = shrink < 1 ? areaDownsample(source, m_width, m_height) : source;
    const std::size_t pixels = std::size_t(m_width) * m_height, channels = grid.channels.size();
    // Rates in samples per model pixel: the uniform CoNUS image's, down to the lowest density's.
    m_baseRate = std::sqrt(double(width) * height / (double(source.width) * source.height)) / shrink;
    const double lowest = m_baseRate * std::sqrt(kLowestDensity);
    std::vector<double> rates;
    for (double s = std::min(lowest, 1.0); s < 1.0; s *= std::sqrt(2.0)) rates.push_back(s);
    for (double s : rates) {
        const int w = std::max(1, static_cast<int>(std::lround(m_width * s))), h = std::max(1, static_cast<int>(std::lround(m_height * s)));
        const Image back = resizeBilinear(areaDownsample(grid, w, h), {}, m_width, m_height);
        std::vector<float> error(pixels);
        for (std::size_t p = 0; p < pixels; ++p) {
            double sum = 0;
            for (std::size_t c = 0; c < channels; ++c) {
                const double d = double(back.pixels[p * channels + c]) - grid.pixels[p * channels + c];
                sum += d * d;
            }
            error[p] = static_cast<float>(sum / double(channels));
        }
        m_logRates.push_back(std::log(std::sqrt(double(w) * h / pixels)));
        m_error.push_back(std::move(error));
    }
    m_logRates.push_back(0.0);
    m_error.emplace_back(pixels, 0.0f);

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
            for (int y = 0; y < m_height; ++y)
                for (int x = 0; x < m_width; ++x) {
                    const int ix = std::min(importance.width - 1, static_cast<int>((x + 0.5) / m_width * importance.width));
                    const int iy = std::min(importance.height - 1, static_cast<int>((y + 0.5) / m_height * importance.height));
                    m_roi[std::size_t(y) * m_width + x] = meanAt(std::size_t(iy) * importance.width + ix) >= 0.5f * peak ? 1 : 0;
                }
        }
    }
}

FramePrediction FrameErrorModel::predictAxes(const std::function<glm::dvec2(double u, double v)>& scales) const {
    const double logBase = std::log(m_baseRate);
    double frameUniform = 0, frameMapped = 0, roiUniform = 0, roiMapped = 0;
    const auto errorAt = [&](std::size_t p, double logRate) {
        if (logRate >= 0.0) return 0.0;
        if (logRate <= m_logRates.front()) return double(m_error.front()[p]);
        const std::size_t i = std::upper_bound(m_logRates.begin(), m_logRates.end(), logRate) - m_logRates.begin();
        const double t = (logRate - m_logRates[i - 1]) / (m_logRates[i] - m_logRates[i - 1]);
        return (1 - t) * m_error[i - 1][p] + t * m_error[i][p];
    };
    for (int y = 0; y < m_height; ++y)
        for (int x = 0; x < m_width; ++x) {
            const std::size_t p = std::size_t(y) * m_width + x;
            const glm::dvec2 k = glm::max(scales((x + 0.5) / m_width, (y + 0.5) / m_height), glm::dvec2(1e-6));
            // Sampled at different rates along two axes: about the mean of the errors of the two
            // isotropic rates (exact for a separable spectrum whose two halves lose alike).
            const double uniform = errorAt(p, logBase);
            const double mapped = 0.5 * (errorAt(p, logBase + std::log(k.x)) + errorAt(p, logBase + std::log(k.y)));
            frameUniform += uniform;
            frameMapped += mapped;
            if (m_roi[p]) {
                roiUniform += uniform;
                roiMapped += mapped;
            }
        }
    const auto db = [](double a, double b) { return 10.0 * std::log10(std::max(a, 1e-30) / std::max(b, 1e-30)); };
    return {db(frameMapped, frameUniform), db(roiUniform, roiMapped)};
}

FramePrediction FrameErrorModel::predict(const std::function<double(double, double)>& density) const {
    return predictAxes([&](double u, double v) { return glm::dvec2(std::sqrt(std::max(density(u, v), 1e-12))); });
}

FramePrediction FrameErrorModel::predict(const SamplingMap& map) const {
    const double aspect = double(m_width) / m_height;
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
                                      AutoMapOptions options) {
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
    BudgetResult low = build(kLowestFloor);
    if (low.predicted.frameLoss <= frameLossDb) {
        low.budgetBinds = false;
        return low;
    }
    BudgetResult high = build(kHighestFloor);
    if (high.predicted.frameLoss > frameLossDb) return high;  // the closest to the budget there is
    for (int i = 0; i < kBisectionSteps; ++i) {
        BudgetResult mid = build(std::sqrt(low.minDensity * high.minDensity));
        (mid.predicted.frameLoss <= frameLossDb ? high : low) = std::move(mid);
    }
    return high;
}

}  // namespace conus::codec
