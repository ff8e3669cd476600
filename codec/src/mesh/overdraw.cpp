#include "conus/codec/mesh/overdraw.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

#include "conus/core/error.h"
#include "conus/core/limits.h"

namespace conus::codec {
namespace {

// The directions looked along, one of each pair +-d: the axes, the face diagonals and the body
// diagonals (any direction lies within 35 degrees of one of them).
std::array<glm::dvec3, 13> directions() {
    std::array<glm::dvec3, 13> d{};
    std::size_t n = 0;
    for (int x = -1; x <= 1; ++x)
        for (int y = -1; y <= 1; ++y)
            for (int z = -1; z <= 1; ++z)
                if (x > 0 || (x == 0 && (y > 0 || (y == 0 && z > 0)))) d[n++] = glm::normalize(glm::dvec3(x, y, z));
    return d;
}

}  // namespace

namespace {

// The surfaces one grid cell holds: their area inside it, and the box around their parts in it.
struct Cell {
    double area = 0;
    double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

}  // namespace

double meshOverdraw(const Mesh& mesh) {
    const std::size_t triangles = mesh.indices.size() / 3;
    if (mesh.positions.empty() || triangles == 0) return 0;
    const AxisBox box = boundsOf(mesh);
    // Level L cuts the shadow's longer side into 2^L cells: one dense grid per level, reused for
    // each direction.
    std::vector<std::vector<Cell>> levels(kMeshOverdrawLevels);
    for (int l = 0; l < kMeshOverdrawLevels; ++l) levels[std::size_t(l)].resize(std::size_t((1 << l) + 2) * std::size_t((1 << l) + 2));
    double most = 0;
    for (const glm::dvec3& d : directions()) {
        // An orthonormal frame (u, v) across d, and the box's shadow on it.
        const glm::dvec3 u = glm::normalize(glm::cross(d, std::abs(d.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0)));
        const glm::dvec3 v = glm::cross(d, u);
        glm::dvec2 lo(INFINITY), hi(-INFINITY);
        for (int k = 0; k < 8; ++k) {
            const glm::dvec3 c = box.corner(k);
            lo = glm::min(lo, glm::dvec2(glm::dot(c, u), glm::dot(c, v)));
            hi = glm::max(hi, glm::dvec2(glm::dot(c, u), glm::dot(c, v)));
        }
        const double side = std::max(hi.x - lo.x, hi.y - lo.y);
        if (!(hi.x - lo.x > 0 && hi.y - lo.y > 0) || !std::isfinite(side)) continue;  // seen edge-on: no area
        for (auto& grid : levels) std::fill(grid.begin(), grid.end(), Cell{});
        for (std::size_t t = 0; t < triangles; ++t) {
            glm::dvec2 p[3];
            for (int k = 0; k < 3; ++k) {
                const glm::dvec3 q(mesh.positions[mesh.indices[3 * t + std::size_t(k)]]);
                p[k] = glm::dvec2(glm::dot(q, u), glm::dot(q, v)) - lo;
            }
            const glm::dvec2 e1 = p[1] - p[0], e2 = p[2] - p[0];
            const double area = 0.5 * std::abs(e1.x * e2.y - e1.y * e2.x);
            const glm::dvec2 low = glm::min(p[0], glm::min(p[1], p[2])), high = glm::max(p[0], glm::max(p[1], p[2]));
            const double boxArea = (high.x - low.x) * (high.y - low.y);
            if (!(area > 0) || !(boxArea > 0)) continue;
            // The finest level whose cells are at least the triangle's size: its box meets at
            // most 2 x 2 of them, which share its area as they share the box.
            const double size = std::max(high.x - low.x, high.y - low.y);
            const int level = std::clamp(int(std::floor(std::log2(side / size))), 0, kMeshOverdrawLevels - 1);
            const int n = (1 << level) + 1;
            const double cell = std::ldexp(side, -level);
            const auto index = [&](double a) { return std::clamp(int(std::floor(a / cell)), 0, n); };
            std::vector<Cell>& grid = levels[std::size_t(level)];
            for (int y = index(low.y); y <= index(high.y); ++y)
                for (int x = index(low.x); x <= index(high.x); ++x) {
                    const double x0 = std::max(low.x, x * cell), x1 = std::min(high.x, (x + 1) * cell);
                    const double y0 = std::max(low.y, y * cell), y1 = std::min(high.y, (y + 1) * cell);
                    if (!(x1 > x0 && y1 > y0)) continue;
                    Cell& c = grid[std::size_t(y) * std::size_t(n + 1) + std::size_t(x)];
                    if (c.area == 0) c = {0, x0, y0, x1, y1};
                    c.area += area * (x1 - x0) * (y1 - y0) / boxArea;
                    c.x0 = std::min(c.x0, x0), c.y0 = std::min(c.y0, y0);
                    c.x1 = std::max(c.x1, x1), c.y1 = std::max(c.y1, y1);
                }
        }
        // Each cell: its surfaces' area over the box they fill in it, the mean number of them
        // over that box.
        for (const auto& grid : levels)
            for (const Cell& c : grid)
                if (c.area > 0) most = std::max(most, c.area / ((c.x1 - c.x0) * (c.y1 - c.y0)));
    }
    return most;
}

void checkMeshOverdraw(const Mesh& mesh, const std::string& what) {
    const double overdraw = meshOverdraw(mesh);
    if (overdraw > kMaxMeshOverlap) {
        char shown[32];
        std::snprintf(shown, sizeof shown, "%.0f", overdraw);
        throw Error(ErrorCode::LimitExceeded,
                    what + ": the mesh's triangles overlap about " + std::string(shown) +
                        " deep where they are densest, and a rasterizer shades every one of them at each pixel "
                        "they cover: overlapping copies of its triangles? (limit meshOverlap, " +
                        std::to_string(kMaxMeshOverlap) + ")");
    }
}

}  // namespace conus::codec
