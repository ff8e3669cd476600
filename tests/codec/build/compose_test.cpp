// Composition: translate, scale, add; the global scale-down rule keeps every result valid.
#include "conus/codec/build/compose.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "conus/codec/build/foci.h"
#include "conus/core/map_rules.h"
#include "conus/format/container.h"
#include "conus/core/error.h"

namespace conus::codec {
namespace {

void expectValid(const SamplingMap& map) {
    const format::ValidationReport report = format::validateGrid(map.toGrid());
    EXPECT_TRUE(report.ok()) << report.str();
}

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
    for (glm::dvec2 p : {glm::dvec2(0.2, 0.25), glm::dvec2(0.23, 0.27)}) {
        EXPECT_NEAR(glm::length(sum.map.distort(p) - a.distort(p)), 0.0, 0.03);
    }
}

TEST(Compose, FoldingSumIsScaledDownAndValid) {
    const SamplingMap a = focusMap(0.5, 0.5, 0.15, 6);
    const std::vector<SamplingMap> maps{a, a, a};
    const ComposeResult sum = addMaps(maps, map_rules::kDefaultSide, map_rules::kDefaultSide);
    expectValid(sum.map);
    EXPECT_LT(sum.scale, 1.0);
    EXPECT_GT(sum.scale, 0.0);
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

TEST(Compose, ValidityCheckAgreesWithValidator) {
    std::vector<glm::vec2> nodes = SamplingMap::identity(4, 4).nodes();
    EXPECT_TRUE(isValidGrid(4, 4, nodes));
    nodes[5] = nodes[6];  // collapse an edge
    EXPECT_FALSE(isValidGrid(4, 4, nodes));
    nodes = SamplingMap::identity(4, 4).nodes();
    nodes[1].y = 1e-3f;  // top node off its edge
    EXPECT_FALSE(isValidGrid(4, 4, nodes));
    EXPECT_FALSE(isValidGrid(4, 5, nodes));
}

}  // namespace
}  // namespace conus::codec
