// Composition: translate, scale, add; the global scale-down rule keeps every result valid.
#include "conus/codec/builders/compose.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <vector>

#include "conus/codec/builders/foci.h"
#include "conus/codec/builders/map_measures.h"
#include "conus/core/map_rules.h"
#include "conus/format/container.h"
#include "conus/core/error.h"
#include "codec/builders/valid_map.h"

namespace conus::codec {
namespace {

using test::expectValid;

SamplingMap focusMap(double u, double v, double r, double k, int side = map_rules::kDefaultSide) {
    const std::vector<Focus> foci{{u, v, r, k}};
    FociOptions o;
    o.columns = o.rows = side;
    return buildFociMap(foci, o);
}

TEST(Compose, AddIdentityGivesSameMap) {
    const SamplingMap a = focusMap(0.4, 0.6, 0.1, 3);
    const std::vector<SamplingMap> maps{a, SamplingMap::identity(9, 5)};
    const ComposeResult sum = addMaps(maps, a.columns(), a.rows());
    EXPECT_EQ(sum.scale, 1.0);
    for (std::size_t k = 0; k < a.nodes().size(); ++k) {
        EXPECT_NEAR(sum.map.nodes()[k].x, a.nodes()[k].x, 1e-6);
        EXPECT_NEAR(sum.map.nodes()[k].y, a.nodes()[k].y, 1e-6);
    }
    EXPECT_EQ(addMaps({}, 5, 5).map.nodes(), SamplingMap::identity(5, 5).nodes());
}

TEST(Compose, TwoFociFarApartKeepTheirMagnification) {
    const SamplingMap a = focusMap(0.2, 0.25, 0.06, 2.5), b = focusMap(0.8, 0.75, 0.06, 2.5);
    const std::vector<SamplingMap> maps{a, b};
    const ComposeResult sum = addMaps(maps, map_rules::kDefaultSide, map_rules::kDefaultSide);
    expectValid(sum.map);
    EXPECT_EQ(sum.scale, 1.0);
    const double da = a.density({0.2, 0.25}), db = b.density({0.8, 0.75});
    EXPECT_GT(da, 3.0);
    EXPECT_NEAR(sum.map.density({0.2, 0.25}) / da, 1.0, 0.25);
    EXPECT_NEAR(sum.map.density({0.8, 0.75}) / db, 1.0, 0.25);
    // Each focus's neighbourhood keeps the map near that focus.
    // (Rebuilt from the composed density where the plain sum passes the anisotropy bound, so a
    // little further than the sum's 0.03.)
    for (glm::dvec2 p : {glm::dvec2(0.2, 0.25), glm::dvec2(0.23, 0.27)}) {
        EXPECT_NEAR(glm::length(sum.map.distort(p) - a.distort(p)), 0.0, 0.045);
    }
}

TEST(Compose, FoldingSumIsBuiltFromItsDensityAndValid) {
    // Three times a k = 6 focus: the plain sum folds; scaling it down until it does not left bands
    // of almost no samples, so the map is built from the composed density instead (k^2 three
    // times over, relative to the context), under the anisotropy bound.
    const SamplingMap a = focusMap(0.5, 0.5, 0.15, 6);
    const std::vector<SamplingMap> maps{a, a, a};
    const ComposeResult sum = addMaps(maps, map_rules::kDefaultSide, map_rules::kDefaultSide);
    expectValid(sum.map);
    EXPECT_TRUE(sum.rebuilt);
    EXPECT_EQ(sum.scale, 1.0);
    const MapMeasures m = measureMap(sum.map);
    EXPECT_LE(m.maxAnisotropy, map_rules::kMaxAnisotropy);
    EXPECT_GE(sum.report.lowestRatio, 0.5);
    EXPECT_GT(sum.map.density({0.5, 0.5}) / m.minCellDensity, a.density({0.5, 0.5}) / measureMap(a).minCellDensity);
    // The displacement rule alone still scales a fold away.
    std::vector<glm::dvec2> displacement(std::size_t(17) * 17, glm::dvec2(0.0));
    displacement[std::size_t(8) * 17 + 8] = {0.2, 0.0};  // past its neighbour: a fold
    const ComposeResult scaled = fitDisplacement(17, 17, displacement);
    expectValid(scaled.map);
    EXPECT_LT(scaled.scale, 1.0);
    EXPECT_GT(scaled.scale, 0.0);
    // Weights: a negative one undoes a positive one.
    const std::vector<double> weights{1.0, -1.0, 0.0};
    const ComposeResult none = addMaps(maps, 17, 17, weights);
    for (std::size_t k = 0; k < none.map.nodes().size(); ++k) {
        EXPECT_NEAR(none.map.nodes()[k].x, SamplingMap::identity(17, 17).nodes()[k].x, 1e-6);
    }
    EXPECT_THROW(addMaps(maps, 17, 17, std::vector<double>{1.0}), Error);
    EXPECT_THROW(addMaps(maps, 1, 17), Error);
}

// A compact radial bump: p + a (p - c) (1 - |p - c|^2 / R^2)^2 inside radius R, identity outside;
// density (1 + a)^2 at the centre, injective for a < 1.25.
SamplingMap bumpMap(glm::dvec2 c, double R, double a, int side = 129) {
    std::vector<glm::vec2> nodes;
    for (int j = 0; j < side; ++j)
        for (int i = 0; i < side; ++i) {
            const glm::dvec2 p(double(i) / (side - 1), double(j) / (side - 1));
            const double s2 = glm::dot(p - c, p - c) / (R * R);
            const double w = s2 < 1.0 ? (1.0 - s2) * (1.0 - s2) : 0.0;
            const glm::dvec2 q = p + a * w * (p - c);
            nodes.emplace_back(float(q.x), float(q.y));
        }
    return SamplingMap(side, side, std::move(nodes));
}

TEST(Compose, TranslateMovesThePattern) {
    const SamplingMap a = bumpMap({0.4, 0.4}, 0.15, 0.6);
    ASSERT_NEAR(a.density({0.4, 0.4}), 2.56, 0.05);
    const ComposeResult moved = translateMap(a, {0.2, 0.1});
    expectValid(moved.map);
    EXPECT_EQ(moved.scale, 1.0);
    EXPECT_NEAR(moved.map.density({0.6, 0.5}), a.density({0.4, 0.4}), 0.05);
    EXPECT_NEAR(moved.map.density({0.4, 0.4}), 1.0, 1e-3);
    // Moved far away: nothing left but the identity.
    const ComposeResult gone = translateMap(a, {2.0, 0.0});
    EXPECT_EQ(gone.map.nodes(), SamplingMap::identity(a.columns(), a.rows()).nodes());
    // Patterns cut by the edge (a bump, a focus map whose displacement reaches every edge) may
    // fold where the cut is; the result is scaled down and valid.
    const SamplingMap focus = focusMap(0.4, 0.4, 0.08, 3);
    for (glm::dvec2 offset : {glm::dvec2(0.55, 0.0), glm::dvec2(-0.4, 0.5), glm::dvec2(0.3, -0.37)}) {
        const ComposeResult r = translateMap(a, offset);
        expectValid(r.map);
        const ComposeResult f = translateMap(focus, offset);
        expectValid(f.map);
        EXPECT_GT(f.scale, 0.0);
    }
    EXPECT_THROW(translateMap(a, {std::nan(""), 0.0}), Error);
}

TEST(Compose, ScaleKeepsDensityPatternLarger) {
    const SamplingMap a = bumpMap({0.5, 0.5}, 0.1, 0.6);
    const ComposeResult big = scaleMap(a, 2.0, {0.5, 0.5});
    expectValid(big.map);
    EXPECT_EQ(big.scale, 1.0);
    // The same density pattern, twice as large.
    EXPECT_NEAR(big.map.density({0.5, 0.5}), a.density({0.5, 0.5}), 0.05);
    EXPECT_NEAR(big.map.density({0.5 + 0.1, 0.5}), a.density({0.5 + 0.05, 0.5}), 0.05);
    EXPECT_NEAR(big.map.density({0.5 + 0.19, 0.5}), a.density({0.5 + 0.095, 0.5}), 0.05);
    const ComposeResult small = scaleMap(a, 0.5, {0.25, 0.25});
    expectValid(small.map);
    EXPECT_THROW(scaleMap(a, 0.0), Error);
    // A focus map's displacement reaches the edges: scaled up it is cut there, scaled down, valid.
    const ComposeResult cut = scaleMap(focusMap(0.5, 0.5, 0.2, 8), 3.0, {0.1, 0.9});
    expectValid(cut.map);
    EXPECT_GT(cut.scale, 0.0);
}

// The largest jump of log cell density between neighbouring cells (both within `near` of the
// point set `on`, when given): a seam (a density step where a moved or scaled pattern ends) or a
// slit (one row of cells squeezed at an edge) makes it large.
double largestLogDensityJump(const SamplingMap& map, const std::function<bool(glm::dvec2)>& on = {}) {
    const map_rules::GridView grid{map.columns(), map.rows(), &map.nodes().front().x};
    const int n = map.columns() - 1, m = map.rows() - 1;
    const auto centre = [&](int i, int j) { return glm::dvec2((i + 0.5) / n, (j + 0.5) / m); };
    double worst = 0;
    for (int j = 0; j < m; ++j)
        for (int i = 0; i < n; ++i) {
            if (on && !on(centre(i, j))) continue;
            const double c = std::log(cellDensity(grid, i, j));
            if (i + 1 < n && (!on || on(centre(i + 1, j))))
                worst = std::max(worst, std::abs(std::log(cellDensity(grid, i + 1, j)) - c));
            if (j + 1 < m && (!on || on(centre(i, j + 1))))
                worst = std::max(worst, std::abs(std::log(cellDensity(grid, i, j + 1)) - c));
        }
    return worst;
}

TEST(Compose, ScaledAndMovedPatternsHaveNoSeam) {
    // `map compose --scale` once left a square seam and a dark slit. A focus map's
    // displacement reaches every edge (context is squeezed everywhere), so shrinking or moving it
    // puts its edge inside the frame (a seam), and enlarging or moving it cuts it at the frame's
    // edge (a slit: the old code folded there and scaled the whole pattern down to 0.1-0.2).
    const SamplingMap focus = focusMap(0.45, 0.55, 0.1, 2);
    const double own = largestLogDensityJump(focus);
    struct Case {
        const char* what;
        ComposeResult result;
        double factor;
        glm::dvec2 low, high;  // the pattern's square in the output
    };
    const Case cases[] = {
        {"scale 0.5 about the middle", scaleMap(focus, 0.5, {0.5, 0.5}), 0.5, {0.25, 0.25}, {0.75, 0.75}},
        {"scale 0.6 about (0.3, 0.7)", scaleMap(focus, 0.6, {0.3, 0.7}), 0.6, {0.12, 0.28}, {0.72, 0.88}},
        {"scale 2 about the focus", scaleMap(focus, 2.0, {0.45, 0.55}), 2.0, {-0.45, -0.55}, {1.55, 1.45}},
        {"translate (0.3, -0.2)", translateMap(focus, {0.3, -0.2}), 1.0, {0.3, -0.2}, {1.3, 0.8}},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.what);
        expectValid(c.result.map);
        EXPECT_EQ(c.result.scale, 1.0);  // no fold to scale away
        // Everywhere: no steeper than the pattern's own steepest jump, enlarged by the factor (its
        // detail spans fewer cells), with 25% for the grid's fit and the fades.
        const double jump = largestLogDensityJump(c.result.map);
        EXPECT_LE(jump, 1.25 * own * std::max(1.0, 1.0 / c.factor)) << "own " << own;
        // Across the pattern's edges inside the frame (cells within 1.5 cells of them): a seam is
        // a jump from the pattern's edge density to 1 in one cell (the old code: 0.22-0.44 here);
        // faded, it spreads over a band (0.04-0.07).
        const double cell = 1.0 / (focus.columns() - 1);
        const auto nearEdge = [&](glm::dvec2 p) {
            for (int axis = 0; axis < 2; ++axis)
                for (double edge : {c.low[axis], c.high[axis]})
                    if (edge > 0 && edge < 1 && std::abs(p[axis] - edge) < 1.5 * cell) return true;
            return false;
        };
        const double seam = largestLogDensityJump(c.result.map, nearEdge);
        EXPECT_LE(seam, 0.1);
        std::printf("%s: largest log density jump %.3f (the pattern alone %.3f), across its edges %.3f\n", c.what, jump,
                    own, seam);
        // The fades keep the pattern: its focus is still magnified about as much, less where the
        // enlarged pattern fills the frame and the fades at its edges reach the focus.
        const glm::dvec2 at = c.low + (c.high - c.low) * glm::dvec2(0.45, 0.55);
        EXPECT_GT(c.result.map.density(at), (c.factor > 1 ? 0.45 : 0.6) * focus.density({0.45, 0.55})) << "at " << at.x << "," << at.y;
    }
}

TEST(Compose, ValidityCheckAgreesWithValidator) {
    std::vector<glm::vec2> nodes = SamplingMap::identity(4, 4).nodes();
    EXPECT_TRUE(map_rules::isValidGrid(4, 4, nodes));
    nodes[5] = nodes[6];  // collapse an edge
    EXPECT_FALSE(map_rules::isValidGrid(4, 4, nodes));
    nodes = SamplingMap::identity(4, 4).nodes();
    nodes[1].y = 1e-3f;  // top node off its edge
    EXPECT_FALSE(map_rules::isValidGrid(4, 4, nodes));
    EXPECT_FALSE(map_rules::isValidGrid(4, 5, nodes));
}

}  // namespace
}  // namespace conus::codec
