#include "conus/core/map_rules.h"

namespace conus::map_rules {

bool isValidGrid(const GridView& g) {
    if (!sidesInRange(g.columns, g.rows) || !g.uv) return false;
    for (int j = 0; j < g.rows; ++j)
        for (int i = 0; i < g.columns; ++i)
            if (!nodeInside(g, i, j) || !nodeOnItsEdge(g, i, j)) return false;  // NaN is not inside
    for (int j = 0; j + 1 < g.rows; ++j)
        for (int i = 0; i + 1 < g.columns; ++i)
            if (firstBadCorner(g, i, j) >= 0) return false;
    return true;
}

bool isValidGrid(int columns, int rows, std::span<const float> uv) {
    if (!sidesInRange(columns, rows) || uv.size() != std::size_t{2} * std::size_t(columns) * std::size_t(rows)) return false;
    return isValidGrid(GridView{columns, rows, uv.data()});
}

bool isValidGrid(int columns, int rows, std::span<const glm::vec2> nodes) {
    if (nodes.empty()) return false;
    return isValidGrid(columns, rows, std::span<const float>(&nodes.front().x, 2 * nodes.size()));
}

}  // namespace conus::map_rules
