#include "conus/core/map_rules.h"

namespace conus::map_rules {

bool isValidGrid(const GridView& g) {
    if (g.columns < 2 || g.rows < 2 || !g.uv) return false;
    for (int j = 0; j < g.rows; ++j)
        for (int i = 0; i < g.columns; ++i)
            if (!nodeInside(g, i, j) || !nodeOnItsEdge(g, i, j)) return false;  // NaN is not inside
    for (int j = 0; j + 1 < g.rows; ++j)
        for (int i = 0; i + 1 < g.columns; ++i)
            if (firstBadCorner(g, i, j) >= 0) return false;
    return true;
}

}  // namespace conus::map_rules
