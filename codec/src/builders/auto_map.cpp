#include "conus/codec/builders/auto_map.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <string>

#include "conus/codec/builders/map_measures.h"
#include "conus/codec/image/decode.h"
#include "conus/codec/image/encode.h"
#include "conus/core/error.h"
#include "../image/area_downsample_pvt.h"
#include "density_cells_pvt.h"

namespace conus::codec {
namespace {

constexpr int kMaxGrid = 256;

[[noreturn]] void invalid(const std::string& what) { throw Error(ErrorCode::InvalidArgument, what); }

// One channel: "Y" or the first channel, or the mean of R, G, B when present.
std::vector<float> luminance(const Image& image) {
    const int r = image.channelIndex("R"), g = image.channelIndex("G"), b = image.channelIndex("B");
    int single = image.channelIndex("Y");
    if (single < 0) single = 0;
    std::vector<float> out(static_cast<std::size_t>(image.width) * image.height);
    for (std::size_t p = 0; p < out.size(); ++p) {
        const float* px = &image.pixels[p * image.channels.size()];
        out[p] = (r >= 0 && g >= 0 && b >= 0) ? (px[r] + px[g] + px[b]) / 3.0f : px[single];
    }
    return out;
}

// Box blur of radius `radius` cells along both axes, edges clamped; applied twice it approximates a
// Gaussian and keeps the field smooth enough for a smooth map.
void blur(std::vector<double>& field, int width, int height, int radius) {
    if (radius <= 0) return;
    std::vector<double> tmp(field.size());
    for (int pass = 0; pass < 2; ++pass) {
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) {
                double sum = 0;
                for (int d = -radius; d <= radius; ++d) sum += field[y * width + std::clamp(x + d, 0, width - 1)];
                tmp[y * width + x] = sum / (2 * radius + 1);
            }
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) {
                double sum = 0;
                for (int d = -radius; d <= radius; ++d) sum += tmp[std::clamp(y + d, 0, height - 1) * width + x];
                field[y * width + x] = sum / (2 * radius + 1);
            }
    }
}

constexpr int kBoundRounds = 4;

[[noreturn]] void refuseBounds(const MapMeasures& m, const AutoMapOptions& options) {
    const auto round3 = [](double v) { return numberText(v, 3); };
    invalid("density bounds " + round3(options.minDensity) + " .. " + round3(options.maxDensity) + " cannot be held on a " +
            std::to_string(options.columns) + "x" + std::to_string(options.rows) + " grid with this importance: the map reaches " +
            round3(m.minCellDensity) + " .. " + round3(m.maxCellDensity) + " per cell (" +
            numberText(100 * kDensityBoundTolerance, 2) + "% outside is allowed); lower --min-density towards " +
            round3(m.minCellDensity) + " or raise --max-density towards " + round3(m.maxCellDensity) +
            ", or use a finer --grid");
}

}  // namespace

double leastScaleForMeanOne(const std::vector<double>& field, const std::vector<double>& context, double floor, double cap,
                            double sMax) {
    // The mean as the bisection always took it: in index order, divided once.
    const auto meanFor = [&](double s) {
        double sum = 0;
        for (std::size_t i = 0; i < field.size(); ++i) sum += context[i] * std::clamp(s * field[i], floor, cap);
        return sum / double(field.size());
    };
    // 1. Near the root in a few passes: the sum is linear in s between each cell's clamp knots, so
    // each pass follows the line of the piece s is on to its root, bisection guarding the bracket.
    const double wanted = double(field.size());
    double lo = 0.0, hi = sMax, guess = sMax;
    for (int pass = 0; pass < 100; ++pass) {
        double constant = 0.0, slope = 0.0;
        for (std::size_t i = 0; i < field.size(); ++i) {
            const double v = guess * field[i];
            if (v <= floor) constant += context[i] * floor;
            else if (v >= cap) constant += context[i] * cap;
            else slope += context[i] * field[i];
        }
        const double sum = constant + slope * guess;
        if (std::abs(sum - wanted) <= 1e-14 * wanted) break;
        (sum < wanted ? lo : hi) = guess;
        if (!(hi - lo > 1e-14 * hi)) break;
        const double root = slope > 0.0 ? (wanted - constant) / slope : -1.0;
        guess = (root > lo && root < hi) ? root : 0.5 * (lo + hi);
    }
    // 2. The exact double: meanFor is monotone in s as computed (every term is, and a rounded sum
    // of non-decreasing terms is), so the least s with meanFor(s) >= 1 is what bisecting [0, sMax]
    // to adjacent doubles finds; here the bisection starts from a bracket around the guess.
    lo = 0.0;
    hi = sMax;
    for (double width = 1e-12; width < 1.0; width *= 64.0) {
        const double a = guess * (1.0 - width), b = std::min(sMax, guess * (1.0 + width));
        if (meanFor(a) < 1.0 && meanFor(b) >= 1.0) {
            lo = a;
            hi = b;
            break;
        }
    }
    for (;;) {
        const double mid = 0.5 * (lo + hi);
        if (!(mid > lo && mid < hi)) return hi;
        (meanFor(mid) < 1.0 ? lo : hi) = mid;
    }
}

DensityField importanceToDensity(const Image& importance, const AutoMapOptions& options) {
    if (importance.empty()) invalid("the importance image is empty");
    if (!(options.minDensity > 0 && options.minDensity < 1))
        invalid("min density " + std::to_string(options.minDensity) + " must lie in (0, 1)");
    if (!(options.maxDensity > 1 && options.maxDensity <= 4096))
        invalid("max density " + std::to_string(options.maxDensity) + " must lie in (1, 4096]");
    if (!(options.smoothing >= 0 && options.smoothing <= 0.5))
        invalid("smoothing " + std::to_string(options.smoothing) + " must lie in [0, 0.5]");
    for (float v : importance.pixels) {
        if (!std::isfinite(v)) invalid("the importance image holds NaN or infinite values");
        if (v < 0) invalid("the importance image holds negative values (" + std::to_string(v) + ")");
    }

    // Down to at most kMaxGrid cells a side, keeping the aspect (cells stay square-ish).
    const double scale = std::min(1.0, double(kMaxGrid) / std::max(importance.width, importance.height));
    const int gw = std::max(2, static_cast<int>(std::lround(importance.width * scale)));
    const int gh = std::max(2, static_cast<int>(std::lround(importance.height * scale)));
    Image single = makeImage(importance.width, importance.height, {"Y"});
    single.pixels = luminance(importance);
    const Image small = (gw <= importance.width && gh <= importance.height)
                                    ? areaDownsample(single, gw, gh)
                                    : resizeBilinear(single, {}, gw, gh);
    std::vector<double> field(small.pixels.begin(), small.pixels.end());
    // A map of n nodes a side cannot follow detail finer than its cells, and a target it cannot
    // follow only makes the flow swirl: blur at least over one map cell.
    const double cell = std::max(double(gw) / std::max(1, options.columns - 1), double(gh) / std::max(1, options.rows - 1));
    blur(field, gw, gh, static_cast<int>(std::lround(std::max(options.smoothing * gw, 0.5 * cell))));

    // The context at each cell, normalized to mean 1 over them (1 everywhere without one).
    std::vector<double> context(field.size(), 1.0);
    if (options.context) {
        double sum = 0;
        for (int y = 0; y < gh; ++y)
            for (int x = 0; x < gw; ++x) sum += context[std::size_t(y) * gw + x] = densityAt(*options.context, (x + 0.5) / gw, (y + 0.5) / gh);
        for (double& v : context) v *= double(context.size()) / sum;
    }

    DensityField out;
    out.width = gw;
    out.height = gh;
    out.values.assign(context.begin(), context.end());
    const double peak = *std::max_element(field.begin(), field.end());
    if (!(peak > 0)) return out;  // no importance anywhere: the context alone

    // s such that mean(clamp(s I, floor, max)) == 1; the mean grows monotonically with s and with
    // the floor. When even saturating every important cell at maxDensity leaves the mean below 1
    // (importance on a few cells), the context gets more than the floor instead.
    auto meanFor = [&](double s, double floor) {
        double sum = 0;
        for (std::size_t i = 0; i < field.size(); ++i) sum += context[i] * std::clamp(s * field[i], floor, options.maxDensity);
        return sum / field.size();
    };
    double smallest = peak;
    for (double v : field)
        if (v > 0) smallest = std::min(smallest, v);
    const double sMax = options.maxDensity / smallest;
    double s = sMax, floor = options.minDensity;
    if (meanFor(sMax, floor) < 1.0) {
        double lo = floor, hi = 1.0;
        for (int i = 0; i < 100; ++i) {
            const double mid = 0.5 * (lo + hi);
            (meanFor(sMax, mid) < 1.0 ? lo : hi) = mid;
        }
        floor = hi;
    } else {
        s = leastScaleForMeanOne(field, context, floor, options.maxDensity, sMax);
    }
    for (std::size_t i = 0; i < field.size(); ++i)
        out.values[i] = static_cast<float>(context[i] * std::clamp(s * field[i], floor, options.maxDensity));
    return out;
}

SamplingMap buildSeparableMap(const DensityField& target, int columns, int rows) {
    const int w = target.width, h = target.height;
    // Cumulative marginals, normalized to end at 1; node i sits at F(i/(columns-1)).
    auto cumulative = [](const std::vector<double>& marginal) {
        std::vector<double> c(marginal.size() + 1, 0.0);
        for (std::size_t i = 0; i < marginal.size(); ++i) c[i + 1] = c[i] + marginal[i];
        for (double& v : c) v /= c.back();
        return c;
    };
    std::vector<double> mu(w, 0.0), mv(h, 0.0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            mu[x] += target.values[y * w + x];
            mv[y] += target.values[y * w + x];
        }
    const auto cu = cumulative(mu), cv = cumulative(mv);
    auto lookup = [](const std::vector<double>& c, double t) {
        const double f = t * (c.size() - 1);
        const int i = std::min(static_cast<int>(f), static_cast<int>(c.size()) - 2);
        return c[i] + (f - i) * (c[i + 1] - c[i]);
    };
    std::vector<glm::vec2> nodes(static_cast<std::size_t>(columns) * rows);
    for (int j = 0; j < rows; ++j)
        for (int i = 0; i < columns; ++i) {
            float x = static_cast<float>(lookup(cu, double(i) / (columns - 1)));
            float y = static_cast<float>(lookup(cv, double(j) / (rows - 1)));
            // Exactly on the edges (V10), whatever the rounding of the cumulative sums.
            if (i == 0) x = 0;
            if (i == columns - 1) x = 1;
            if (j == 0) y = 0;
            if (j == rows - 1) y = 1;
            nodes[static_cast<std::size_t>(j) * columns + i] = {x, y};
        }
    return SamplingMap(columns, rows, std::move(nodes));
}

SamplingMap buildAutoMap(const Image& importance, const AutoMapOptions& options) {
    const DensityField target = importanceToDensity(importance, options);
    const auto within = [&](const MapMeasures& m) {
        return m.minCellDensity >= options.minDensity * (1.0 - kDensityBoundTolerance) &&
               m.maxCellDensity <= options.maxDensity * (1.0 + kDensityBoundTolerance);
    };
    const double aspect = fieldAspect(target);
    if (options.method == AutoMethod::Separable) {
        SamplingMap map = buildSeparableMap(target, options.columns, options.rows);
        const MapMeasures m = measureMap(map, aspect);
        if (options.refuseBounds && !within(m)) refuseBounds(m, options);
        return map;
    }
    DensityMapOptions mapOptions;
    mapOptions.columns = options.columns;
    mapOptions.rows = options.rows;
    mapOptions.maxAnisotropy = options.maxAnisotropy;
    mapOptions.builder = options.builder;
    mapOptions.minDensity = options.minDensity;  // the target's mean is 1 (importanceToDensity)
    if (options.context) {
        // The bounds hold on the importance's factor, which the target already holds: one round,
        // the builder's floor the target's lowest density.
        mapOptions.minDensity = *std::min_element(target.values.begin(), target.values.end());
        return buildMapFromDensity(target, mapOptions);
    }
    // A grid cannot follow a steep rise exactly: the cells beside it come out denser or sparser than
    // the target. Each round divides the followed field by what the map achieved there (its cell
    // density at each sample) and rebuilds; the best map by its worst bound violation is kept.
    DensityField followed = target;
    std::optional<SamplingMap> best;
    double bestExcess = HUGE_VAL;
    MapMeasures bestMeasures;
    for (int round = 0; round < kBoundRounds; ++round) {
        SamplingMap map = buildMapFromDensity(followed, mapOptions);
        const MapMeasures m = measureMap(map, aspect);
        const double excess = std::max(options.minDensity / m.minCellDensity, m.maxCellDensity / options.maxDensity);
        if (excess < bestExcess) {
            bestExcess = excess;
            bestMeasures = m;
            best = std::move(map);
        }
        if (within(m)) break;
        const SamplingMap& last = *best;
        for (int y = 0; y < followed.height; ++y)
            for (int x = 0; x < followed.width; ++x) {
                const std::size_t k = std::size_t(y) * followed.width + x;
                const double achieved = cellDensityAt(last, {(x + 0.5) / followed.width, (y + 0.5) / followed.height});
                const double wanted = target.values[k];
                // Only the cells that break a bound are pushed, half-way (in log) past their bound.
                double factor = 1.0;
                if (achieved < options.minDensity) factor = std::sqrt(options.minDensity / achieved) * options.minDensity / achieved;
                if (achieved > options.maxDensity) factor = std::sqrt(options.maxDensity / achieved) * options.maxDensity / achieved;
                if (factor == 1.0) continue;
                followed.values[k] = static_cast<float>(std::clamp(followed.values[k] * factor, wanted * 1e-3, wanted * 1e3));
            }
    }
    if (options.refuseBounds && !within(bestMeasures)) refuseBounds(bestMeasures, options);
    return std::move(*best);
}

// importance.h's detail rule, here beside importanceToDensity for the luminance they share.
namespace {
// The detail rule reads the luminance area-downsampled to at most this many pixels a side.
constexpr int kDetailSide = 1024;
// The size the detail rule reads a width x height picture's luminance at; `shrinks` where that
// is an area downsample of it.
struct DetailSize {
    int width, height;
    bool shrinks;
};
DetailSize detailSize(int width, int height) {
    const double scale = std::min(1.0, double(kDetailSide) / std::max(width, height));
    return {std::max(1, static_cast<int>(std::lround(width * scale))), std::max(1, static_cast<int>(std::lround(height * scale))),
            scale < 1};
}
Image detailOfLuminance(const Image& single);
Image sobelMagnitude(const Image& small);
}

Image detailImportance(const Image& image) {
    if (image.empty()) invalid("the image is empty");
    return detailOfLuminance(Image{image.width, image.height, {"Y"}, luminance(image)});
}

Image detailImportanceOfLuminance(const Image& luminance) {
    if (luminance.empty() || luminance.channelCount() != 1) invalid("the luminance must be one channel");
    return detailOfLuminance(luminance);
}

Image detailImportance(const EightBitImage& codes, const float* shownCode) {
    if (codes.width < 1 || codes.height < 1 || codes.channels.empty() ||
        codes.codes.size() != std::size_t(codes.width) * codes.height * codes.channels.size())
        invalid("the image is empty");
    // luminance() of the codes' display values, without a float copy of the picture.
    const std::vector<std::string>& names = codes.channels;
    const auto index = [&](const char* name) {
        const auto it = std::find(names.begin(), names.end(), name);
        return it == names.end() ? -1 : static_cast<int>(it - names.begin());
    };
    const int r = index("R"), g = index("G"), b = index("B"), y = std::max(0, index("Y"));
    const std::size_t ch = names.size();
    const float* unit = shownCode ? shownCode : codeToUnit();
    const auto luminanceRow = [&](int row, float* out) {
        const std::uint8_t* px = &codes.codes[std::size_t(row) * codes.width * ch];
        for (int x = 0; x < codes.width; ++x, px += ch)
            out[x] = (r >= 0 && g >= 0 && b >= 0) ? (unit[px[r]] + unit[px[g]] + unit[px[b]]) / 3.0f : unit[px[y]];
    };
    const DetailSize size = detailSize(codes.width, codes.height);
    if (size.shrinks) {
        // Rows of luminance made as the downsample reads them: no picture-sized copy.
        Image small = makeImage(size.width, size.height, {"Y"});
        detail::areaDownsampleRows(codes.width, codes.height, 1, luminanceRow, small.pixels.data(), size.width, size.height, 0);
        return sobelMagnitude(small);
    }
    Image single = makeImage(codes.width, codes.height, {"Y"});
    for (int row = 0; row < codes.height; ++row) luminanceRow(row, single.pixels.data() + std::size_t(row) * codes.width);
    return sobelMagnitude(single);
}

namespace {
// The detail rule on the picture's luminance: area-downsampled to at most kDetailSide px a side,
// its Sobel gradient magnitude.
Image detailOfLuminance(const Image& single) {
    const DetailSize size = detailSize(single.width, single.height);
    return sobelMagnitude(size.shrinks ? areaDownsample(single, size.width, size.height) : single);
}

// The Sobel gradient magnitude of a one-channel picture (its border clamped).
Image sobelMagnitude(const Image& small) {
    const int w = small.width, h = small.height;
    Image detail = makeImage(w, h, {"Y"});
    auto at = [&](int x, int y) { return small.at(std::clamp(x, 0, w - 1), std::clamp(y, 0, h - 1)); };
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            // Sobel gradient magnitude.
            const double gx = (at(x + 1, y - 1) + 2 * at(x + 1, y) + at(x + 1, y + 1)) -
                              (at(x - 1, y - 1) + 2 * at(x - 1, y) + at(x - 1, y + 1));
            const double gy = (at(x - 1, y + 1) + 2 * at(x, y + 1) + at(x + 1, y + 1)) -
                              (at(x - 1, y - 1) + 2 * at(x, y - 1) + at(x + 1, y - 1));
            detail.at(x, y) = static_cast<float>(std::sqrt(gx * gx + gy * gy));
        }
    return detail;
}
}  // namespace

double densityCorrelation(const SamplingMap& map, const DensityField& target) {
    const std::size_t n = target.values.size();
    std::vector<double> achieved(n);
    for (int y = 0; y < target.height; ++y)
        for (int x = 0; x < target.width; ++x)
            achieved[y * target.width + x] = map.density({(x + 0.5) / target.width, (y + 0.5) / target.height});
    const double ma = std::accumulate(achieved.begin(), achieved.end(), 0.0) / n;
    const double mt = std::accumulate(target.values.begin(), target.values.end(), 0.0) / n;
    double sab = 0, saa = 0, stt = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const double a = achieved[i] - ma, t = target.values[i] - mt;
        sab += a * t;
        saa += a * a;
        stt += t * t;
    }
    if (saa <= 0 || stt <= 0) return (saa <= 0 && stt <= 0) ? 1.0 : 0.0;
    return sab / std::sqrt(saa * stt);
}

}  // namespace conus::codec
