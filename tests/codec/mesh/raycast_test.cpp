// The Embree mesh reference against closed-form answers: a sphere, a plane and a box seen through
// a conventional camera and through an FPC with an off-centre focus: which pixels hit, the camera
// depth of each hit, the headlight shading; multisampling; and the quality claim of the paper:
// decoded CoNUS views beat a uniform render of the same pixel count inside the focus.
#include "conus/codec/mesh/raycast.h"

#include <gtest/gtest.h>

#include "codec/mesh/mesh_test_scenes.h"
#include "conus/codec/image/decode.h"
#include "conus/codec/image/metrics.h"
#include "conus/codec/mesh/shading.h"
#include "conus/core/error.h"
#include "conus/core/limits.h"
#include "conus/sceneio/mesh_file.h"

namespace conus::codec {
namespace {

using namespace test;

constexpr int kW = 96, kH = 64;  // not square: the FPC's aspect matters

Camera testCamera(glm::dvec3 eye, glm::dvec3 target, double aspect = double(kW) / kH) {
    return Camera::perspective(eye, target, {0, 1, 0}, 40, aspect, 0.1, 100);
}

// The identity FPC and one magnifying a disc left of centre, below the middle.
std::vector<Fpc> fpcsOf(const Camera& camera) {
    return {Fpc(camera, nullptr), Fpc(camera, focusMap(0.4, 0.58, 0.15, 3, double(kW) / kH))};
}

glm::dvec2 pixelCentre(int x, int y, int w = kW, int h = kH) { return {(x + 0.5) / w, (y + 0.5) / h}; }

glm::dvec2 undistorted(const Fpc& fpc, glm::dvec2 pd) { return fpc.distortion() ? fpc.distortion()->undistort(pd) : pd; }

float expectedShade(glm::dvec3 normal, glm::dvec3 toEye, double albedo = kDefaultAlbedo) {
    return float(albedo * (kAmbient + (1 - kAmbient) * std::abs(glm::dot(normal, toEye))));
}

TEST(MeshReference, ChannelsAreRGBAZ) {
    const MeshScene scene(sharedBox({-1, -1, -1}, {1, 1, 1}));
    const Image out = renderMeshReference(scene, Fpc(testCamera({0, 0, 5}, {0, 0, 0}), nullptr), 8, 6);
    EXPECT_EQ(out.channels, (std::vector<std::string>{"R", "G", "B", "A", "Z"}));
    EXPECT_EQ(out.width, 8);
    EXPECT_EQ(out.height, 6);
}

TEST(MeshReference, SphereMaskDepthAndShading) {
    const glm::dvec3 centre(0.2, -0.1, 0.0);
    const double radius = 1.0;
    const int rings = 96, segments = 192;
    // The tessellation lies between the sphere and a ball of this radius.
    const double inner = radius * std::cos(kTestPi / rings) * std::cos(kTestPi / segments);
    const MeshScene scene(uvSphere(glm::vec3(centre), float(radius), rings, segments));
    const Camera camera = testCamera({0.6, 0.9, 4.5}, {0, 0, 0});
    int hits[2] = {0, 0}, index = 0;
    for (const Fpc& fpc : fpcsOf(camera)) {
        SCOPED_TRACE(fpc.distortion() ? "foci FPC" : "identity FPC");
        const Image out = renderMeshReference(scene, fpc, kW, kH);
        int checked = 0;
        for (int y = 0; y < kH; ++y)
            for (int x = 0; x < kW; ++x) {
                const glm::dvec2 pd = pixelCentre(x, y);
                const Ray ray = camera.ray(undistorted(fpc, pd));
                const double d = rayDistance(ray, centre);
                const float a = out.at(x, y, kMeshChannelA), z = out.at(x, y, kMeshChannelZ);
                if (a > 0) ++hits[index];
                if (d > radius) {
                    EXPECT_EQ(a, 0.0f) << x << "," << y;
                    EXPECT_EQ(z, float(camera.far()));
                    EXPECT_EQ(out.at(x, y, 0), 0.0f);
                    continue;
                }
                if (d > inner * 0.9999) continue;  // between the sphere and its tessellation
                ASSERT_EQ(a, 1.0f) << x << "," << y;
                ++checked;
                // Depth between the true sphere's and the inner ball's.
                const double tOuter = *hitSphere(ray, centre, radius), tInner = *hitSphere(ray, centre, inner);
                const double zOuter = camera.project(ray.origin + ray.direction * tOuter).z;
                const double zInner = camera.project(ray.origin + ray.direction * tInner).z;
                EXPECT_GE(z, zOuter - 1e-5);
                EXPECT_LE(z, zInner + 1e-5);
                // The point the FPC puts under this pixel at depth Z lies on the surface.
                const glm::dvec3 p = fpc.unproject(pd, z);
                EXPECT_LE(glm::length(p - centre), radius + 1e-4);
                EXPECT_GE(glm::length(p - centre), inner - 1e-4);
                // Headlight with the radial normal (vertex normals are within a facet's angle of it).
                const glm::dvec3 n = glm::normalize(p - centre), toEye = glm::normalize(camera.eye() - p);
                const float shade = expectedShade(n, toEye);
                for (int c = 0; c < 3; ++c) EXPECT_NEAR(out.at(x, y, c), shade, 0.03f);
            }
        EXPECT_GT(checked, 300);
        ++index;
    }
    // The focus sits on the sphere: the CoNUS image gives it more pixels.
    EXPECT_GT(hits[1], hits[0] * 11 / 10);
}

TEST(MeshReference, PlaneDepthAndShadingAreExact) {
    const float y0 = -1.0f;
    const MeshScene scene(plane(y0, 50));
    const Camera camera = testCamera({0.5, 3, 4}, {0.2, 0.5, -8});
    for (const Fpc& fpc : fpcsOf(camera)) {
        SCOPED_TRACE(fpc.distortion() ? "foci FPC" : "identity FPC");
        const Image out = renderMeshReference(scene, fpc, kW, kH);
        int hit = 0, missed = 0;
        for (int y = 0; y < kH; ++y)
            for (int x = 0; x < kW; ++x) {
                const glm::dvec2 pd = pixelCentre(x, y);
                const Ray ray = camera.ray(undistorted(fpc, pd));
                const double t = (y0 - ray.origin.y) / ray.direction.y;
                const glm::dvec3 p = ray.origin + ray.direction * t;
                const bool expectHit = t > 0 && std::abs(p.x) < 50 && std::abs(p.z) < 50 &&
                                       camera.project(p).z < camera.far();
                if (!expectHit) {
                    // The horizon: rays that leave the plane's edge or pass the far plane.
                    if (t > 0 && (std::abs(std::abs(p.x) - 50) < 0.5 || std::abs(std::abs(p.z) - 50) < 0.5)) continue;
                    EXPECT_EQ(out.at(x, y, kMeshChannelA), 0.0f) << x << "," << y;
                    ++missed;
                    continue;
                }
                ++hit;
                ASSERT_EQ(out.at(x, y, kMeshChannelA), 1.0f) << x << "," << y;
                const double depth = camera.project(p).z;
                EXPECT_NEAR(out.at(x, y, kMeshChannelZ), depth, 1e-5 * depth);
                const float shade = expectedShade({0, 1, 0}, glm::normalize(camera.eye() - p));
                for (int c = 0; c < 3; ++c) EXPECT_NEAR(out.at(x, y, c), shade, 1e-5f);
            }
        EXPECT_GT(hit, kW * kH / 2);
        EXPECT_GT(missed, 0) << "the horizon is in view";
    }
}

TEST(MeshReference, OrthographicLightComesFromBehindTheViewer) {
    const MeshScene scene(plane(0.0f, 10));
    const Camera camera = Camera::orthographic({1, 4, 3}, {0, 0, 0}, {0, 1, 0}, 4, double(kW) / kH, -5, 20);
    const Fpc fpc(camera, focusMap(0.6, 0.4, 0.1, 2, double(kW) / kH));
    const Image out = renderMeshReference(scene, fpc, kW, kH);
    const float shade = expectedShade({0, 1, 0}, -camera.forward());
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            const Ray ray = fpc.ray(pixelCentre(x, y));
            const double t = -ray.origin.y / ray.direction.y;
            ASSERT_EQ(out.at(x, y, kMeshChannelA), 1.0f);
            EXPECT_NEAR(out.at(x, y, kMeshChannelZ), camera.project(ray.origin + ray.direction * t).z, 1e-5);
            EXPECT_NEAR(out.at(x, y, 1), shade, 1e-6f);
        }
}

TEST(MeshReference, BoxFacesDepthsAndShading) {
    const glm::dvec3 lo(-1, -0.5, -0.7), hi(0.8, 0.6, 0.9);
    const MeshScene scene(flatBox(glm::vec3(lo), glm::vec3(hi)));
    const Camera camera = testCamera({2.5, 1.8, 3.2}, {0, 0, 0});
    for (const Fpc& fpc : fpcsOf(camera)) {
        SCOPED_TRACE(fpc.distortion() ? "foci FPC" : "identity FPC");
        const Image out = renderMeshReference(scene, fpc, kW, kH);
        int faces[3] = {0, 0, 0};
        const glm::dvec3 margin(1e-3);
        for (int y = 0; y < kH; ++y)
            for (int x = 0; x < kW; ++x) {
                const glm::dvec2 pd = pixelCentre(x, y);
                const Ray ray = camera.ray(undistorted(fpc, pd));
                const float a = out.at(x, y, kMeshChannelA);
                if (!hitBox(ray, lo - margin, hi + margin)) {
                    EXPECT_EQ(a, 0.0f) << x << "," << y;
                    continue;
                }
                const auto inner = hitBox(ray, lo + margin, hi - margin);
                if (!inner) continue;  // grazing an edge
                const auto exact = hitBox(ray, lo, hi);
                ASSERT_TRUE(exact && a == 1.0f) << x << "," << y;
                const glm::dvec3 p = ray.origin + ray.direction * exact->t;
                EXPECT_NEAR(out.at(x, y, kMeshChannelZ), camera.project(p).z, 1e-5);
                glm::dvec3 n(0.0);
                n[exact->axis] = ray.direction[exact->axis] < 0 ? 1 : -1;
                ++faces[exact->axis];
                const float shade = expectedShade(n, glm::normalize(camera.eye() - p));
                for (int c = 0; c < 3; ++c) EXPECT_NEAR(out.at(x, y, c), shade, 1e-5f);
            }
        for (int axis = 0; axis < 3; ++axis) EXPECT_GT(faces[axis], 50) << "three faces in view, axis " << axis;
    }
}

TEST(MeshReference, FourSamplesAreTheTwiceFinerRenderAveraged) {
    const MeshScene scene(uvSphere({0.1f, 0.0f, 0.0f}, 1.0f, 24, 48));
    const Camera camera = testCamera({0.4, 0.5, 3.5}, {0, 0, 0});
    const Fpc identity(camera, nullptr);
    ReferenceOptions four;
    four.samplesPerPixel = 4;
    const Image coarse = renderMeshReference(scene, identity, kW, kH, four);
    const Image fine = renderMeshReference(scene, identity, 2 * kW, 2 * kH);
    int partial = 0, mismatched = 0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            float sum[4] = {0, 0, 0, 0}, zSum = 0, zHits = 0;
            for (int j = 0; j < 2; ++j)
                for (int i = 0; i < 2; ++i) {
                    for (int c = 0; c < 4; ++c) sum[c] += fine.at(2 * x + i, 2 * y + j, c) / 4;
                    if (fine.at(2 * x + i, 2 * y + j, kMeshChannelA) > 0) {
                        zSum += fine.at(2 * x + i, 2 * y + j, kMeshChannelZ);
                        ++zHits;
                    }
                }
            const float a = coarse.at(x, y, kMeshChannelA);
            if (a > 0 && a < 1) ++partial;
            bool same = true;
            for (int c = 0; c < 4; ++c) same = same && std::abs(coarse.at(x, y, c) - sum[c]) < 1e-5f;
            const float z = zHits > 0 ? zSum / zHits : float(camera.far());
            same = same && std::abs(coarse.at(x, y, kMeshChannelZ) - z) < 1e-4f;
            if (!same) ++mismatched;
        }
    EXPECT_GT(partial, 20) << "the silhouette has partly covered pixels";
    EXPECT_LE(mismatched, 2) << "sample positions agree but for rounding on an exact edge";
}

TEST(MeshReference, BadRequests) {
    const MeshScene scene(sharedBox({-1, -1, -1}, {1, 1, 1}));
    const Fpc fpc(testCamera({0, 0, 5}, {0, 0, 0}), nullptr);
    for (int spp : {0, 2, 3, 5, 257, -4}) {
        ReferenceOptions o;
        o.samplesPerPixel = spp;
        EXPECT_THROW(renderMeshReference(scene, fpc, 8, 8, o), Error) << spp;
    }
    EXPECT_THROW(renderMeshReference(scene, fpc, 0, 8), Error);
    Mesh broken = sharedBox({-1, -1, -1}, {1, 1, 1});
    broken.indices[5] = 99;
    EXPECT_THROW(MeshScene{std::move(broken)}, Error);
    EXPECT_THROW(MeshScene{Mesh{}}, Error);
}

// `copies` squares (two triangles each) facing +z, at z = -0.01 i, each shifted sideways by
// `shift` i: a stack the camera on the +z axis sees through.
Mesh stackedSquares(int copies, float shift) {
    Mesh m;
    for (int i = 0; i < copies; ++i) {
        const float z = -0.01f * float(i), d = shift * float(i);
        const auto first = static_cast<std::uint32_t>(m.positions.size());
        for (const glm::vec3 p : {glm::vec3(-1 + d, -1, z), glm::vec3(1 + d, -1, z), glm::vec3(1 + d, 1, z), glm::vec3(-1 + d, 1, z)})
            m.positions.push_back(p);
        for (const std::uint32_t k : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(first + k);
    }
    return m;
}

TEST(MeshReference, SurfacesAlongARayAreCountedUpToTheAskedMost) {
    const MeshScene stack(stackedSquares(40, 0.0f));
    // Through the squares' insides (not their shared diagonal), inside and outside a range.
    const Ray ray{{0.3, -0.2, 5}, {0, 0, -1}};
    EXPECT_EQ(stack.surfacesAlong(ray, 0, 100, 1000), 40);
    EXPECT_EQ(stack.surfacesAlong(ray, 0, 5.0 + 0.095, 1000), 10);  // z = 0 .. -0.09
    EXPECT_EQ(stack.surfacesAlong(ray, 0, 100, 7), 7);
    EXPECT_EQ(stack.surfacesAlong(Ray{{3, 3, 5}, {0, 0, -1}}, 0, 100, 1000), 0);
    // A box: a ray through it crosses two faces; the first-hit query is unchanged by the count.
    const MeshScene box(sharedBox({-1, -1, -1}, {1, 1, 1}));
    const Ray through{{0.3, -0.2, 5}, {0, 0, -1}};
    EXPECT_EQ(box.surfacesAlong(through, 0, 100, 1000), 2);
    const auto hit = box.intersect(through);
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->distance, 4.0, 1e-9);
}

// Overlapping copies of a surface cost every ray one test each: past kMaxMeshOverlap surfaces on
// the average probed ray the render is refused before it starts (both renders); a stack within
// it renders, its front square in front.
TEST(MeshReference, AViewThroughTooManyOverlappingSurfacesIsRefused) {
    // Close enough that the squares fill the view: every probed ray crosses the whole stack.
    const Camera camera = testCamera({0, 0, 1.5}, {0, 0, 0});
    const Fpc fpc(camera, focusMap(0.4, 0.58, 0.15, 3, double(kW) / kH));
    const MeshScene deep(stackedSquares(2 * kMaxMeshOverlap, 1e-4f));
    try {
        renderMeshReference(deep, fpc, kW, kH);
        ADD_FAILURE() << "rendered";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::LimitExceeded);
        EXPECT_NE(std::string(e.what()).find("limit meshOverlap"), std::string::npos) << e.what();
    }
    EXPECT_THROW(renderMeshLayers(deep, fpc, kW, kH, 2), Error);
    const MeshScene within(stackedSquares(kMaxMeshOverlap / 2, 1e-4f));
    const Image out = renderMeshReference(within, fpc, kW, kH);
    EXPECT_EQ(out.at(kW / 2, kH / 2, kMeshChannelA), 1.0f);
    EXPECT_NEAR(out.at(kW / 2, kH / 2, kMeshChannelZ), float(camera.project({0, 0, 0}).z), 1e-5);
}

TEST(MeshReference, ProgressReachesOne) {
    const MeshScene scene(sharedBox({-1, -1, -1}, {1, 1, 1}));
    ReferenceOptions o;
    double last = 0;
    o.progress = [&](double f) { last = std::max(last, f); };
    renderMeshReference(scene, Fpc(testCamera({0, 0, 5}, {0, 0, 0}), nullptr), 32, 40, o);
    EXPECT_DOUBLE_EQ(last, 1.0);
}

// ROI PSNR of a decoded view, CoNUS against uniform, both of n x n pixels with 4 samples each,
// against the 4n x 4n render of the same camera.
struct RoiScores {
    double conus, uniform;
};
RoiScores roiScores(const MeshScene& scene, const Camera& camera, glm::dvec2 focus) {
    const int n = 128, full = 4 * n, roi = 64;
    ReferenceOptions four;
    four.samplesPerPixel = 4;
    const auto map = focusMap(focus.x, focus.y, 0.1, 4, 1.0);
    const Image conus = renderMeshReference(scene, Fpc(camera, map), n, n, four);
    const Image uniform = renderMeshReference(scene, Fpc(camera, nullptr), n, n, four);
    const Image truth = renderMeshReference(scene, Fpc(camera, nullptr), full, full, four);
    // The ROI: roi x roi pixels of the full frame around the focus, on its pixel grid.
    const int x0 = std::clamp(int(focus.x * full) - roi / 2, 0, full - roi);
    const int y0 = std::clamp(int(focus.y * full) - roi / 2, 0, full - roi);
    Image crop = makeImage(roi, roi, truth.channels);
    for (int y = 0; y < roi; ++y)
        for (int x = 0; x < roi; ++x)
            for (int c = 0; c < truth.channelCount(); ++c) crop.at(x, y, c) = truth.at(x0 + x, y0 + y, c);
    DecodeOptions decode;
    decode.view = {double(x0) / full, double(y0) / full, double(x0 + roi) / full, double(y0 + roi) / full};
    decode.width = decode.height = roi;
    const Image conusView = decodeImage(conus, *map, decode);
    const Image uniformView = resizeBilinear(uniform, decode.view, roi, roi);
    return {psnr(conusView, crop), psnr(uniformView, crop)};
}

TEST(MeshReference, CoNUSBeatsUniformInTheFocusOnATexturedPlane) {
    const MeshScene scene(plane(0.0f, 4, 6, conus::test::texture(128, 3)));
    const Camera camera = Camera::perspective({0.3, 2.2, 3.0}, {0, 0, -0.5}, {0, 1, 0}, 45, 1.0, 0.1, 50);
    const RoiScores s = roiScores(scene, camera, {0.42, 0.55});
    std::printf("textured plane ROI PSNR: CoNUS %.2f dB, uniform %.2f dB\n", s.conus, s.uniform);
    EXPECT_GT(s.conus, s.uniform + 4.0) << "CoNUS " << s.conus << " dB, uniform " << s.uniform << " dB";
}

TEST(MeshReference, CoNUSBeatsUniformInTheFocusOnTheBunny) {
    CONUS_REQUIRE_SHARED_MESHES();
    Mesh bunny = sceneio::readMesh((sharedMeshes() / "stanford-bunny.obj").string());
    glm::dvec3 lo(1e300), hi(-1e300);
    std::size_t top = 0;
    for (std::size_t i = 0; i < bunny.positions.size(); ++i) {
        lo = glm::min(lo, glm::dvec3(bunny.positions[i]));
        hi = glm::max(hi, glm::dvec3(bunny.positions[i]));
        if (bunny.positions[i].y > bunny.positions[top].y) top = i;
    }
    const glm::dvec3 centre = (lo + hi) / 2.0;
    const double size = glm::length(hi - lo);
    const Camera camera = Camera::perspective(centre + glm::dvec3(0.25, 0.2, 1.0) * size * 1.3, centre, {0, 1, 0}, 40,
                                              1.0, size * 0.05, size * 10);
    // The focus on the ear tip (the highest vertex), a region of fine geometry.
    const glm::dvec3 ear = camera.project(glm::dvec3(bunny.positions[top]));
    const MeshScene scene(std::move(bunny));
    const RoiScores s = roiScores(scene, camera, {std::clamp(ear.x, 0.1, 0.9), std::clamp(ear.y + 0.05, 0.1, 0.9)});
    std::printf("bunny ROI PSNR: CoNUS %.2f dB, uniform %.2f dB\n", s.conus, s.uniform);
    EXPECT_GT(s.conus, s.uniform + 4.0) << "CoNUS " << s.conus << " dB, uniform " << s.uniform << " dB";
}

}  // namespace
}  // namespace conus::codec
