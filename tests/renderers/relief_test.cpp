#include "conus/renderers/relief.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "codec/depth/intersect_scenes.h"
#include "codec/mesh/mesh_test_scenes.h"
#include "conus/codec/depth/reflection.h"
#include "conus/core/error.h"
#include "renderers/gl_test_util.h"

namespace conus::renderers {
namespace {

using codec::DepthHit;
using codec::DepthImage;
using codec::test::focusMap;
using codec::test::heightImage;
using codec::test::identityMap;
using codec::test::rayThrough;

class ReliefGl : public ::testing::TestWithParam<Backend> {
protected:
    Context& context() { return test::contextFor(GetParam()); }
};

// Asymmetric hills, a ridge and a pit.
double hills(double x, double z) {
    return 0.25 + 0.08 * std::sin(7.0 * x + 3.0 * z) * std::cos(4.0 * z - x) +
           0.1 * std::exp(-((x - 0.3) * (x - 0.3) + (z - 0.65) * (z - 0.65)) / 0.01) -
           0.07 * std::exp(-((x - 0.7) * (x - 0.7) + (z - 0.3) * (z - 0.3)) / 0.004);
}

// Rays from around and above the box toward random points on and beside it, some grazing, some
// entering through the sides, some missing.
std::vector<Ray> reliefRays(unsigned seed, int count) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(-0.2, 1.2), height(0.0, 0.6), angle(0.0, 6.283185307179586);
    std::vector<Ray> rays;
    for (int i = 0; i < count; ++i) {
        const double a = angle(rng);
        const glm::dvec3 from(0.5 + 1.5 * std::cos(a), 0.3 + height(rng) * 2.0, 0.5 + 1.5 * std::sin(a));
        rays.push_back(rayThrough(from, {unit(rng), height(rng), unit(rng)}));
    }
    return rays;
}

// The GLSL agrees with the CPU reference: the same rays hit, at the same places (float vs double:
// a step may land a hair differently, so positions agree to a fraction of a texel).
void expectAgreement(Context& context, const DepthImage& image, const std::vector<Ray>& rays,
                     const codec::IntersectOptions& options, double tolerance) {
    const auto gpu = intersectRays(context, image, rays, options);
    ASSERT_EQ(gpu.size(), rays.size());
    int hits = 0, disagreements = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const auto cpu = codec::intersect(image, rays[i], options);
        if (cpu.has_value() != gpu[i].has_value()) {
            ++disagreements;
            continue;
        }
        if (!cpu) continue;
        ++hits;
        const DepthHit& c = *cpu;
        const DepthHit& g = *gpu[i];
        if (glm::distance(c.position, g.position) > tolerance || std::abs(c.t - g.t) > tolerance ||
            glm::distance(c.point, g.point) > tolerance || glm::distance(c.distorted, g.distorted) > tolerance ||
            std::abs(c.depth - g.depth) > tolerance || c.face != g.face || c.hidden != g.hidden ||
            std::abs(c.steps - g.steps) > 2 + c.steps / 50 || glm::length(glm::dvec2(c.texel - g.texel)) > 1.5)
            ++disagreements;
    }
    // Float rounding may flip a ray that only grazes a crest; allow one in a hundred.
    EXPECT_LE(disagreements, static_cast<int>(rays.size()) / 100) << hits << " hits";
    EXPECT_GT(hits, static_cast<int>(rays.size()) / 4);
}

TEST_P(ReliefGl, GlslMatchesCpuOnAHeightFieldIdentityAndCoNUS) {
    const std::vector<Ray> rays = reliefRays(3, 2000);
    for (const bool conus : {false, true}) {
        const DepthImage image = heightImage(hills, conus ? focusMap(0.3, 0.65, 0.15, 4.0) : identityMap(), 96);
        expectAgreement(context(), image, rays, {}, 2e-3);
    }
}

TEST_P(ReliefGl, GlslMatchesCpuOnAPerspectiveSphere) {
    const DepthImage image = codec::test::sphereImage(focusMap(0.5, 0.5, 0.2, 3.0), 128);
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> spread(-1.6, 1.6);
    std::vector<Ray> rays;
    for (int i = 0; i < 1000; ++i)
        rays.push_back(rayThrough({1.5, 1.0, -3.5}, {spread(rng), spread(rng), spread(rng) * 0.5}));
    expectAgreement(context(), image, rays, {}, 1e-2);
}

// Between the last texel centres and the side the surface goes on at its last step, in both twins.
TEST_P(ReliefGl, GlslMatchesCpuInTheSideStrips) {
    for (const bool conus : {false, true}) {
        const auto map = conus ? focusMap(0.3, 0.65, 0.15, 4.0) : identityMap();
        const DepthImage image = heightImage(codec::test::steepPlane, map, 64);
        expectAgreement(context(), image, codec::test::raysIntoTheSideStrips(64, 8, 500), {}, 2e-3);
    }
}

TEST_P(ReliefGl, GlslMatchesCpuInAPerspectiveImagesSideStrips) {
    for (const bool conus : {false, true}) {
        const auto map = conus ? focusMap(0.3, 0.6, 0.15, 3.0) : identityMap();
        const DepthImage image = codec::test::tiltedWallImage(map, 64);
        expectAgreement(context(), image, codec::test::raysIntoTheWallsSideStrips(64, 9, 500), {}, 2e-3);
    }
}

// A scene's silhouettes (walls are no hits, hidden rays take the background) follow the same rule.
TEST_P(ReliefGl, GlslMatchesCpuBesideAThinBoard) {
    const DepthImage image = codec::test::boardImage(focusMap(0.5, 0.5, 0.1, 3.0), 128);
    std::mt19937 rng(4);
    std::uniform_real_distribution<double> x(-0.6, 0.6), y(-0.6, 0.6);
    std::vector<Ray> rays;
    for (int i = 0; i < 1000; ++i) rays.push_back(rayThrough({1.2, 0.3, -3.0}, {x(rng), y(rng), codec::test::kWallZ}));
    const auto gpu = intersectRays(context(), image, rays, {});
    int hidden = 0;
    for (const auto& h : gpu) hidden += h && h->hidden;
    EXPECT_GT(hidden, 10);
    expectAgreement(context(), image, rays, {}, 1e-2);
}

// A scene's surface across the side a ray enters through (a floor seen by two cube faces): hit
// where the ray enters, in both twins.
TEST_P(ReliefGl, GlslMatchesCpuWhereAFloorCrossesAFaceSide) {
    const codec::MeshScene mesh(codec::test::rampedBoxAndFloor({0.4f, -0.3f, 1.5f}, {1.0f, 0.5f, 2.2f}));
    codec::ReflectionBakeOptions bake;
    bake.size = 64;
    const auto faces = codec::bakeReflection(mesh, bake);
    const DepthImage& below = faces[3].depth;  // -y: the floor meets +z's and -x's faces at its sides
    std::vector<Ray> rays;
    for (int i = 0; i < 200; ++i) {
        const double across = -0.7 + 1.4 * (i % 20) / 19.0, off = -0.01 + 0.02 * (i / 20) / 9.0;
        rays.push_back(rayThrough({0.07, 0.25, 0.1}, {across, -1.0, 1.0 + off}));
        rays.push_back(rayThrough({0.07, 0.25, 0.1}, {-1.0 - off, -1.0, across}));
    }
    int acrossSide = 0;
    for (const auto& ray : rays)
        if (const auto hit = codec::intersect(below, ray); hit && hit->steps == 0 && hit->face >= 0 && hit->face < 4) ++acrossSide;
    EXPECT_GT(acrossSide, 40);
    expectAgreement(context(), below, rays, {}, 1e-2);
}

TEST_P(ReliefGl, GlslFindsNothingPastAScenesFarPlaneEither) {
    const DepthImage image = codec::test::skyImage(focusMap(0.3, 0.6, 0.1, 3.0), 96);
    const auto gpu = intersectRays(context(), image, codec::test::raysPastTheFarPlane());
    for (const auto& hit : gpu) EXPECT_FALSE(hit);
}

TEST_P(ReliefGl, FinerStepsAndShortRaysAgreeToo) {
    const DepthImage image = heightImage(hills, focusMap(0.7, 0.3, 0.1, 3.0), 64);
    codec::IntersectOptions options;
    options.stepTexels = 0.5;
    options.refinements = 16;
    options.tMax = 1.8;
    expectAgreement(context(), image, reliefRays(8, 600), options, 2e-3);
}

TEST_P(ReliefGl, BadInputIsRefused) {
    const DepthImage image = heightImage(hills, identityMap(), 16);
    EXPECT_THROW(intersectRays(context(), image, {{{0, 0, 0}, {0, 0, 3}}}), Error);
    codec::IntersectOptions bad;
    bad.stepTexels = -1;
    EXPECT_THROW(intersectRays(context(), image, {{{0, 0, 0}, {0, 0, 1}}}, bad), Error);
    EXPECT_TRUE(intersectRays(context(), image, {}).empty());
    EXPECT_THROW(ReliefRenderer(context(), image, makeImage(8, 8, {"R", "G", "B"})), Error);
}

INSTANTIATE_TEST_SUITE_P(Backends, ReliefGl, ::testing::Values(Backend::Egl, Backend::OsMesa), test::paramName);

}  // namespace
}  // namespace conus::renderers
