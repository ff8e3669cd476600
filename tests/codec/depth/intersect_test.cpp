#include "conus/codec/depth/intersect.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "codec/depth/intersect_scenes.h"
#include "conus/core/error.h"

namespace conus::codec {
namespace {

using test::focusMap;
using test::heightFieldHit;
using test::heightImage;
using test::identityMap;
using test::rayThrough;

// What every hit must satisfy, whatever the surface: its fields describe one point.
void expectConsistent(const DepthImage& image, const Ray& ray, const DepthHit& hit) {
    EXPECT_NEAR(glm::distance(hit.position, ray.origin + ray.direction * hit.t), 0.0, 1e-9);
    const glm::dvec3 projected = image.camera().project(hit.position);
    EXPECT_NEAR(projected.x, hit.point.x, 1e-6);
    EXPECT_NEAR(projected.y, hit.point.y, 1e-6);
    EXPECT_NEAR(projected.z, hit.depth, 1e-6);
    const glm::dvec2 pd = image.map().distort(hit.point);
    EXPECT_NEAR(pd.x, hit.distorted.x, 1e-9);
    EXPECT_NEAR(pd.y, hit.distorted.y, 1e-9);
    EXPECT_EQ(hit.texel.x, std::min(int(pd.x * image.width()), image.width() - 1));
    EXPECT_EQ(hit.texel.y, std::min(int(pd.y * image.height()), image.height() - 1));
    // The hit lies on the stored surface (the bisection's tolerance).
    EXPECT_NEAR(image.sampleDepth(hit.distorted), hit.depth, 1e-4);
}

TEST(Intersect, ReliefCameraSeesTheBoxFromAbove) {
    const Camera camera = test::reliefCamera();
    const glm::dvec3 a = camera.project({0.0, 0.3, 0.0}), b = camera.project({1.0, 0.3, 1.0});
    EXPECT_NEAR(a.x, 0.0, 1e-9);
    EXPECT_NEAR(a.y, 0.0, 1e-9);
    EXPECT_NEAR(b.x, 1.0, 1e-9);
    EXPECT_NEAR(b.y, 1.0, 1e-9);
    EXPECT_NEAR(a.z, heightToDepth(camera, 0.3), 1e-9);
}

// A tilted plane: bilinear interpolation of an affine function is exact in a conventional image;
// through a CoNUS map it is exact at the samples and close between them.
TEST(Intersect, TiltedPlaneMatchesClosedForm) {
    const auto plane = [](double x, double z) { return 0.2 + 0.1 * x + 0.05 * z; };
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> unit(0.05, 0.95), tilt(-0.6, 0.6);
    for (const bool conus : {false, true}) {
        const DepthImage image = heightImage(plane, conus ? focusMap(0.3, 0.6) : identityMap(), 128);
        for (int i = 0; i < 60; ++i) {
            const glm::dvec3 target(unit(rng), 0.0, unit(rng));
            const glm::dvec3 target3(target.x, plane(target.x, target.z), target.z);
            const Ray ray = rayThrough(target3 + glm::dvec3(tilt(rng), 1.2, tilt(rng)), target3);
            // Closed form: origin.y + t d.y = plane(origin + t d).
            const double num = plane(ray.origin.x, ray.origin.z) - ray.origin.y;
            const double den = ray.direction.y - 0.1 * ray.direction.x - 0.05 * ray.direction.z;
            const double truth = num / den;
            const auto hit = intersect(image, ray);
            ASSERT_TRUE(hit) << (conus ? "CoNUS" : "identity") << " ray " << i;
            EXPECT_NEAR(hit->t, truth, conus ? 2e-3 : 2e-4) << (conus ? "CoNUS" : "identity") << " ray " << i;
            expectConsistent(image, ray, *hit);
        }
    }
}

// Between the last texel centres and the image's side the surface goes on at its last step: a
// steep plane is met where it is there too, not at the edge texel's height (half a texel's rise
// off), and the depth range reaches the side.
TEST(Intersect, TiltedPlaneReachesTheImagesSides) {
    constexpr int kSize = 64;
    const DepthImage image = heightImage(test::steepPlane, identityMap(), kSize);
    const Camera& camera = image.camera();
    EXPECT_NEAR(image.maxDepth(), heightToDepth(camera, test::steepPlane(0.0, 1.0)), 1e-6);  // the lowest corner
    EXPECT_NEAR(image.minDepth(), heightToDepth(camera, test::steepPlane(1.0, 0.0)), 1e-6);  // the highest
    for (const Ray& ray : test::raysIntoTheSideStrips(kSize, 5, 400)) {
        // Closed form: origin.y + t d.y = steepPlane(origin + t d).
        const double num = test::steepPlane(ray.origin.x, ray.origin.z) - ray.origin.y;
        const double truth = num / (ray.direction.y - 0.5 * ray.direction.x + 0.4 * ray.direction.z);
        const auto hit = intersect(image, ray);
        ASSERT_TRUE(hit) << "ray from " << ray.origin.x << ", " << ray.origin.z;
        EXPECT_NEAR(hit->t, truth, 2e-4) << "ray from " << ray.origin.x << ", " << ray.origin.z;
        expectConsistent(image, ray, *hit);
    }
}

// The same in perspective, in a scene's image: 1/depth carried on to the side, where a plane's is
// affine, so a wall is met where it is (linear depth would fall short by its curvature; the edge
// texel's depth by half a texel's step).
TEST(Intersect, TiltedWallReachesAPerspectiveImagesSides) {
    constexpr int kSize = 64;
    IntersectOptions options;
    options.refinements = 24;  // the hit to a hair of the surface: the depths here are about 8
    for (const bool conus : {false, true}) {
        const DepthImage image = test::tiltedWallImage(conus ? focusMap(0.3, 0.6, 0.15, 3.0) : identityMap(), kSize);
        for (const Ray& ray : test::raysIntoTheWallsSideStrips(kSize, 6, 400)) {
            const auto hit = intersect(image, ray, options);
            ASSERT_TRUE(hit) << (conus ? "CoNUS" : "identity");
            const double tolerance = conus ? 5e-3 : 2e-4;  // CoNUS: larger texels at the sides
            EXPECT_NEAR(hit->t, test::tiltedWallHit(ray).value(), tolerance) << (conus ? "CoNUS" : "identity");
            EXPECT_FALSE(hit->hidden);
            expectConsistent(image, ray, *hit);
        }
    }
}

// A sphere in front of a wall, seen by a perspective camera; rays from elsewhere (as reflected
// rays would come) must find the sphere where it truly is.
TEST(Intersect, PerspectiveSphereFromAnotherViewpoint) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> angle(-0.9, 0.9);
    for (const bool conus : {false, true}) {
        const DepthImage image = test::sphereImage(conus ? focusMap(0.52, 0.5, 0.2, 3.0) : identityMap(), 256);
        const glm::dvec3 origin(1.5, 1.0, -3.5);
        int hits = 0;
        for (int i = 0; i < 60; ++i) {
            // Points on the sphere facing both the camera (-z) and the ray's origin, away from the
            // silhouette, where a depth image holds the surface.
            const double a = angle(rng), b = angle(rng) * 0.7;
            const glm::dvec3 normal = glm::normalize(glm::dvec3(std::sin(a) * 0.6 + 0.25, std::sin(b) * 0.6 + 0.15, -1.0));
            const glm::dvec3 target = test::kSphereCentre + normal * test::kSphereRadius;
            const Ray ray = rayThrough(origin, target);
            const auto truth = test::sphereSceneHit(ray);
            ASSERT_TRUE(truth);
            const auto hit = intersect(image, ray);
            ASSERT_TRUE(hit) << i;
            EXPECT_NEAR(hit->t, *truth, 0.01) << (conus ? "CoNUS" : "identity") << " ray " << i;
            expectConsistent(image, ray, *hit);
            ++hits;
        }
        EXPECT_EQ(hits, 60);
        // Rays into the wall past the sphere hit the wall.
        const Ray wallRay = rayThrough({-1.0, 1.2, -4.0}, {-1.2, 0.9, test::kWallZ});
        const auto wall = intersect(image, wallRay);
        ASSERT_TRUE(wall);
        EXPECT_NEAR(wall->position.z, test::kWallZ, 0.01);
    }
}

// A thin board in front of a far wall (a depth image of a scene): rays from elsewhere that pass
// beside the board, over its silhouette in the image, hit the wall where it is, not the "skin"
// between the board's depth and the wall's (the bilinear surface across the silhouette, which the
// intersection hit before cells were split at discontinuities); rays at the board hit the board;
// rays into the wall behind it, which the image never saw, hit the wall carried on behind it.
TEST(Intersect, ThinBoardInFrontOfAFarWallHasNoSkin) {
    for (const bool conus : {false, true}) {
        const DepthImage image = test::boardImage(conus ? focusMap(0.5, 0.5, 0.1, 3.0) : identityMap(), 128);
        const char* what = conus ? "CoNUS" : "identity";
        const glm::dvec3 origin(1.2, 0.3, -3.0);
        int crossings = 0;
        for (int i = 0; i < 40; ++i) {
            const double x = -0.5 + 0.38 * i / 39.0, y = -0.5 + 0.027 * i;
            const Ray ray = rayThrough(origin, {x, y, test::kWallZ});
            const auto truth = test::boardSceneHit(ray);
            ASSERT_TRUE(truth);
            // The ray passes the board's plane beside it and ends on the other side of its image:
            // its projection crosses the board's image behind the board, the skin case.
            const double t0 = -ray.origin.z / ray.direction.z;
            const double u0 = image.camera().project(ray.origin + ray.direction * t0).x;
            const double u1 = image.camera().project(ray.origin + ray.direction * *truth).x;
            if ((u0 - 0.5) * (u1 - 0.5) < 0.0) ++crossings;
            const auto hit = intersect(image, ray);
            ASSERT_TRUE(hit) << what << " ray " << i;
            EXPECT_NEAR(hit->position.z, test::kWallZ, 0.01) << what << " ray " << i;
            EXPECT_NEAR(hit->t, *truth, 0.02) << what << " ray " << i;
            EXPECT_FALSE(hit->hidden);
            expectConsistent(image, ray, *hit);
        }
        EXPECT_GT(crossings, 30);
        // At the board, over half a texel (0.028 here) inside its outline: a single layer keeps a
        // silhouette to within half a texel.
        for (int i = 0; i < 12; ++i) {
            const Ray ray = rayThrough(origin, {-0.015 + 0.0025 * i, -0.4 + 0.07 * i, 0.0});
            const auto hit = intersect(image, ray);
            ASSERT_TRUE(hit) << what << " board ray " << i;
            EXPECT_NEAR(hit->position.z, 0.0, 0.01) << what << " board ray " << i;
            EXPECT_NEAR(hit->t, test::boardSceneHit(ray).value(), 0.01);
        }
        // Into the strip of wall the board hides from the camera: the background carried on.
        const Ray behind = rayThrough(origin, {0.0, 0.1, test::kWallZ});
        ASSERT_GT(std::abs(behind.origin.x + behind.direction.x * (-origin.z / behind.direction.z)), test::kBoardHalf);
        const auto hidden = intersect(image, behind);
        ASSERT_TRUE(hidden) << what;
        EXPECT_TRUE(hidden->hidden);
        EXPECT_NEAR(hidden->position.z, test::kWallZ, 0.01);
        // The same depths as matter (a height field's rule): the board is solid to the wall, and
        // the first ray that passes behind its silhouette hits its side.
        const DepthImage solid = test::boardImage(conus ? focusMap(0.5, 0.5, 0.1, 3.0) : identityMap(), 128, true);
        const auto side = intersect(solid, rayThrough(origin, {-0.3, 0.0, test::kWallZ}));
        ASSERT_TRUE(side);
        EXPECT_LT(side->position.z, 1.5);
    }
}

// The far plane of a scene's image is where it saw nothing: a ray entering through the image's
// side within a jump behind it is not taken to meet a surface there (a floor across a cube face's
// side is; Reflection.FloorAcrossAFaceSeamIsHitNotMissed).
TEST(Intersect, NothingSeenIsNotContinuedAcrossTheSide) {
    for (const bool conus : {false, true}) {
        const DepthImage image = test::skyImage(conus ? focusMap(0.3, 0.6, 0.1, 3.0) : identityMap(), 96);
        int enteringThroughASide = 0;
        for (const Ray& ray : test::raysPastTheFarPlane()) {
            const glm::dvec3 p = image.camera().project(ray.origin);
            if (p.x > 1.0 || p.x < 0.0) ++enteringThroughASide;
            EXPECT_FALSE(intersect(image, ray)) << (conus ? "CoNUS" : "identity") << " ray from " << ray.origin.y;
        }
        EXPECT_EQ(enteringThroughASide, 24);
    }
}

// Cells are flagged where the depth jumps against its neighbours, not where it changes steadily:
// a plane seen at a grazing angle has none, the board's silhouette columns have them.
TEST(Intersect, DiscontinuityFlagsMarkSilhouettesOnly) {
    const Camera camera = test::sphereCamera();
    const int size = 64;
    std::vector<float> floor(static_cast<std::size_t>(size) * size);
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            // The plane y = -0.3 + 0.02 z, steeply foreshortened: 1/depth affine in the image.
            const Ray ray = camera.ray({(x + 0.5) / size, (y + 0.5) / size});
            const double t = (-0.3 - ray.origin.y + 0.02 * ray.origin.z) / (ray.direction.y - 0.02 * ray.direction.z);
            floor[static_cast<std::size_t>(y) * size + x] =
                static_cast<float>(t > 0 ? std::min(glm::dot(ray.direction * t, camera.forward()), 19.0) : 19.0);
        }
    const DepthImage plane(camera, identityMap(), size, size, floor, false);
    int flaggedRows = 0;
    for (int y = 0; y < size; ++y) {
        bool any = false;
        for (int x = 0; x < size; ++x) any = any || plane.cellFlags()[static_cast<std::size_t>(y) * size + x];
        flaggedRows += any;
    }
    EXPECT_LE(flaggedRows, 1);  // at most the horizon, where the plane meets the far clip
    const DepthImage board = test::boardImage(identityMap(), size);
    int flagged = 0;
    for (int x = 0; x < size; ++x) flagged += board.cellFlags()[static_cast<std::size_t>(size / 2) * size + x];
    EXPECT_GE(flagged, 2);
    EXPECT_LE(flagged, 4);
}

// A step: heights jump at x = 0.5. A focus on the edge holds it sharper than the identity at the
// same texel count, so rays that hit the wall are placed better.
TEST(Intersect, StepWallSharperWhereTheMapMagnifies) {
    const auto step = [](double x, double) { return x > 0.5 ? 0.4 : 0.1; };
    double error[2] = {0, 0};
    for (const bool conus : {false, true}) {
        const DepthImage image = heightImage(step, conus ? focusMap(0.5, 0.5, 0.06, 4.0) : identityMap(), 64);
        int n = 0;
        for (double z = 0.4; z <= 0.6; z += 0.01)
            for (const double y : {0.15, 0.25, 0.35}) {
                // From the low side, level, into the wall.
                const Ray ray = rayThrough({0.1, y + 0.05, z}, {0.7, y - 0.05, z + 0.03});
                const auto truth = heightFieldHit(step, ray);
                ASSERT_TRUE(truth);
                const auto hit = intersect(image, ray);
                ASSERT_TRUE(hit) << "z " << z << " y " << y;
                error[conus] += std::abs(hit->t - *truth);
                expectConsistent(image, ray, *hit);
                ++n;
            }
        error[conus] /= n;
        // At most about a texel (1/64) off, even where the wall is a one-texel ramp.
        EXPECT_LT(error[conus], 1.5 / 64) << (conus ? "CoNUS" : "identity");
    }
    EXPECT_LT(error[1], 0.5 * error[0]);
}

// A spike two texels wide: rays at it hit its side; rays beside it miss and hit the floor beyond.
TEST(Intersect, ThinSpikeIsFoundAndMissedWhereItIsNot) {
    const glm::dvec2 spike(0.37, 0.61);
    const double radius = 1.0 / 64;
    const auto field = [&](double x, double z) { return glm::distance(glm::dvec2(x, z), spike) < radius ? 0.5 : 0.05; };
    for (const bool conus : {false, true}) {
        const DepthImage image = heightImage(field, conus ? focusMap(0.37, 0.61, 0.1, 3.0) : identityMap(), 64);
        IntersectOptions fine;
        fine.stepTexels = 0.5;
        // Nearly level, at half the spike's height, straight at it.
        const Ray at = rayThrough({0.05, 0.3, 0.55}, {spike.x, 0.28, spike.y});
        const auto hit = intersect(image, at, fine);
        ASSERT_TRUE(hit) << (conus ? "CoNUS" : "identity");
        EXPECT_LT(glm::distance(glm::dvec2(hit->position.x, hit->position.z), spike), 2.5 * radius);
        EXPECT_GT(hit->position.y, 0.2);
        // Beside it by six radii, lower than its top: passes, and comes down on the floor beyond it.
        const Ray beside = rayThrough({0.05, 0.3, 0.55 + 6 * radius}, {spike.x, 0.2, spike.y + 6 * radius});
        const auto floor = intersect(image, beside, fine);
        ASSERT_TRUE(floor);
        EXPECT_NEAR(floor->position.y, 0.05, 0.01);
        const auto truth = heightFieldHit(field, beside);
        ASSERT_TRUE(truth);
        EXPECT_NEAR(floor->t, *truth, 0.02);
    }
}

TEST(Intersect, GrazingAndMissingRays) {
    const auto plane = [](double, double) { return 0.25; };
    for (const bool conus : {false, true}) {
        const DepthImage image = heightImage(plane, conus ? focusMap(0.5, 0.5) : identityMap(), 64);
        // Level, just above the plane: never touches it.
        EXPECT_FALSE(intersect(image, rayThrough({-0.5, 0.2501, 0.3}, {1.5, 0.2501, 0.7})));
        // Grazing down at 1/200: comes down where the closed form says.
        const Ray grazing = rayThrough({0.0, 0.2525, 0.5}, {1.0, 0.2475, 0.5});
        const auto hit = intersect(image, grazing);
        ASSERT_TRUE(hit);
        EXPECT_NEAR(hit->position.x, 0.5, 1e-3);
        // Beside the box, above it going up, pointing away, and cut short by tMax.
        EXPECT_FALSE(intersect(image, rayThrough({1.2, 0.1, 0.5}, {1.2, 0.1, 0.9})));
        EXPECT_FALSE(intersect(image, rayThrough({0.5, 0.5, 0.5}, {0.6, 0.9, 0.5})));
        EXPECT_FALSE(intersect(image, rayThrough({0.5, 1.0, -0.5}, {0.5, 1.5, -1.0})));
        IntersectOptions shortRay;
        shortRay.tMax = 0.5;
        EXPECT_FALSE(intersect(image, rayThrough({0.5, 1.0, 0.5}, {0.5, 0.0, 0.5}), shortRay));
        // Straight down (the projection is a point): still found.
        const auto down = intersect(image, rayThrough({0.3, 1.0, 0.7}, {0.3, 0.0, 0.7}));
        ASSERT_TRUE(down);
        EXPECT_NEAR(down->t, 0.75, 1e-6);
    }
}

// A ray entering the box through its side below the surface hits the side wall where it enters.
TEST(Intersect, SideWallOfTheBox) {
    const auto field = [](double x, double z) { return 0.3 + 0.1 * std::sin(6 * x + 2 * z); };
    const DepthImage image = heightImage(field, focusMap(0.6, 0.4), 64);
    const Ray ray = rayThrough({-0.5, 0.25, 0.4}, {1.0, 0.25, 0.45});
    const auto hit = intersect(image, ray);
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->position.x, 0.0, 1e-9);
    EXPECT_EQ(hit->steps, 0);
    EXPECT_EQ(hit->face, 0);  // u = 0
}

// Step counts follow the map's density: a walk through a 4x focus takes several times the
// identity's steps over the same stretch, one through the compressed context fewer. (Over the
// whole image the totals agree: the CoNUS image is as wide as the conventional one.)
TEST(Intersect, StepsFollowTheLocalDensity) {
    // A floor with a bump in a corner, away from the rays (the clip keeps the bump's depth range).
    const auto floor = [](double x, double z) { return std::hypot(x - 0.9, z - 0.1) < 0.05 ? 0.5 : 0.1; };
    const DepthImage flat = heightImage(floor, identityMap(), 128);
    const DepthImage focused = heightImage(floor, focusMap(0.5, 0.5, 0.1, 4.0), 128);
    // Rays across a fifth of the field, coming down on the floor at its end.
    const auto steps = [&](const DepthImage& image, double x, double z) {
        const auto hit = intersect(image, rayThrough({x, 0.3, z}, {x + 0.2, 0.099, z}));
        return hit ? hit->steps : -1;
    };
    const int throughFlat = steps(flat, 0.4, 0.5), throughFocus = steps(focused, 0.4, 0.5);
    EXPECT_NEAR(throughFlat, 0.2 * 128, 2);
    EXPECT_GT(throughFocus, 2 * throughFlat);
    const int contextFlat = steps(flat, 0.02, 0.97), contextFocused = steps(focused, 0.02, 0.97);
    EXPECT_NEAR(contextFlat, 0.2 * 128, 2);
    EXPECT_LT(contextFocused, contextFlat);
    EXPECT_GT(contextFocused, 0);
}

TEST(Intersect, FromFileReadsHeightsAndCamera) {
    const auto field = [](double x, double z) { return 0.2 + 0.15 * x * z; };
    const DepthImage direct = heightImage(field, identityMap(), 16);
    format::ConusFile file;
    file.image = makeImage(16, 16, {"R", "G", "B", "Z"});
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) file.image.at(x, y, 3) = static_cast<float>(field((x + 0.5) / 16, (y + 0.5) / 16));
    file.dataKind = format::DataKind::HeightField;
    file.depth.kind = format::DepthKind::Height;
    file.map = SamplingMap::identity(2, 2).toGrid();
    file.camera = format::toAttributes(test::reliefCamera());
    const DepthImage read = DepthImage::fromFile(file);
    for (std::size_t i = 0; i < direct.depths().size(); ++i) EXPECT_NEAR(read.depths()[i], direct.depths()[i], 1e-5);
    file.camera.reset();
    EXPECT_THROW(DepthImage::fromFile(file), Error);
}

TEST(Intersect, BadOptionsAndRaysAreRefused) {
    IntersectOptions bad;
    bad.stepTexels = 0;
    EXPECT_THROW(checkIntersectOptions(bad), Error);
    bad = {};
    bad.refinements = 100;
    EXPECT_THROW(checkIntersectOptions(bad), Error);
    EXPECT_NO_THROW(checkIntersectOptions({}));
    EXPECT_THROW(checkRay({{0, 0, 0}, {0, 0, 2}}), Error);
    EXPECT_THROW(checkRay({{NAN, 0, 0}, {0, 0, 1}}), Error);
    EXPECT_THROW(DepthImage(test::reliefCamera(), nullptr, 2, 2, {1.0f, 2.0f, 3.0f}), Error);
    EXPECT_THROW(DepthImage(test::reliefCamera(), nullptr, 1, 1, {INFINITY}), Error);
}

}  // namespace
}  // namespace conus::codec
