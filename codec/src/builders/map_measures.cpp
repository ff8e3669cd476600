#include "conus/codec/builders/map_measures.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/type_ptr.hpp>

namespace conus::codec {

double cellDensity(const map_rules::GridView& g, int i, int j) {
    const double ex = g.u(i + 1, j + 1) - g.u(i, j), ey = g.v(i + 1, j + 1) - g.v(i, j);
    const double fx = g.u(i, j + 1) - g.u(i + 1, j), fy = g.v(i, j + 1) - g.v(i + 1, j);
    return 0.5 * std::abs(ex * fy - ey * fx) * double(g.columns - 1) * (g.rows - 1);
}

namespace {
map_rules::GridView viewOf(const SamplingMap& map) {
    return {map.columns(), map.rows(), glm::value_ptr(map.nodes().front())};
}
}  // namespace

glm::dmat2 cellJacobianAt(const SamplingMap& map, glm::dvec2 p) {
    const int n = map.columns(), m = map.rows();
    const int i = std::clamp(static_cast<int>(p.x * (n - 1)), 0, n - 2), j = std::clamp(static_cast<int>(p.y * (m - 1)), 0, m - 2);
    return map.jacobian({(i + 0.5) / (n - 1), (j + 0.5) / (m - 1)});
}

double cellDensityAt(const SamplingMap& map, glm::dvec2 p) {
    const int n = map.columns(), m = map.rows();
    const int i = std::clamp(static_cast<int>(p.x * (n - 1)), 0, n - 2), j = std::clamp(static_cast<int>(p.y * (m - 1)), 0, m - 2);
    return cellDensity(viewOf(map), i, j);
}

double anisotropy(const glm::dmat2& jacobian, double aspect) {
    // Pixel units: x = u * W, y = v * H, in the source and (same aspect) in the CoNUS image, so
    // J_px = D J D^-1 with D = diag(aspect, 1) up to a common scale that cancels in the ratio.
    const double a = jacobian[0][0], b = jacobian[1][0] * aspect;  // glm is column-major: [column][row]
    const double c = jacobian[0][1] / aspect, d = jacobian[1][1];
    // Singular values of [[a, b], [c, d]] from the invariants of J^T J.
    const double sumSquares = a * a + b * b + c * c + d * d;
    const double det = std::abs(a * d - b * c);
    const double root = std::sqrt(std::max(0.0, sumSquares * sumSquares - 4.0 * det * det));
    const double large = std::sqrt(0.5 * (sumSquares + root));
    const double small = det / std::max(large, 1e-300);
    return small > 0.0 ? large / small : HUGE_VAL;
}

MapMeasures measureMap(const SamplingMap& map, double aspect) {
    const int n = map.columns(), m = map.rows();
    const map_rules::GridView grid = viewOf(map);
    MapMeasures out;
    out.minCellDensity = HUGE_VAL;
    out.maxCellDensity = 0.0;
    out.maxAnisotropy = 1.0;
    for (int j = 0; j + 1 < m; ++j)
        for (int i = 0; i + 1 < n; ++i) {
            const double density = cellDensity(grid, i, j);
            out.minCellDensity = std::min(out.minCellDensity, density);
            out.maxCellDensity = std::max(out.maxCellDensity, density);
            // The cell's mean Jacobian (at a corner of a sheared cell it can be far larger; that is
            // one point, not a pixel's footprint).
            const glm::dvec2 p{(i + 0.5) / (n - 1), (j + 0.5) / (m - 1)};
            const double ratio = anisotropy(cellJacobianAt(map, p), aspect);
            if (ratio > out.maxAnisotropy) {
                out.maxAnisotropy = ratio;
                out.mostAnisotropic = p;
            }
        }
    return out;
}

}  // namespace conus::codec
