// Closed-form per-frame focus maps: the lens profile, magnification k at isolated foci, valid maps
// for crowded and bordering foci, the identity without foci, continuity in the focus parameters.
#include "conus/codec/builders/frame_foci.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "conus/codec/builders/map_measures.h"
#include "conus/core/error.h"
#include "conus/core/map_rules.h"
#include "conus/format/container.h"
#include "codec/builders/valid_map.h"

namespace conus::codec {
namespace {

using test::expectValid;

FociOptions grid(int side, double aspect) {
    FociOptions o;
    o.columns = o.rows = side;
    o.aspect = aspect;
    return o;
}

// The linear magnification of `map` at undistorted p: the square root of its Jacobian's determinant.
double magnificationAt(const SamplingMap& map, glm::dvec2 p) { return std::sqrt(glm::determinant(map.jacobian(p))); }

double largestMove(const SamplingMap& a, const SamplingMap& b) {
    double largest = 0;
    for (std::size_t n = 0; n < a.nodes().size(); ++n)
        largest = std::max(largest, static_cast<double>(glm::distance(a.nodes()[n], b.nodes()[n])));
    return largest;
}

TEST(FrameFoci, LensProfileIsAMonotoneLensJoiningTheIdentity) {
    const double h = 1e-6;
    for (double k : {1.0, 1.5, 2.0, 4.0, 9.0, 23.0, map_rules::kMaxMagnification}) {
        EXPECT_EQ(lensProfile(0.0, k), 0.0);
        EXPECT_NEAR(lensProfile(h, k) / h, k, 1e-3 * k) << k;                       // slope k at the centre
        EXPECT_NEAR(lensProfile(1.0 - h, k), 1.0 - h, 1e-9) << k;                  // meets the identity
        EXPECT_NEAR((1.0 - lensProfile(1.0 - h, k)) / h, 1.0, 1e-3) << k;          // without a kink
        EXPECT_EQ(lensProfile(1.5, k), 1.5);
        double previous = 0, smallestSlope = 1e9;
        for (int i = 1; i <= 4000; ++i) {
            const double x = i / 4000.0, value = lensProfile(x, k);
            smallestSlope = std::min(smallestSlope, (value - previous) * 4000.0);
            EXPECT_GE(value, x - 1e-12);  // a lens pushes outward
            previous = value;
        }
        EXPECT_GT(smallestSlope, 0.2) << k;
    }
}

TEST(FrameFoci, IsolatedFocusMagnifiesByKAtItsCentre) {
    struct Case {
        Focus focus;
        int side;
        double aspect;
    };
    // Grids fine enough that the magnified core (undistorted radius ~ r / (k - 1)) spans cells, and
    // lenses inside the frame (a lens reaching past an edge is scaled down by the fold guard).
    const Case cases[] = {{{0.5, 0.5, 0.15, 4.0}, map_rules::kDefaultSide, 1.0},
                          {{0.43, 0.57, 0.08, 3.0}, map_rules::kDefaultSide, 16.0 / 9.0},
                          {{0.61, 0.38, 0.1, 8.0}, 257, 0.75},
                          {{0.5, 0.5, 0.08, 2.0}, map_rules::kDefaultSide, 1.5}};
    for (const Case& c : cases) {
        const Focus foci[] = {c.focus};
        // The lens of k = 8 alone stretches its ring to 7.4, past the default bound (which would
        // scale it, AnisotropyStaysUnderTheBound): a looser one leaves the lens whole here.
        FociOptions options = grid(c.side, c.aspect);
        options.maxAnisotropy = 12.0;
        const SamplingMap map = buildFrameFociMap(foci, options);
        expectValid(map);
        const double reached = magnificationAt(map, {c.focus.u, c.focus.v});
        EXPECT_NEAR(reached, c.focus.k, 0.12 * c.focus.k) << c.focus.k;
        // The lens stays where it was put (up to Eq. 1's bilinear between nodes: a small share of a
        // cell) and magnifies isotropically.
        EXPECT_LT(glm::distance(map.distort({c.focus.u, c.focus.v}), glm::dvec2(c.focus.u, c.focus.v)),
                  0.05 / (c.side - 1));
        const glm::dmat2 j = map.jacobian({c.focus.u, c.focus.v});
        EXPECT_NEAR(j[0][0], j[1][1], 0.1 * c.focus.k);
        // Beyond the falloff radius the map is the identity; inside, each node moved radially by the
        // lens profile.
        const double radius = kFalloffRadii * c.focus.r;
        int inside = 0;
        for (int jj = 0; jj < map.rows(); ++jj)
            for (int i = 0; i < map.columns(); ++i) {
                const glm::dvec2 p(i / double(map.columns() - 1), jj / double(map.rows() - 1));
                const glm::dvec2 offset((p.x - c.focus.u), (p.y - c.focus.v) / c.aspect);  // widths
                const double reach = glm::length(offset) / radius;
                const glm::dvec2 node = map.node(i, jj);
                const glm::dvec2 moved((node.x - c.focus.u), (node.y - c.focus.v) / c.aspect);
                if (reach >= 1.0) {
                    EXPECT_LT(glm::distance(node, p), 1e-6);
                } else if (reach > 0) {
                    ++inside;
                    EXPECT_NEAR(glm::length(moved) / radius, lensProfile(reach, c.focus.k), 1e-5);
                    EXPECT_NEAR(offset.x * moved.y - offset.y * moved.x, 0.0, 1e-6);  // radial
                }
            }
        EXPECT_GT(inside, 20);
    }
}

TEST(FrameFoci, EightOverlappingFociGiveAValidMap) {
    std::vector<Focus> foci;
    for (int i = 0; i < 8; ++i)
        foci.push_back({0.35 + 0.04 * i, 0.4 + 0.025 * ((i * 3) % 8), 0.09 + 0.01 * (i % 3), 2.0 + i});
    for (double aspect : {1.0, 16.0 / 9.0, 0.6}) {
        const SamplingMap map = buildFrameFociMap(foci, grid(map_rules::kDefaultSide, aspect));
        expectValid(map);
        // The guard scaled the sum down, but every focus is still magnified.
        for (const Focus& f : foci) EXPECT_GT(magnificationAt(map, {f.u, f.v}), 1.2) << aspect;
    }
}

TEST(FrameFoci, AnisotropyStaysUnderTheBound) {
    // Lenses cut by the frame's edge, or overlapping, stretch cells: unscaled, these measured 10 to
    // 18. The sum is scaled to the bound.
    const std::vector<std::vector<Focus>> cases = {{{0.5, 0.5, 0.2, 4.0}},
                                                   {{0.3, 0.4, 0.1, 4.0}, {0.4, 0.45, 0.1, 4.0}},
                                                   {{0.3, 0.4, 0.1, 8.0}, {0.4, 0.45, 0.1, 8.0}},
                                                   {{0.05, 0.9, 0.12, 6.0}}};
    for (const auto& foci : cases) {
        for (double aspect : {1.0, 16.0 / 9.0}) {
            const SamplingMap map = buildFrameFociMap(foci, grid(map_rules::kDefaultSide, aspect));
            expectValid(map);
            EXPECT_LE(measureMap(map, aspect).maxAnisotropy, map_rules::kMaxAnisotropy) << foci.size() << " foci, aspect " << aspect;
            // One factor scales every lens, so a lens cut by the edge costs its neighbours too;
            // each still magnifies.
            for (const Focus& f : foci) EXPECT_GT(magnificationAt(map, {f.u, f.v}), 1.3) << aspect;
            // A looser bound scales less.
            FociOptions loose = grid(map_rules::kDefaultSide, aspect);
            loose.maxAnisotropy = 30.0;
            EXPECT_GE(magnificationAt(buildFrameFociMap(foci, loose), {foci[0].u, foci[0].v}),
                      magnificationAt(map, {foci[0].u, foci[0].v}) - 1e-6);
        }
    }
}

TEST(FrameFoci, FociAtTheBordersKeepBoundaryNodesOnTheirEdges) {
    const Focus foci[] = {{0.0, 0.0, 0.1, 4.0}, {1.0, 0.4, 0.12, 6.0}, {0.3, 1.0, 0.08, 3.0}, {0.0, 0.7, 0.2, map_rules::kMaxMagnification}};
    for (double aspect : {1.0, 2.0, 0.5}) {
        const SamplingMap map = buildFrameFociMap(foci, grid(map_rules::kDefaultSide, aspect));
        expectValid(map);
        EXPECT_GT(largestMove(map, SamplingMap::identity(map_rules::kDefaultSide, map_rules::kDefaultSide)), 0.01) << aspect;
        // Edge nodes slide along the edge: the focus on the right edge pushes them apart in v.
        constexpr int kLast = map_rules::kDefaultSide - 1;  // the right edge's column, and cells a side
        const double row = 0.4 * kLast;
        const glm::vec2 below = map.node(kLast, int(row) + 2), above = map.node(kLast, int(row) - 2);
        EXPECT_EQ(below.x, 1.0f);
        EXPECT_GT(below.y - above.y, 4.0 / kLast * 1.2) << aspect;
    }
}

TEST(FrameFoci, NoFociOrUnitMagnificationIsTheIdentity) {
    const FociOptions options = grid(33, 1.3);
    EXPECT_EQ(largestMove(buildFrameFociMap({}, options), SamplingMap::identity(33, 33)), 0.0);
    const Focus flat[] = {{0.4, 0.6, 0.2, 1.0}, {0.1, 0.1, 0.3, 1.0}};
    EXPECT_EQ(largestMove(buildFrameFociMap(flat, options), SamplingMap::identity(33, 33)), 0.0);
}

// Small changes of any focus parameter move the nodes a little, also while the fold guard scales
// crowded foci, so frames built from moving foci do not jump.
TEST(FrameFoci, ContinuousInTheFocusParameters) {
    const double delta = 1e-4;
    const std::vector<Focus> sets[] = {
        {{0.45, 0.5, 0.1, 4.0}, {0.55, 0.52, 0.1, 4.0}},                              // overlapping pair
        {{0.3, 0.3, 0.12, 8.0}, {0.4, 0.35, 0.1, 6.0}, {0.35, 0.45, 0.1, 5.0}, {1.0, 0.5, 0.1, 4.0}}};
    const FociOptions options = grid(map_rules::kDefaultSide, 16.0 / 9.0);
    for (const auto& base : sets) {
        const SamplingMap reference = buildFrameFociMap(base, options);
        for (int field = 0; field < 4; ++field)
            for (double sign : {-1.0, 1.0}) {
                std::vector<Focus> moved = base;
                Focus& f = moved[0];
                double* value[] = {&f.u, &f.v, &f.r, &f.k};
                *value[field] += sign * delta;
                const double step = largestMove(reference, buildFrameFociMap(moved, options));
                EXPECT_GT(step, 0.0) << field;
                EXPECT_LT(step, 4.0 * 8.0 * delta) << field;
            }
    }
}

TEST(FrameFoci, BadInputIsAnError) {
    const Focus outside[] = {{1.2, 0.5, 0.1, 2.0}};
    const Focus tooStrong[] = {{0.5, 0.5, 0.1, map_rules::kMaxMagnification + 1}};
    const Focus noRadius[] = {{0.5, 0.5, 0.0, 2.0}};
    EXPECT_THROW(buildFrameFociMap(outside), Error);
    EXPECT_THROW(buildFrameFociMap(tooStrong), Error);
    EXPECT_THROW(buildFrameFociMap(noRadius), Error);
    EXPECT_THROW(buildFrameFociMap({}, grid(1, 1.0)), Error);
    EXPECT_THROW(buildFrameFociMap({}, grid(map_rules::kDefaultSide, 0.0)), Error);
}

}  // namespace
}  // namespace conus::codec
