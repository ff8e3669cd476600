#include "conus/codec/builders/mesh_sequence.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <span>
#include <vector>

#include <gtest/gtest.h>

#include "conus/core/error.h"

namespace conus::codec {
namespace {

Camera camera(double aspect) {
    return Camera::perspective({0.0, 0.0, 10.0}, {0.0, 0.0, 0.0}, {0, 1, 0}, 40.0, aspect, 0.5, 100.0);
}

TEST(TrackedFoci, FollowTheProjectedPoints) {
    const double aspect = 16.0 / 9.0;
    const Camera c = camera(aspect);
    const glm::dvec3 points[] = {{1.0, 0.5, 0.0}, {-2.0, -1.0, 2.0}};
    const auto foci = trackedFoci(c, points, aspect, {0.07, 3.0});
    ASSERT_EQ(foci.size(), 2u);
    for (int i = 0; i < 2; ++i) {
        const glm::dvec3 p = c.project(points[i]);
        EXPECT_NEAR(foci[i].u, p.x, 1e-12);
        EXPECT_NEAR(foci[i].v, p.y, 1e-12);
        EXPECT_EQ(foci[i].r, 0.07);
        EXPECT_EQ(foci[i].k, 3.0);
    }
    EXPECT_GT(foci[0].u, 0.5);  // right of centre
    EXPECT_LT(foci[0].v, 0.5);  // above centre: v grows downward
}

TEST(TrackedFoci, FadeOutBeyondTheBorderAndVanishBehindTheEye) {
    const double aspect = 2.0;
    const Camera c = camera(aspect);
    // A point whose projection lies half a radius (in widths) right of the frame.
    const double r = 0.1;
    const glm::dvec3 onEdge = c.unproject({1.0 + 0.5 * r, 0.3}, 10.0);
    const glm::dvec3 far = c.unproject({1.0 + 1.5 * r, 0.3}, 10.0);
    const glm::dvec3 behind{0.0, 0.0, 12.0};
    const glm::dvec3 points[] = {onEdge, far, behind};
    const auto foci = trackedFoci(c, points, aspect, {r, 5.0});
    ASSERT_EQ(foci.size(), 1u);
    EXPECT_NEAR(foci[0].u, 1.0, 1e-12);  // clamped to the frame
    EXPECT_NEAR(foci[0].v, 0.3, 1e-9);
    EXPECT_NEAR(foci[0].k, 3.0, 1e-9);   // halfway from 5 to 1
    EXPECT_THROW(trackedFoci(c, points, aspect, {0.0, 2.0}), Error);
}

// The per-frame largest node move while two foci (k = 4) pass each other in 40 steps of 1% of the
// width each, with the maps built by `build`.
using MapBuilder = SamplingMap (*)(std::span<const Focus>, const FociOptions&);
std::vector<double> passingMoves(MapBuilder build, FociComposition composition, double step) {
    FociOptions options;
    options.aspect = 16.0 / 9.0;
    options.composition = composition;
    std::vector<double> moves;
    std::optional<SamplingMap> previous;
    for (int frame = 0; frame <= 40; ++frame) {
        const double s = frame * step;
        const Focus foci[] = {{0.3 + s, 0.45, 0.08, 4.0}, {0.7 - s, 0.55, 0.08, 4.0}};
        SamplingMap map = build(std::span<const Focus>(foci), options);
        if (previous) moves.push_back(largestNodeStep(*previous, map));
        previous = std::move(map);
    }
    return moves;
}

double largestRatio(const std::vector<double>& moves) {
    double worst = 1;
    for (std::size_t i = 1; i < moves.size(); ++i)
        worst = std::max(worst, std::max(moves[i] / moves[i - 1], moves[i - 1] / moves[i]));
    return worst;
}

// The animation's composition (add, built in closed form by frameMap): the map follows the foci
// smoothly as they merge and separate. A node near a focus of magnification k moves up to about
// k - 1 times the focus's own step (the lens's Jacobian minus the identity), and the moves change
// gradually from frame to frame (no jump). The density-grid builders are measured alongside
// (printed): the add composition through the density grid, and the density composition, which
// rebuilds the map globally from a sampled density and jitters.
TEST(FrameMaps, FociMergeAndSeparateWithoutJumps) {
    const double step = 0.01, k = 4.0;
    const std::vector<double> add = passingMoves(frameMap, FociComposition::Add, step);
    const std::vector<double> gridAdd = passingMoves(buildFociMap, FociComposition::Add, step);
    const std::vector<double> density = passingMoves(frameMap, FociComposition::Density, step);
    const double largest = *std::max_element(add.begin(), add.end());
    std::printf("largest per-frame node move for a 0.01 focus step: closed-form add %.4f (frame-to-frame ratio up "
                "to %.2f), density-grid add %.4f (%.2f), density %.4f (%.2f)\n",
                largest, largestRatio(add), *std::max_element(gridAdd.begin(), gridAdd.end()), largestRatio(gridAdd),
                *std::max_element(density.begin(), density.end()), largestRatio(density));
    EXPECT_LT(largest, k * step);
    EXPECT_GT(*std::min_element(add.begin(), add.end()), 0.0);
    EXPECT_LT(largestRatio(add), 1.5);
}

TEST(FrameMaps, NoFociIsTheIdentityOfTheGrid) {
    FociOptions options;
    const auto map = frameMap({}, options);
    EXPECT_EQ(map.columns(), options.columns);
    EXPECT_EQ(largestNodeStep(map, SamplingMap::identity(options.columns, options.rows)), 0.0);
    EXPECT_THROW(largestNodeStep(map, SamplingMap::identity(2, 2)), Error);
}

}  // namespace
}  // namespace conus::codec
