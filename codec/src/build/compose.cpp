// Composition of sampling maps through their displacement fields, with one injectivity rule
// (a global factor on all displacements, found by bisection).
#include "conus/codec/build/compose.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include <glm/gtc/type_ptr.hpp>

#include "conus/core/error.h"
#include "conus/core/map_rules.h"

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

}  // namespace

bool isValidGrid(int columns, int rows, std::span<const glm::vec2> nodes) {
    if (columns < 2 || rows < 2 || nodes.size() != std::size_t(columns) * rows) return false;
    return map_rules::isValidGrid({columns, rows, glm::value_ptr(nodes.front())});
}

ComposeResult fitDisplacement(int columns, int rows, std::span<const glm::dvec2> displacement) {
    checkGrid(columns, rows, "fitDisplacement");
    if (displacement.size() != std::size_t(columns) * rows) {
        throw Error(ErrorCode::InvalidArgument, "fitDisplacement: " + std::to_string(displacement.size()) +
                                                    " displacement vectors for a " + std::to_string(columns) + "x" +
                                                    std::to_string(rows) + " grid");
    }
    std::vector<glm::vec2> nodes;
    placeNodes(columns, rows, displacement, 1.0, nodes);
    if (isValidGrid(columns, rows, nodes)) return {SamplingMap(columns, rows, std::move(nodes)), 1.0};
    // Invariant: lo is valid (0 is the identity), hi is not.
    double lo = 0.0, hi = 1.0;
    for (int it = 0; it < kBisectionSteps; ++it) {
        const double mid = 0.5 * (lo + hi);
        placeNodes(columns, rows, displacement, mid, nodes);
        (isValidGrid(columns, rows, nodes) ? lo : hi) = mid;
    }
    placeNodes(columns, rows, displacement, lo, nodes);
    return {SamplingMap(columns, rows, std::move(nodes)), lo};
}

ComposeResult translateMap(const SamplingMap& map, glm::dvec2 offset) {
    if (!std::isfinite(offset.x) || !std::isfinite(offset.y)) {
        throw Error(ErrorCode::InvalidArgument, "translateMap: offset (" + numberText(offset.x) + ", " + numberText(offset.y) + ") is not finite");
    }
    const auto d = resampleField(map.columns(), map.rows(), [&](glm::dvec2 p) { return displacementAt(map, p - offset); });
    return fitDisplacement(map.columns(), map.rows(), d);
}

ComposeResult scaleMap(const SamplingMap& map, double factor, glm::dvec2 centre) {
    if (!(factor > 0.0) || !std::isfinite(factor)) {
        throw Error(ErrorCode::InvalidArgument, "scaleMap: factor " + numberText(factor) + " is not finite and > 0");
    }
    if (!std::isfinite(centre.x) || !std::isfinite(centre.y)) {
        throw Error(ErrorCode::InvalidArgument, "scaleMap: centre (" + numberText(centre.x) + ", " + numberText(centre.y) + ") is not finite");
    }
    const auto d = resampleField(map.columns(), map.rows(), [&](glm::dvec2 p) {
        return factor * displacementAt(map, centre + (p - centre) / factor);
    });
    return fitDisplacement(map.columns(), map.rows(), d);
}

ComposeResult addMaps(std::span<const SamplingMap> maps, int columns, int rows, std::span<const double> weights) {
    checkGrid(columns, rows, "addMaps");
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
    return fitDisplacement(columns, rows, d);
}

}  // namespace conus::codec
