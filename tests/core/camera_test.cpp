// The planar pinhole camera and the FPC: OpenEXR's conventions, exact inverses, matrices that
// round-trip through the container's attributes.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "conus/core/camera.h"
#include "conus/core/error.h"
#include "conus/core/fpc.h"

namespace conus {
namespace {

void expectNear(glm::dvec3 a, glm::dvec3 b, double tolerance, const char* what) {
    EXPECT_NEAR(a.x, b.x, tolerance) << what;
    EXPECT_NEAR(a.y, b.y, tolerance) << what;
    EXPECT_NEAR(a.z, b.z, tolerance) << what;
}

// p * M with M a row-major 4x4 of OpenEXR's attributes (row vectors), divided by w.
glm::dvec3 rowVectorTimes(glm::dvec3 p, const std::array<float, 16>& m) {
    double out[4] = {};
    for (int c = 0; c < 4; ++c) out[c] = p.x * m[0 * 4 + c] + p.y * m[1 * 4 + c] + p.z * m[2 * 4 + c] + m[3 * 4 + c];
    return {out[0] / out[3], out[1] / out[3], out[2] / out[3]};
}

// u -> u^2 (an FPC that magnifies the right side), exactly invertible.
class Squared final : public Distortion {
public:
    glm::dvec2 distort(glm::dvec2 p) const override { return {p.x * p.x, p.y}; }
    glm::dvec2 undistort(glm::dvec2 pd) const override { return {std::sqrt(pd.x), pd.y}; }
    glm::dmat2 jacobian(glm::dvec2 p) const override { return glm::dmat2(2 * p.x, 0, 0, 1); }
};

}  // namespace

TEST(Camera, PerspectiveFollowsOpenExrConventions) {
    // A right-handed world, y up, the eye on +z looking at the origin.
    const Camera camera = Camera::perspective({0, 0, 10}, {0, 0, 0}, {0, 1, 0}, 60.0, 2.0, 0.5, 100.0);
    expectNear(camera.project({0, 0, 0}), {0.5, 0.5, 10.0}, 1e-12, "the target is in the middle, 10 deep");
    const glm::dvec3 upRight = camera.project({1, 1, 0});
    EXPECT_GT(upRight.x, 0.5) << "u grows to the right";
    EXPECT_LT(upRight.y, 0.5) << "v grows downward";
    // The top edge of the field of view: tan(30 deg) * 10 above the target.
    EXPECT_NEAR(camera.project({0, std::tan(glm::radians(30.0)) * 10, 0}).y, 0.0, 1e-12);
    // ... and the right edge, twice as far (aspect 2).
    EXPECT_NEAR(camera.project({2 * std::tan(glm::radians(30.0)) * 10, 0, 0}).x, 1.0, 1e-12);
    EXPECT_LT(camera.project({0, 0, 20}).z, 0.0) << "behind the eye";
    // worldToCamera: left-handed camera space, +z forward, depth = z.
    expectNear(rowVectorTimes({0, 0, 0}, camera.worldToCamera()), {0, 0, 10}, 1e-5, "camera space");
    // worldToNDC as a row vector times the matrix gives (u, v) after the division by w.
    const glm::dvec3 ndc = rowVectorTimes({1, 1, 0}, camera.worldToNDC());
    EXPECT_NEAR(ndc.x, upRight.x, 1e-6);
    EXPECT_NEAR(ndc.y, upRight.y, 1e-6);
    expectNear(camera.eye(), {0, 0, 10}, 1e-12, "eye");
    expectNear(camera.forward(), {0, 0, -1}, 1e-12, "forward");
}

TEST(Camera, UnprojectRaysAndMatricesRoundTrip) {
    for (const Camera& camera : {Camera::perspective({3, 4, 5}, {-1, 0.5, 2}, {0, 1, 0}, 45.0, 1.5, 0.1, 50.0),
                                 Camera::orthographic({3, 4, 5}, {-1, 0.5, 2}, {0, 1, 0}, 6.0, 1.5, -2.0, 20.0)}) {
        for (const glm::dvec2 uv : {glm::dvec2(0.5, 0.5), glm::dvec2(0.1, 0.8), glm::dvec2(1.0, 0.0)}) {
            for (const double depth : {0.3, 2.0, 17.0}) {
                const glm::dvec3 world = camera.unproject(uv, depth);
                expectNear(camera.project(world), {uv.x, uv.y, depth}, 1e-9, "project(unproject)");
                const Ray ray = camera.ray(uv);
                EXPECT_NEAR(glm::length(ray.direction), 1.0, 1e-12);
                const glm::dvec3 toPoint = world - ray.origin;
                EXPECT_NEAR(glm::length(glm::cross(toPoint, ray.direction)), 0.0, 1e-9) << "the ray passes the point";
            }
        }
        // Through the container's 32-bit matrices and back.
        const Camera back = Camera::fromMatrices(camera.worldToCamera(), camera.worldToNDC(), camera.projection());
        for (const glm::dvec3 p : {glm::dvec3(0, 0, 0), glm::dvec3(-2, 1, 1), glm::dvec3(1, 3, -4)})
            expectNear(back.project(p), camera.project(p), 1e-4, "fromMatrices");
        EXPECT_NEAR(back.near(), camera.near(), 1e-3 * std::max(1.0, std::abs(camera.near())));
        EXPECT_NEAR(back.far(), camera.far(), 1e-3 * camera.far());
    }
    const Camera ortho = Camera::orthographic({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 2.0, 1.0, 0.0, 10.0);
    expectNear(ortho.ray({0.1, 0.3}).direction, ortho.ray({0.9, 0.7}).direction, 1e-12, "parallel rays");
}

TEST(Camera, BadCamerasAndMatricesAreRefused) {
    EXPECT_THROW(Camera::perspective({0, 0, 0}, {0, 0, 0}, {0, 1, 0}, 50, 1, 1, 10), Error);
    EXPECT_THROW(Camera::perspective({0, 0, 0}, {0, 1, 0}, {0, 1, 0}, 50, 1, 1, 10), Error) << "up along the view";
    EXPECT_THROW(Camera::perspective({0, 0, 0}, {0, 0, 1}, {0, 1, 0}, 180, 1, 1, 10), Error);
    EXPECT_THROW(Camera::perspective({0, 0, 0}, {0, 0, 1}, {0, 1, 0}, 50, 1, 10, 1), Error);
    const Camera camera = Camera::perspective({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 50, 1, 1, 10);
    std::array<float, 16> singular{};
    EXPECT_THROW(Camera::fromMatrices(singular, camera.worldToNDC(), Projection::Perspective), Error);
    std::array<float, 16> nan = camera.worldToCamera();
    nan[5] = std::nanf("");
    EXPECT_THROW(Camera::fromMatrices(nan, camera.worldToNDC(), Projection::Perspective), Error);
    EXPECT_THROW(Camera::fromMatrices(camera.worldToCamera(), camera.worldToNDC(), Projection::Orthographic), Error)
        << "the matrices say perspective";
}

TEST(Fpc, ProjectsThroughTheMapAndRaysComeBackThroughItsInverse) {
    const Camera camera = Camera::perspective({0, 0, 10}, {0, 0, 0}, {0, 1, 0}, 60.0, 1.0, 0.5, 100.0);
    const Fpc fpc(camera, std::make_shared<Squared>());
    const Fpc conventional(camera, nullptr);
    for (const glm::dvec3 world : {glm::dvec3(1, 1, 0), glm::dvec3(-3, 2, -5), glm::dvec3(0.5, -1, 4)}) {
        const glm::dvec3 p = camera.project(world), d = fpc.project(world);
        EXPECT_NEAR(d.x, p.x * p.x, 1e-12) << "Equation 1 after the camera";
        EXPECT_NEAR(d.y, p.y, 1e-12);
        EXPECT_NEAR(d.z, p.z, 1e-12) << "the depth is the camera's";
        expectNear(fpc.unproject({d.x, d.y}, d.z), world, 1e-9, "unproject(project)");
        const Ray ray = fpc.ray({d.x, d.y});
        EXPECT_NEAR(glm::length(glm::cross(world - ray.origin, ray.direction)), 0.0, 1e-9) << "the CoNUS ray hits it";
        expectNear(conventional.project(world), p, 0.0, "no map: the camera alone");
    }
}

}  // namespace conus
