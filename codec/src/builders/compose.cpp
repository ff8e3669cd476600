// Composition of sampling maps through their displacement fields, with one injectivity rule
// (a global factor on all displacements, found by bisection), and a rebuild from the composed
// density where that rule folds, starves a cell or passes the anisotropy bound (compose.h).
#include "conus/codec/builders/compose.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "conus/codec/builders/map_measures.h"
#include "conus/core/error.h"
#include "conus/core/map_rules.h"
#include "density_cells_pvt.h"

namespace conus::codec {
namespace {

// Bisection halvings on the global factor: 2^-24 is far below anything visible in a map.
constexpr int kBisectionSteps = 24;

void checkGrid(int columns, int rows, const char* what) {
    if (columns < 2 || rows < 2 || columns > kMaxMapSide || rows > kMaxMapSide) {
        throw Error(ErrorCode::InvalidArgument, std::string(what) + ": grid " + std::to_string(columns) + "x" +
                                                    std::to_string(rows) + " is outside [2, " + std::to_string(kMaxMapSide) +
                                                    "] nodes per side");
    }
}

// Displacement of `map` at undistorted q, zero outside the unit square.
glm::dvec2 displacementAt(const SamplingMap& map, glm::dvec2 q) {
    if (!(q.x >= 0.0 && q.x <= 1.0 && q.y >= 0.0 && q.y <= 1.0)) return {0.0, 0.0};
    return map.distort(q) - q;
}

// 0 for t <= 0, 1 for t >= 1, the quintic smoothstep between (its slope peaks at 15/8).
double ramp(double t) {
    t = std::clamp(t, 0.0, 1.0);
    return t * t * t * (t * (6.0 * t - 15.0) + 10.0);
}
constexpr double kRampSlope = 15.0 / 8.0;

// A map's pattern placed in the output by the affine change q = a * p + b (per axis, a > 0): the
// output's displacement is D(q) / a. Two cuts would leave it discontinuous (a visible
// square seam and a dark slit), so both are tapered:
// - An edge of the pattern's square that falls inside the output (a pattern shrunk or moved in):
//   D is tangential there but not zero (boundary nodes slide along their edge), and zero outside,
//   so nodes on either side of the edge jumped apart, and the density stepped from the pattern's
//   edge density to 1. The whole displacement fades to zero over a band inside the pattern; the
//   fade of a tangential field is a shear (no change of density), so density meets 1 smoothly.
// - An edge of the output that cuts the pattern (a pattern enlarged or moved out): D has a normal
//   part there that only the boundary nodes dropped, squeezing or stretching one row of cells
//   into a slit. The normal part fades to zero over a band wide enough that the fade changes the
//   density by at most a half (and at least a quarter of the frame).
struct Placement {
    glm::dvec2 a{1.0}, b{0.0};
};

std::vector<glm::dvec2> placedDisplacement(const SamplingMap& map, Placement placement) {
    const int columns = map.columns(), rows = map.rows();
    const glm::dvec2 a = placement.a, b = placement.b;
    constexpr double kInside = 1e-9;
    const auto strictlyInside = [](double t) { return t > kInside && t < 1.0 - kInside; };
    // Pattern edges inside the output, per axis: [axis][0] the q = 0 edge, [axis][1] the q = 1 edge.
    bool patternEdge[2][2], outputCut[2][2];
    double bandQ[2], bandOut[2];
    const double cell[2] = {1.0 / (columns - 1), 1.0 / (rows - 1)};
    for (int axis = 0; axis < 2; ++axis) {
        patternEdge[axis][0] = strictlyInside(-b[axis] / a[axis]);
        patternEdge[axis][1] = strictlyInside((1.0 - b[axis]) / a[axis]);
        outputCut[axis][0] = strictlyInside(b[axis]);
        outputCut[axis][1] = strictlyInside(a[axis] + b[axis]);
        // A tenth of the pattern, and at least two output cells.
        bandQ[axis] = std::max(0.1, 2.0 * cell[axis] * a[axis]);
    }
    // The largest normal displacement anywhere (the band reaches in where it may be larger than at
    // the edge) sets the band of each cut output edge: its fade then changes the density by at
    // most half; and at least a quarter of the frame, so that the change is gentle.
    glm::dvec2 largest(0.0);
    for (int j = 0; j < rows; ++j)
        for (int i = 0; i < columns; ++i)
            largest = glm::max(largest, glm::abs(displacementAt(map, a * glm::dvec2(double(i) / (columns - 1), double(j) / (rows - 1)) + b) / a));
    for (int axis = 0; axis < 2; ++axis) bandOut[axis] = std::clamp(2.0 * kRampSlope * largest[axis], 0.25, 1.0);
    std::vector<glm::dvec2> d(std::size_t(columns) * rows);
    for (int j = 0; j < rows; ++j)
        for (int i = 0; i < columns; ++i) {
            const glm::dvec2 p(double(i) / (columns - 1), double(j) / (rows - 1));
            const glm::dvec2 q = a * p + b;
            glm::dvec2 disp = displacementAt(map, q) / a;
            double fade = 1.0;
            for (int axis = 0; axis < 2; ++axis) {
                if (patternEdge[axis][0]) fade *= ramp(q[axis] / bandQ[axis]);
                if (patternEdge[axis][1]) fade *= ramp((1.0 - q[axis]) / bandQ[axis]);
                if (outputCut[axis][0]) disp[axis] *= ramp(p[axis] / bandOut[axis]);
                if (outputCut[axis][1]) disp[axis] *= ramp((1.0 - p[axis]) / bandOut[axis]);
            }
            d[std::size_t(j) * columns + i] = fade * disp;
        }
    return d;
}

// Node positions p + s*D, boundary nodes snapped onto their edge (tangential part kept, clamped).
void placeNodes(int columns, int rows, std::span<const glm::dvec2> displacement, double s, std::vector<glm::vec2>& out) {
    out.resize(std::size_t(columns) * rows);
    for (int j = 0; j < rows; ++j) {
        const double v = double(j) / (rows - 1);
        for (int i = 0; i < columns; ++i) {
            const double u = double(i) / (columns - 1);
            const std::size_t k = std::size_t(j) * columns + i;
            double x = std::clamp(u + s * displacement[k].x, 0.0, 1.0);
            double y = std::clamp(v + s * displacement[k].y, 0.0, 1.0);
            if (!std::isfinite(x)) x = u;  // clamp passes NaN through; NaN displacement means none
            if (!std::isfinite(y)) y = v;
            if (i == 0) x = 0.0;
            if (i == columns - 1) x = 1.0;
            if (j == 0) y = 0.0;
            if (j == rows - 1) y = 1.0;
            out[k] = glm::vec2(float(x), float(y));
        }
    }
}

std::vector<glm::dvec2> resampleField(int columns, int rows, auto&& field) {
    std::vector<glm::dvec2> d(std::size_t(columns) * rows);
    for (int j = 0; j < rows; ++j)
        for (int i = 0; i < columns; ++i)
            d[std::size_t(j) * columns + i] = field(glm::dvec2(double(i) / (columns - 1), double(j) / (rows - 1)));
    return d;
}

// The target density on square samples for `aspect`, about four a cell of the output grid.
DensityField sampleTarget(int columns, int rows, double aspect, auto&& density) {
    DensityField field;
    field.width = std::clamp(4 * (std::max(columns, rows) - 1), 64, 1024);
    field.height = std::clamp(static_cast<int>(std::lround(field.width / aspect)), 16, 4096);
    field.values.resize(std::size_t(field.width) * field.height);
    for (int y = 0; y < field.height; ++y)
        for (int x = 0; x < field.width; ++x)
            field.values[std::size_t(y) * field.width + x] =
                static_cast<float>(density(glm::dvec2((x + 0.5) / field.width, (y + 0.5) / field.height)));
    return field;
}

// The density of `map` at q clamped to the unit square (a pattern's edge, continued).
double densityAt(const SamplingMap& map, glm::dvec2 q) { return map.density(glm::clamp(q, 0.0, 1.0)); }

void checkAspect(double aspect, const char* what) {
    if (!(aspect > 0.0) || !std::isfinite(aspect))
        throw Error(ErrorCode::InvalidArgument, std::string(what) + ": aspect " + numberText(aspect) + " is not finite and > 0");
}

// The displacement rule's map when it holds the density floor and the anisotropy bound, else the
// bounded builder's map of the target (compose.h).
ComposeResult composeOrBuild(int columns, int rows, std::span<const glm::dvec2> displacement, const DensityField& target, double aspect) {
    ComposeResult r = fitDisplacement(columns, rows, displacement);
    const std::vector<double> cells = cellTargets(target, columns, rows);
    const double lowest = *std::min_element(cells.begin(), cells.end());
    const MapMeasures m = measureMap(r.map, aspect);
    if (r.scale == 1.0 && m.minCellDensity >= 0.5 * lowest && m.maxAnisotropy <= map_rules::kMaxAnisotropy) return r;
    DensityMapOptions options;
    options.columns = columns;
    options.rows = rows;
    options.aspect = aspect;
    ComposeResult built{SamplingMap::identity(2, 2), 1.0, true, {}};
    built.map = buildMapFromDensity(target, options, &built.report);
    return built;
}

}  // namespace

ComposeResult fitDisplacement(int columns, int rows, std::span<const glm::dvec2> displacement) {
    checkGrid(columns, rows, "fitDisplacement");
    if (displacement.size() != std::size_t(columns) * rows) {
        throw Error(ErrorCode::InvalidArgument, "fitDisplacement: " + std::to_string(displacement.size()) +
                                                    " displacement vectors for a " + std::to_string(columns) + "x" +
                                                    std::to_string(rows) + " grid");
    }
    std::vector<glm::vec2> nodes;
    placeNodes(columns, rows, displacement, 1.0, nodes);
    if (map_rules::isValidGrid(columns, rows, nodes)) return {SamplingMap(columns, rows, std::move(nodes)), 1.0};
    // Invariant: lo is valid (0 is the identity), hi is not.
    double lo = 0.0, hi = 1.0;
    for (int it = 0; it < kBisectionSteps; ++it) {
        const double mid = 0.5 * (lo + hi);
        placeNodes(columns, rows, displacement, mid, nodes);
        (map_rules::isValidGrid(columns, rows, nodes) ? lo : hi) = mid;
    }
    placeNodes(columns, rows, displacement, lo, nodes);
    return {SamplingMap(columns, rows, std::move(nodes)), lo};
}

ComposeResult translateMap(const SamplingMap& map, glm::dvec2 offset, double aspect) {
    if (!std::isfinite(offset.x) || !std::isfinite(offset.y)) {
        throw Error(ErrorCode::InvalidArgument, "translateMap: offset (" + numberText(offset.x) + ", " + numberText(offset.y) + ") is not finite");
    }
    checkAspect(aspect, "translateMap");
    const auto d = placedDisplacement(map, {glm::dvec2(1.0), -offset});
    const DensityField target = sampleTarget(map.columns(), map.rows(), aspect, [&](glm::dvec2 p) { return densityAt(map, p - offset); });
    return composeOrBuild(map.columns(), map.rows(), d, target, aspect);
}

ComposeResult scaleMap(const SamplingMap& map, double factor, glm::dvec2 centre, double aspect) {
    if (!(factor > 0.0) || !std::isfinite(factor)) {
        throw Error(ErrorCode::InvalidArgument, "scaleMap: factor " + numberText(factor) + " is not finite and > 0");
    }
    if (!std::isfinite(centre.x) || !std::isfinite(centre.y)) {
        throw Error(ErrorCode::InvalidArgument, "scaleMap: centre (" + numberText(centre.x) + ", " + numberText(centre.y) + ") is not finite");
    }
    checkAspect(aspect, "scaleMap");
    // q = centre + (p - centre) / factor
    const auto d = placedDisplacement(map, {glm::dvec2(1.0 / factor), centre - centre / factor});
    const DensityField target =
        sampleTarget(map.columns(), map.rows(), aspect, [&](glm::dvec2 p) { return densityAt(map, centre + (p - centre) / factor); });
    return composeOrBuild(map.columns(), map.rows(), d, target, aspect);
}

ComposeResult addMaps(std::span<const SamplingMap> maps, int columns, int rows, std::span<const double> weights, double aspect) {
    checkGrid(columns, rows, "addMaps");
    checkAspect(aspect, "addMaps");
    if (!weights.empty() && weights.size() != maps.size()) {
        throw Error(ErrorCode::InvalidArgument, "addMaps: " + std::to_string(weights.size()) + " weights for " +
                                                    std::to_string(maps.size()) + " maps");
    }
    for (double w : weights) {
        if (!std::isfinite(w)) throw Error(ErrorCode::InvalidArgument, "addMaps: weight " + numberText(w) + " is not finite");
    }
    const auto d = resampleField(columns, rows, [&](glm::dvec2 p) {
        glm::dvec2 sum(0.0);
        for (std::size_t m = 0; m < maps.size(); ++m) sum += (weights.empty() ? 1.0 : weights[m]) * displacementAt(maps[m], p);
        return sum;
    });
    // Each input's density relative to its context (its lowest, sampled where the target is).
    std::vector<double> context(maps.size(), HUGE_VAL);
    sampleTarget(columns, rows, aspect, [&](glm::dvec2 p) {
        for (std::size_t m = 0; m < maps.size(); ++m) context[m] = std::min(context[m], maps[m].density(p));
        return 1.0;
    });
    const DensityField target = sampleTarget(columns, rows, aspect, [&](glm::dvec2 p) {
        double density = 1.0;
        for (std::size_t m = 0; m < maps.size(); ++m) density += (weights.empty() ? 1.0 : weights[m]) * (maps[m].density(p) / context[m] - 1.0);
        return std::max(density, kComposeFloor);
    });
    return composeOrBuild(columns, rows, d, target, aspect);
}

}  // namespace conus::codec
