// Perspective ground-plane map: exact inverse, boundary to boundary, density falling with
// distance, valid grids, analytic round trip.
#include "conus/codec/builders/ground_map.h"

#include <gtest/gtest.h>

#include <random>

#include "conus/core/map_rules.h"
#include "conus/format/container.h"
#include "conus/core/error.h"
#include "codec/builders/valid_map.h"

namespace conus::codec {
namespace {

const GroundParams kCases[] = {
    {0.25, 0.0, 1.0, 60.0}, {0.05, 0.1, 3.0, 90.0}, {2.0, 0.5, 1.5, 30.0}, {0.01, 0.0, 10.0, 120.0}, {1.7, 3.0, 400.0, 45.0},
};

double numericDensity(const GroundParams& g, glm::dvec2 p) {
    const double e = 1e-6;
    const glm::dvec2 du = (groundDistort(g, p + glm::dvec2(e, 0)) - groundDistort(g, p - glm::dvec2(e, 0))) / (2 * e);
    const glm::dvec2 dv = (groundDistort(g, p + glm::dvec2(0, e)) - groundDistort(g, p - glm::dvec2(0, e))) / (2 * e);
    return du.x * dv.y - du.y * dv.x;
}

TEST(Ground, InverseIsExact) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (const GroundParams& g : kCases) {
        double worst = 0;
        for (int n = 0; n < 2000; ++n) {
            const glm::dvec2 p(unit(rng), unit(rng));
            worst = std::max(worst, glm::length(groundUndistort(g, groundDistort(g, p)) - p));
            worst = std::max(worst, glm::length(groundDistort(g, groundUndistort(g, p)) - p));
        }
        EXPECT_LT(worst, 1e-9) << g.eyeHeight << " " << g.near << " " << g.far << " " << g.fovDegrees;
    }
}

TEST(Ground, BoundaryToBoundary) {
    for (const GroundParams& g : kCases) {
        for (double t = 0; t <= 1.0; t += 0.125) {
            EXPECT_EQ(groundDistort(g, {0.0, t}).x, 0.0);
            EXPECT_EQ(groundDistort(g, {1.0, t}).x, 1.0);
            EXPECT_EQ(groundDistort(g, {t, 0.0}).y, 0.0);
            EXPECT_EQ(groundDistort(g, {t, 1.0}).y, 1.0);
            EXPECT_EQ(groundUndistort(g, {0.0, t}).x, 0.0);
            EXPECT_EQ(groundUndistort(g, {t, 1.0}).y, 1.0);
        }
    }
}

TEST(Ground, DensityFallsWithDistance) {
    for (const GroundParams& g : kCases) {
        double previousCentre = 1e300, previousRow = 1e300;
        // From near (v = 1) to far (v = 0).
        for (double v = 0.98; v > 0.0; v -= 0.06) {
            const double centre = numericDensity(g, {0.5, v});
            double row = 0;
            for (double u = 0.025; u < 1.0; u += 0.05) row += numericDensity(g, {u, v}) / 20;
            EXPECT_LT(centre, previousCentre);
            EXPECT_LT(row, previousRow);
            EXPECT_GT(centre, 0.0);
            previousCentre = centre;
            previousRow = row;
        }
        EXPECT_GT(numericDensity(g, {0.5, 0.98}), 1.0);
        EXPECT_LT(numericDensity(g, {0.5, 0.02}), 1.0);
    }
}

TEST(Ground, BuiltGridIsValidAndMatches) {
    for (const GroundParams& g : kCases) {
        for (int side : {2, 3, 17, map_rules::kDefaultSide, 257}) {
            const SamplingMap map = buildGroundMap(g, side, side);
            test::expectValid(map);
            if (side == 257) {
                const glm::dvec2 p(0.3, 0.8);
                EXPECT_NEAR(glm::length(map.distort(p) - groundDistort(g, p)), 0.0, 1e-4);
                EXPECT_NEAR(map.density({0.5, 0.9}) / numericDensity(g, {0.5, 0.9}), 1.0, 0.02);
            }
        }
    }
}

TEST(Ground, AnalyticRoundTrip) {
    const GroundParams g{0.3, 0.2, 5.0, 75.0};
    const format::AnalyticMap a = toAnalytic(g);
    EXPECT_EQ(a.kind, "ground");
    const GroundParams back = groundFromAnalytic(a);
    EXPECT_EQ(back.eyeHeight, g.eyeHeight);
    EXPECT_EQ(back.near, g.near);
    EXPECT_EQ(back.far, g.far);
    EXPECT_EQ(back.fovDegrees, g.fovDegrees);
    format::AnalyticMap wrong = a;
    wrong.kind = "foci";
    EXPECT_THROW(groundFromAnalytic(wrong), Error);
    format::AnalyticMap missing = a;
    missing.scalars.erase("far");
    EXPECT_THROW(groundFromAnalytic(missing), Error);
}

TEST(Ground, RejectsBadParams) {
    EXPECT_THROW(buildGroundMap({0.0, 0.0, 1.0, 60.0}, 9, 9), Error);
    EXPECT_THROW(buildGroundMap({1.0, 2.0, 1.0, 60.0}, 9, 9), Error);
    EXPECT_THROW(buildGroundMap({1.0, 0.0, 1.0, 180.0}, 9, 9), Error);
    EXPECT_THROW(buildGroundMap({1.0, -1.0, 1.0, 60.0}, 9, 9), Error);
    EXPECT_THROW(buildGroundMap({1.0, 0.0, 1.0, 60.0}, 1, 9), Error);
}

}  // namespace
}  // namespace conus::codec
