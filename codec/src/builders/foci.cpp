// Circular foci: their target density, and maps built from it (joint density, or the paper's
// addition of displacement vectors).
#include "conus/codec/builders/foci.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <string>

#include "conus/codec/builders/density_map.h"
#include "conus/codec/builders/map_measures.h"
#include "conus/core/error.h"
#include "conus/core/map_rules.h"

namespace conus::codec {
namespace {

// The density grid resolves the smallest focus radius with at least this many samples, within
// [kMinDensitySide, kMaxDensitySide] samples along the longer side.
constexpr double kSamplesPerRadius = 12.0;
constexpr int kMinDensitySide = 256;
constexpr int kMaxDensitySide = 512;
constexpr int kMinShortSide = 32;
// Add composition: the factor applied to all displacements while the sum folds.
constexpr double kAddShrink = 0.9;

void checkOptions(const FociOptions& options) {
    if (!(options.aspect > 0.0) || !std::isfinite(options.aspect)) {
        throw Error(ErrorCode::InvalidArgument, "aspect " + numberText(options.aspect) + " is not finite and > 0");
    }
    checkFalloff(options.falloff);
}

// Quintic smoothstep: 0 at x <= 0, 1 at x >= 1, C2 in between.
double smoothstep(double x) {
    if (x <= 0.0) return 0.0;
    if (x >= 1.0) return 1.0;
    return x * x * x * (x * (x * 6.0 - 15.0) + 10.0);
}

// The density of one focus of magnification k at s = distance / r (FociFalloff).
double focusDensity(double s, double k, const FociFalloff& falloff) {
    if (s <= 1.0) return k * k;
    if (s >= falloff.width) return 1.0;
    switch (falloff.shape) {
        case FociFalloffShape::Density:
            return 1.0 + (k * k - 1.0) * smoothstep((falloff.width - s) / (falloff.width - 1.0));
        case FociFalloffShape::LogDensity:
            return std::pow(k, 2.0 * smoothstep((falloff.width - s) / (falloff.width - 1.0)));
        case FociFalloffShape::LogRadius:
            return std::pow(k, 2.0 * smoothstep(std::log(falloff.width / s) / std::log(falloff.width)));
    }
    return 1.0;
}

// WidenedFocus's table step, and where the table ends (density 1 beyond), in radii.
constexpr double kWidenedStep = 1.0 / 512.0;
constexpr double kWidenedLimit = 64.0;

DensityField sampleFociDensity(std::span<const Focus> foci, double aspect, const FociFalloff& falloff, double bound = 0,
                               const DensityField* context = nullptr) {
    double rMin = 1.0;
    for (const Focus& f : foci) rMin = std::min(rMin, f.r);
    // Radius in u is r, in v it is r * aspect; sample pixel-isotropically (H = W / aspect).
    const double needW = kSamplesPerRadius / rMin, needH = kSamplesPerRadius / (rMin * aspect);
    double w = std::max(needW, needH * aspect), h = w / aspect;
    const double longSide = std::max(w, h);
    const double scale = std::clamp(longSide, double(kMinDensitySide), double(kMaxDensitySide)) / longSide;
    DensityField field;
    field.width = std::max(kMinShortSide, static_cast<int>(std::lround(w * scale)));
    field.height = std::max(kMinShortSide, static_cast<int>(std::lround(h * scale)));
    field.values.resize(std::size_t(field.width) * field.height);
    std::vector<WidenedFocus> profiles;
    if (bound > 0)
        for (const Focus& f : foci) profiles.emplace_back(f.k, falloff, bound);
    for (int y = 0; y < field.height; ++y)
        for (int x = 0; x < field.width; ++x) {
            const double u = (x + 0.5) / field.width, v = (y + 0.5) / field.height;
            double density = 1.0;
            if (bound > 0) {
                for (std::size_t i = 0; i < foci.size(); ++i) {
                    const double dx = u - foci[i].u, dy = (v - foci[i].v) / aspect;
                    density = std::max(density, profiles[i].density(std::sqrt(dx * dx + dy * dy) / foci[i].r));
                }
            } else {
                density = fociDensity(foci, aspect, u, v, falloff);
            }
            // The foci multiply the context: k times its rate there (a focus on detail gets more
            // than one on a flat sky, which a higher rate would not show).
            if (context) density *= densityAt(*context, u, v);
            field.values[std::size_t(y) * field.width + x] = static_cast<float>(density);
        }
    return field;
}

double boundOf(const FociOptions& options) {
    if (options.builder != DensityBuilder::Bounded) return options.maxAnisotropy;
    return options.maxAnisotropy > 0 ? options.maxAnisotropy : map_rules::kMaxAnisotropy;
}

SamplingMap buildDensityComposition(std::span<const Focus> foci, const FociOptions& options, DensityMapReport* report = nullptr) {
    DensityMapOptions mapOptions;
    mapOptions.columns = options.columns;
    mapOptions.rows = options.rows;
    mapOptions.maxAnisotropy = options.maxAnisotropy;
    mapOptions.builder = options.builder;
    mapOptions.aspect = options.aspect;
    const double widenFor = options.builder == DensityBuilder::Bounded ? boundOf(options) : 0.0;
    return buildMapFromDensity(sampleFociDensity(foci, options.aspect, options.falloff, widenFor, options.context), mapOptions, report);
}

std::string focusText(const Focus& f) {
    return numberText(f.u) + "," + numberText(f.v) + "," + numberText(f.r) + "," + numberText(f.k);
}

std::string rounded(double value) { return numberText(std::round(value * 100) / 100); }

// A focus holds its k when it reaches three quarters of its extra magnification.
bool heldWell(double reached, double k) { return reached >= 1.0 + 0.75 * (k - 1.0) - 1e-9; }

// The bounded density composition, refining the grid while a focus smaller than a few of its
// cells misses its k, with the report.
SamplingMap buildBoundedFoci(std::span<const Focus> foci, const FociOptions& options, FociReport* report) {
    // Refining helps only a focus this few cells wide; a larger one that misses is held back by
    // the bound or by its neighbours, which a finer grid does not change.
    constexpr double kSmallFocusCells = 4.0;
    FociOptions o = options;
    DensityMapReport densityReport;
    SamplingMap map = buildDensityComposition(foci, o, &densityReport);
    std::vector<double> reached = reachedMagnification(map, foci);
    const auto needsFiner = [&](const FociOptions& at, const std::vector<double>& r) {
        if (std::max(at.columns, at.rows) >= kMaxRefinedSide) return false;
        for (std::size_t i = 0; i < foci.size(); ++i) {
            const double cells = foci[i].r * std::min(at.columns - 1, int(std::lround((at.rows - 1) * options.aspect)));
            if (!heldWell(r[i], foci[i].k) && cells < kSmallFocusCells) return true;
        }
        return false;
    };
    while (needsFiner(o, reached)) {
        o.columns = std::min(2 * o.columns - 1, kMaxRefinedSide);
        o.rows = std::min(2 * o.rows - 1, kMaxRefinedSide);
        DensityMapReport finerReport;
        SamplingMap finer = buildDensityComposition(foci, o, &finerReport);
        map = std::move(finer);
        densityReport = finerReport;
        reached = reachedMagnification(map, foci);
    }
    if (!report) return map;
    const double bound = boundOf(options);
    *report = {};
    report->columns = map.columns();
    report->rows = map.rows();
    report->bound = bound;
    report->maxAnisotropy = densityReport.maxAnisotropy;
    report->reached = reached;
    if (map.columns() != options.columns || map.rows() != options.rows) {
        report->notes.push_back("grid refined from " + std::to_string(options.columns) + "x" + std::to_string(options.rows) + " to " +
                                std::to_string(map.columns()) + "x" + std::to_string(map.rows()) + " nodes for the smallest focus");
    }
    for (std::size_t i = 0; i < foci.size(); ++i) {
        const double end = WidenedFocus(foci[i].k, options.falloff, bound).end();
        report->transition.push_back(end);
        if (end > options.falloff.width + 1e-9) {
            report->notes.push_back("focus " + focusText(foci[i]) + ": transition widened from " + rounded(options.falloff.width) +
                                    " to " + rounded(end) + " radii to keep anisotropy under " + rounded(bound));
        }
        if (!heldWell(reached[i], foci[i].k)) {
            report->notes.push_back("focus " + focusText(foci[i]) + ": magnification " + rounded(reached[i]) + " of " +
                                    rounded(foci[i].k) + " (the anisotropy bound " + rounded(bound) +
                                    " and the frame's edges or neighbouring foci leave no more)");
        }
    }
    return map;
}

SamplingMap buildAddComposition(std::span<const Focus> foci, const FociOptions& options) {
    const int n = options.columns, m = options.rows;
    const std::size_t count = std::size_t(n) * m;
    std::vector<glm::dvec2> displacement(count, glm::dvec2(0.0));
    for (const Focus& f : foci) {
        const SamplingMap single = buildDensityComposition(std::span<const Focus>(&f, 1), options);
        for (int j = 0; j < m; ++j)
            for (int i = 0; i < n; ++i) {
                const std::size_t k = std::size_t(j) * n + i;
                displacement[k] += glm::dvec2(single.nodes()[k]) - glm::dvec2(double(i) / (n - 1), double(j) / (m - 1));
            }
    }
    format::GridNodes grid;
    grid.columns = n;
    grid.rows = m;
    grid.xy.resize(2 * count);
    for (double scale = 1.0;; scale *= kAddShrink) {
        if (scale < 1e-3) scale = 0.0;  // the identity: always valid
        for (int j = 0; j < m; ++j)
            for (int i = 0; i < n; ++i) {
                const std::size_t k = std::size_t(j) * n + i;
                glm::dvec2 p = glm::dvec2(double(i) / (n - 1), double(j) / (m - 1)) + scale * displacement[k];
                p = glm::clamp(p, 0.0, 1.0);
                if (i == 0) p.x = 0.0;
                if (i == n - 1) p.x = 1.0;
                if (j == 0) p.y = 0.0;
                if (j == m - 1) p.y = 1.0;
                grid.xy[2 * k] = static_cast<float>(p.x);
                grid.xy[2 * k + 1] = static_cast<float>(p.y);
            }
        if (scale == 0.0 || map_rules::isValidGrid(grid.columns, grid.rows, grid.xy)) return SamplingMap::fromGrid(grid);
    }
}

}  // namespace

double fociDensity(std::span<const Focus> foci, double aspect, double u, double v, const FociFalloff& falloff) {
    double density = 1.0;
    for (const Focus& f : foci) {
        const double dx = u - f.u, dy = (v - f.v) / aspect;
        density = std::max(density, focusDensity(std::sqrt(dx * dx + dy * dy) / f.r, f.k, falloff));
    }
    return density;
}

void checkFalloff(const FociFalloff& falloff) {
    if (!(falloff.width > 1.0 && falloff.width <= map_rules::kMaxFalloffWidth)) {
        throw Error(ErrorCode::InvalidArgument, "focus falloff width " + numberText(falloff.width) + " is not in (1, " +
                                                    numberText(map_rules::kMaxFalloffWidth) + "] (radii of the focus)");
    }
}

FociFalloff parseFalloff(const std::string& text) {
    FociFalloff falloff;
    const std::size_t comma = text.find(',');
    const std::string width = text.substr(0, comma);
    const std::string shape = comma == std::string::npos ? enumName(FociFalloff{}.shape) : text.substr(comma + 1);
    char* end = nullptr;
    errno = 0;
    falloff.width = std::strtod(width.c_str(), &end);
    if (width.empty() || end != width.c_str() + width.size() || errno == ERANGE) {
        throw Error(ErrorCode::InvalidArgument, "falloff \"" + text + "\": width \"" + width + "\" is not a number");
    }
    if (const std::optional<FociFalloffShape> parsed = tryParseEnum<FociFalloffShape>(shape)) falloff.shape = *parsed;
    else throw Error(ErrorCode::InvalidArgument, "falloff \"" + text + "\": shape \"" + shape + "\" is not one of " + enumChoices<FociFalloffShape>());
    try {
        checkFalloff(falloff);
    } catch (const Error& e) {
        throw Error(ErrorCode::InvalidArgument, "falloff \"" + text + "\": " + e.what());
    }
    return falloff;
}

std::string falloffText(const FociFalloff& falloff) {
    return numberText(falloff.width) + "," + enumName(falloff.shape);
}

void checkFocus(const Focus& f) {
    if (!map_rules::focusCentreValid(f.u, f.v)) {
        throw Error(ErrorCode::InvalidArgument, "focus centre (" + numberText(f.u) + ", " + numberText(f.v) + ") is outside [0,1]^2");
    }
    if (!map_rules::focusRadiusValid(f.r)) {
        throw Error(ErrorCode::InvalidArgument, "focus radius " + numberText(f.r) + " is not in (0, " + numberText(map_rules::kMaxFocusRadius) + "]");
    }
    if (!map_rules::focusMagnificationValid(f.k)) {
        throw Error(ErrorCode::InvalidArgument, "focus magnification " + numberText(f.k) + " is not in [1, " + numberText(map_rules::kMaxMagnification) + "]");
    }
}

Focus hottestRegion(const Image& importance, int width, int height) {
    float peak = 0;
    for (int y = 0; y < importance.height; ++y)
        for (int x = 0; x < importance.width; ++x) peak = std::max(peak, importance.at(x, y));
    double u0 = 1, v0 = 1, u1 = 0, v1 = 0;
    for (int y = 0; y < importance.height; ++y)
        for (int x = 0; x < importance.width; ++x)
            if (peak > 0 && importance.at(x, y) >= 0.5f * peak) {
                u0 = std::min(u0, double(x) / importance.width);
                u1 = std::max(u1, double(x + 1) / importance.width);
                v0 = std::min(v0, double(y) / importance.height);
                v1 = std::max(v1, double(y + 1) / importance.height);
            }
    if (u1 <= u0) return {0.5, 0.5, 0.1, 1};
    const double half = 0.5 * std::max((u1 - u0) * width, (v1 - v0) * height) / width;
    return {0.5 * (u0 + u1), 0.5 * (v0 + v1), std::max(half, 8.0 / width), 1};
}

namespace {
// The larger of the falloff's density and the bound's, joined smoothly (a p-norm of their excess
// over the context's 1): never below either, and without the kink of a plain max, whose sudden
// change of slope shows as a ring of aliasing in the encoded picture.
double join(double base, double bounded) {
    constexpr double kJoinPower = 4.0;
    const double a = base - 1.0, b = std::max(bounded - 1.0, 0.0);
    if (a <= 0.0) return 1.0 + b;
    if (b <= 0.0) return base;
    return 1.0 + std::pow(std::pow(a, kJoinPower) + std::pow(b, kJoinPower), 1.0 / kJoinPower);
}
}  // namespace

WidenedFocus::WidenedFocus(double k, const FociFalloff& falloff, double bound) {
    checkFalloff(falloff);
    const double design = std::max(1.0 + 1e-3, kTransitionShare * bound);
    const double step = kWidenedStep;
    double mass = 0.0, s = 0.0, d = k * k;
    m_density.push_back(d);
    // M(s) = integral of 2 t d(t) dt by trapezoids; d(next) depends on M(next), so one
    // fixed-point pass from the explicit guess (exact to the step's order).
    while (true) {
        const double next = s + step;
        const double base = focusDensity(next, k, falloff);
        if (next <= 1.0) {  // the disc: k^2 (its own anisotropy is 1)
            mass += step * (s * d + next * base);
            s = next;
            d = base;
            m_density.push_back(d);
            continue;
        }
        // Capped at k^2, which the bound's density (at most k^2 / K) never needs.
        double dNext = std::min(k * k, join(base, (mass + 2.0 * next * d * step) / (design * next * next)));
        dNext = std::min(k * k, join(base, (mass + 0.5 * step * (2.0 * s * d + 2.0 * next * dNext)) / (design * next * next)));
        mass += 0.5 * step * (2.0 * s * d + 2.0 * next * dNext);
        s = next;
        d = dNext;
        m_density.push_back(d);
        // A bound near 1 allows almost no change of density: the transition would never end.
        if ((s >= falloff.width && d <= 1.0) || s >= kWidenedLimit) break;
    }
    m_end = s;
}

double WidenedFocus::density(double s) const {
    const double x = s / kWidenedStep;
    if (!(x < double(m_density.size() - 1))) return 1.0;
    const std::size_t i = static_cast<std::size_t>(x);
    return m_density[i] + (x - i) * (m_density[i + 1] - m_density[i]);
}

SamplingMap buildFociMap(std::span<const Focus> foci, const FociOptions& options) { return buildFociMap(foci, options, nullptr); }

SamplingMap buildFociMap(std::span<const Focus> foci, const FociOptions& options, FociReport* report) {
    checkOptions(options);
    for (const Focus& f : foci) checkFocus(f);
    if (options.columns < 2 || options.rows < 2) {
        throw Error(ErrorCode::InvalidArgument, "foci map grid " + std::to_string(options.columns) + "x" +
                                                    std::to_string(options.rows) + " needs at least 2x2 nodes");
    }
    if (foci.empty()) {
        if (report) *report = {options.columns, options.rows, boundOf(options), 1.0, {}, {}, {}};
        return SamplingMap::identity(options.columns, options.rows);
    }
    if (options.composition == FociComposition::Density && options.builder == DensityBuilder::Bounded)
        return buildBoundedFoci(foci, options, report);
    SamplingMap map = options.composition == FociComposition::Add ? buildAddComposition(foci, options)
                                                                  : buildDensityComposition(foci, options);
    if (report) {
        *report = {map.columns(), map.rows(), boundOf(options), measureMap(map, options.aspect).maxAnisotropy,
                   reachedMagnification(map, foci), std::vector<double>(foci.size(), options.falloff.width), {}};
    }
    return map;
}

std::vector<double> reachedMagnification(const SamplingMap& map, std::span<const Focus> foci) {
    // The lowest density, sampled finely enough to find the context between and around foci.
    constexpr int kSamples = 64;
    double lowest = std::numeric_limits<double>::infinity();
    for (int j = 0; j < kSamples; ++j)
        for (int i = 0; i < kSamples; ++i) lowest = std::min(lowest, map.density({(i + 0.5) / kSamples, (j + 0.5) / kSamples}));
    std::vector<double> reached;
    for (const Focus& f : foci) reached.push_back(std::sqrt(std::max(0.0, map.density({f.u, f.v}) / lowest)));
    return reached;
}

void checkFociHeld(const SamplingMap& map, std::span<const Focus> foci, const FociOptions& options) {
    constexpr int kLargestSuggestion = 257;
    auto firstMissed = [&](const SamplingMap& m) -> int {
        const std::vector<double> reached = reachedMagnification(m, foci);
        for (std::size_t i = 0; i < foci.size(); ++i)
            if (reached[i] < 1.0 + 0.5 * (foci[i].k - 1.0)) return static_cast<int>(i);
        return -1;
    };
    const int missed = firstMissed(map);
    if (missed < 0) return;
    const Focus& f = foci[missed];
    const double reached = reachedMagnification(map, foci)[missed];
    const std::string focusText = numberText(f.u) + "," + numberText(f.v) + "," + numberText(f.r) + "," + numberText(f.k);
    if (options.maxAnisotropy > 0) {
        FociOptions unlimited = options;
        unlimited.maxAnisotropy = 0;
        if (firstMissed(buildFociMap(foci, unlimited)) < 0) {
            throw Error(ErrorCode::InvalidArgument,
                        "the anisotropy limit " + numberText(options.maxAnisotropy) + " leaves focus " + focusText +
                            " a magnification of " + numberText(std::round(reached * 100) / 100) +
                            ": raise --max-anisotropy, widen the focus (larger r) or lower its k");
        }
    }
    std::string advice = "no grid up to " + std::to_string(kLargestSuggestion) + " nodes a side holds it";
    for (int side = 3; side <= kLargestSuggestion; side = 2 * side - 1) {
        if (side <= std::max(options.columns, options.rows)) continue;
        FociOptions finer = options;
        finer.columns = finer.rows = side;
        if (firstMissed(buildFociMap(foci, finer)) < 0) {
            advice = "a grid of " + std::to_string(side) + " nodes a side or more does";
            break;
        }
    }
    throw Error(ErrorCode::InvalidArgument,
                "a " + std::to_string(options.columns) + "x" + std::to_string(options.rows) + " grid is too coarse for focus " +
                    focusText + ": it reaches a magnification of " +
                    numberText(std::round(reached * 100) / 100) + " there; " + advice);
}

Focus parseFocus(const std::string& text) {
    std::vector<std::string> parts;
    std::size_t begin = 0;
    while (true) {
        const std::size_t comma = text.find(',', begin);
        parts.push_back(text.substr(begin, comma == std::string::npos ? std::string::npos : comma - begin));
        if (comma == std::string::npos) break;
        begin = comma + 1;
    }
    if (parts.size() != 4) {
        throw Error(ErrorCode::InvalidArgument, "focus \"" + text + "\" has " + std::to_string(parts.size()) +
                                                    " values; expected u,v,r,k (e.g. 0.42,0.31,0.08,4)");
    }
    static constexpr const char* kNames[4] = {"u", "v", "r", "k"};
    double values[4];
    for (int c = 0; c < 4; ++c) {
        const std::string& s = parts[c];
        const char* first = s.c_str();
        char* end = nullptr;
        errno = 0;
        values[c] = std::strtod(first, &end);
        while (end && (*end == ' ' || *end == '\t')) ++end;
        if (s.find_first_not_of(" \t") == std::string::npos || end == first || *end != '\0' || errno == ERANGE ||
            !std::isfinite(values[c])) {
            throw Error(ErrorCode::InvalidArgument,
                        "focus \"" + text + "\": " + kNames[c] + " = \"" + s + "\" is not a finite number");
        }
    }
    const Focus focus{values[0], values[1], values[2], values[3]};
    try {
        checkFocus(focus);
    } catch (const Error& e) {
        throw Error(ErrorCode::InvalidArgument, "focus \"" + text + "\": " + e.what());
    }
    return focus;
}

format::AnalyticMap toAnalytic(std::span<const Focus> foci, FociComposition composition, const FociFalloff& falloff) {
    format::AnalyticMap analytic;
    analytic.kind = enumName(format::MapKind::Foci);
    analytic.composition = enumName(composition);
    for (const Focus& f : foci) analytic.foci.push_back({f.u, f.v, f.r, f.k});
    if (falloff.width != kFormatFalloff.width || falloff.shape != kFormatFalloff.shape) {
        analytic.scalars["falloffWidth"] = falloff.width;
        analytic.scalars["falloffShape"] = static_cast<double>(falloff.shape);
    }
    return analytic;
}

}  // namespace conus::codec
