// The faces' eye placed for a viewpoint (placeReflectionEye): the rays a mirror reflects toward
// it, a sphere's virtual image of it, and a placed eye that sees what the mirror shows.
#include "conus/codec/depth/reflection.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "codec/mesh/mesh_test_scenes.h"
#include "conus/codec/mesh/shading.h"
#include "conus/core/error.h"

namespace conus::codec {
namespace {

// The eye placed for a viewpoint: a plane mirror z = 0 facing +z before the occluder and the wall
// (test::boxBeforeWall), seen from beside and above.
Reflector mirrorBeforeOccluder() { return test::planeMirrorZ(1.0); }
const glm::dvec3 kViewpoint(0.6, 0.35, 1.1);

double distanceToLine(glm::dvec3 p, const Ray& ray) {
    const glm::dvec3 v = p - ray.origin;
    return glm::length(v - glm::dot(v, ray.direction) * ray.direction);
}

TEST(ReflectionEye, EveryRayAPlaneMirrorReflectsPassesThroughTheReflectedViewpoint) {
    Reflector r = mirrorBeforeOccluder();
    r.normal = glm::normalize(glm::dvec3(0.2, -0.1, 1.0));  // a tilted mirror, off every axis
    r.centre = {0.3, -0.2, 0.1};
    const glm::dvec3 image = reflectedViewpoint(r, kViewpoint);
    // The mirror image: as far behind the plane as the viewpoint is before it, on its normal.
    EXPECT_NEAR(glm::dot(image - r.centre, r.normal), -glm::dot(kViewpoint - r.centre, r.normal), 1e-12);
    EXPECT_LT(glm::length(glm::cross(kViewpoint - image, r.normal)), 1e-12);
    const std::vector<Ray> rays = reflectedRays(r, kViewpoint, 500);
    ASSERT_EQ(rays.size(), 500u);
    for (const Ray& ray : rays) {
        EXPECT_LT(distanceToLine(image, ray), 1e-9);
        // Each leaves a point of the square mirror, away from it.
        EXPECT_NEAR(glm::dot(ray.origin - r.centre, r.normal), 0.0, 1e-9);
        EXPECT_GT(glm::dot(ray.direction, r.normal), 0.0);
    }
    // No mirror side faces a viewpoint behind the plane or inside the sphere.
    EXPECT_THROW(reflectedRays(r, glm::dvec3(0.0, 0.0, -2.0), 10), Error);
    Reflector sphere;
    sphere.radius = 1.0;
    EXPECT_THROW(reflectedRays(sphere, glm::dvec3(0.2, 0.1, 0.3), 10), Error);
}

TEST(ReflectionEye, ASpheresReflectedViewpointIsItsVirtualImage) {
    Reflector r;
    r.centre = {0.5, -0.4, 0.2};
    r.radius = 2.0;
    const glm::dvec3 axis = glm::normalize(glm::dvec3(0.3, 0.2, 1.0));
    // Far away the image lies at the focus, r/2 before the centre; near the surface, at it.
    EXPECT_NEAR(glm::distance(reflectedViewpoint(r, r.centre + 1e7 * axis), r.centre + axis), 0.0, 1e-5);
    EXPECT_NEAR(glm::distance(reflectedViewpoint(r, r.centre + 2.001 * axis), r.centre + 2.0 * axis), 0.0, 1e-2);
    // Rays from near the axis pass near it (spherical aberration grows with their height).
    const glm::dvec3 viewpoint = r.centre + 9.0 * axis, image = reflectedViewpoint(r, viewpoint);
    int near = 0;
    for (const Ray& ray : reflectedRays(r, viewpoint, 8000, 3)) {
        const double height = glm::length(glm::cross(ray.origin - r.centre, axis));
        if (height > 0.2) continue;
        ++near;
        EXPECT_LT(distanceToLine(image, ray), 2e-3) << height;
    }
    EXPECT_GT(near, 20);
}

// The eye placed at the reflected viewpoint stores the first surface along every ray the mirror
// reflects toward the viewpoint, where the centre's single layer misses the wall behind the box
// and the box's side; the frame from it beats the centre's against the traced reference.
TEST(ReflectionEye, ThePlacedEyeSeesWhatTheMirrorShowsAndItsFrameBeatsTheCentres) {
    const MeshScene scene(test::boxBeforeWall());
    const Reflector mirror = mirrorBeforeOccluder();
    const EyePlacement placed = placeReflectionEye(scene, mirror, kViewpoint, 1);
    // Measured (4000 rays): 2.2% from the centre, none from the placed eye (the reflected
    // viewpoint itself; the frames 22.1 and 26.9 dB).
    EXPECT_GT(placed.centreDisoccluded, 0.01);
    EXPECT_LT(placed.disoccluded, 1e-3);
    EXPECT_EQ(placed.centreDisoccluded, disocclusionFraction(scene, mirror.centre, reflectedRays(mirror, kViewpoint, kViewRays), 1));
    // The eye lies on the segment from the centre to the reflected viewpoint.
    const glm::dvec3 image = reflectedViewpoint(mirror, kViewpoint);
    EXPECT_LT(glm::length(glm::cross(placed.eye - mirror.centre, image - mirror.centre)), 1e-9);
    EXPECT_GT(glm::length(placed.eye - mirror.centre), 0.0);
    // As many layers as the view needs: one there; a bad count is refused.
    EXPECT_EQ(placed.layers, 1);
    EXPECT_EQ(placeReflectionEye(scene, mirror, kViewpoint, 0).layers, 1);
    EXPECT_EQ(placeReflectionEye(scene, mirror, kViewpoint, 3).layers, 3);
    EXPECT_THROW(placeReflectionEye(scene, mirror, kViewpoint, kMaxReflectionLayers + 1), Error);

    const Camera camera = Camera::perspective(kViewpoint, mirror.centre, {0, 1, 0}, 60.0, 1.0, 1e-3, 100.0);
    ReflectionFrameOptions o;
    o.reflector = mirror;
    o.threads = 1;
    double squared[2] = {}, count = 0;
    for (int p = 0; p < 2; ++p) {
        ReflectionBakeOptions bake;
        bake.size = 64;
        bake.centre = p ? placed.eye : mirror.centre;
        bake.roi = AxisBox{test::kOccluderLo, test::kOccluderHi};
        const std::vector<ReflectionFace> faces = bakeReflection(scene, bake);
        // Each against the reference shaded with the headlight at its own eye, as the faces are.
        const Image truth = renderReflectionFrame(scene, nullptr, bake.centre, camera, 64, 64, o);
        const Image frame = renderReflectionFrame(scene, &faces, bake.centre, camera, 64, 64, o);
        for (int y = 0; y < 64; ++y)
            for (int x = 0; x < 64; ++x) {
                if (truth.at(x, y, 3) == 0.0f) continue;
                count += p == 0;
                for (int c = 0; c < 3; ++c) squared[p] += std::pow(frame.at(x, y, c) - truth.at(x, y, c), 2);
            }
    }
    ASSERT_GT(count, 1000);
    const double centreDb = 10 * std::log10(3 * count / squared[0]), placedDb = 10 * std::log10(3 * count / squared[1]);
    EXPECT_GT(placedDb, centreDb + 3.0) << centreDb << " dB from the centre";
}

// A baked texel holds the mean colour of the surface over its footprint, not one point of it: a
// floor under the -y face whose texture alternates black and white columns, three to a texel of a
// 16-texel face (the floor at distance 1 fills the face, parallel to it), bakes to a third or two
// thirds of the white floor's colour in every texel; its centre ray alone would give 0 or 1.
TEST(ReflectionBake, ATexelsColourIsItsFootprintsMeanOverOneSurface) {
    Image stripes{48, 4, {"R", "G", "B"}, std::vector<float>(48 * 4 * 3)};
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 48; ++x)
            for (int c = 0; c < 3; ++c) stripes.at(x, y, c) = float(x % 2);
    Image white = stripes;
    std::fill(white.pixels.begin(), white.pixels.end(), 1.0f);
    ReflectionBakeOptions o;
    o.size = 16;
    o.uniform = true;
    const auto bake = [&](Mesh mesh) { return bakeReflection(MeshScene(std::move(mesh)), o)[3]; };  // ny
    const ReflectionFace striped = bake(test::plane(-1.0f, 1.0f, 1.0f, stripes));
    const ReflectionFace plain = bake(test::plane(-1.0f, 1.0f, 1.0f, white));
    int thirds = 0, twoThirds = 0;
    for (int y = 1; y < 15; ++y)
        for (int x = 1; x < 15; ++x) {
            ASSERT_GT(plain.image.at(x, y, kMeshChannelA), 0.0f);
            EXPECT_EQ(striped.image.at(x, y, kMeshChannelZ), plain.image.at(x, y, kMeshChannelZ));  // the centre ray's
            const float ratio = striped.image.at(x, y, 1) / plain.image.at(x, y, 1);
            EXPECT_GT(ratio, 0.2f) << x << "," << y;
            EXPECT_LT(ratio, 0.8f) << x << "," << y;
            thirds += std::abs(ratio - 1.0f / 3) < 0.05f;
            twoThirds += std::abs(ratio - 2.0f / 3) < 0.05f;
        }
    EXPECT_GT(thirds, 14 * 14 / 3);
    EXPECT_GT(twoThirds, 14 * 14 / 3);

    // Across a silhouette the mean takes only the centre ray's surface: a white square (y = -1,
    // half side 0.4) over a black floor (y = -2): the floor's texels stay black beside it, and the
    // square's keep the colour they have without the floor (up to the shading's scale, which
    // follows the scene's size: one ratio over the whole square, its outline included).
    Mesh both = test::plane(-1.0f, 0.4f);
    Mesh floor = test::plane(-2.0f, 4.0f);
    const auto base = static_cast<std::uint32_t>(both.positions.size());
    both.positions.insert(both.positions.end(), floor.positions.begin(), floor.positions.end());
    both.normals.insert(both.normals.end(), floor.normals.begin(), floor.normals.end());
    for (std::uint32_t i : floor.indices) both.indices.push_back(base + i);
    both.colours.assign(4, glm::vec3(1.0f));
    both.colours.resize(8, glm::vec3(0.0f));
    const ReflectionFace withFloor = bake(both);
    const ReflectionFace square = bake(test::plane(-1.0f, 0.4f));
    const float scale = withFloor.image.at(8, 8, 0) / square.image.at(8, 8, 0);
    int edges = 0;
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) {
            const float z = withFloor.image.at(x, y, kMeshChannelZ);
            if (z > 1.5f) {
                EXPECT_EQ(withFloor.image.at(x, y, 0), 0.0f) << x << "," << y;
            } else {
                EXPECT_NEAR(withFloor.image.at(x, y, 0) / square.image.at(x, y, 0), scale, 1e-4) << x << "," << y;
                edges += x < 15 && withFloor.image.at(x + 1, y, kMeshChannelZ) > 1.5f;
            }
        }
    EXPECT_GT(edges, 0);  // the square's outline crosses the face
}

}  // namespace
}  // namespace conus::codec
