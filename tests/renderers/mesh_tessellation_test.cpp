// The tessellation stages of the GPU mesh encoder: triangles split where the map bends them
// (MeshRenderOptions::maxBend), against the Embree reference's exact rays, with no cracks between
// triangles that share an edge, and nothing split where the map is affine.
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "conus/codec/builders/foci.h"
#include "conus/codec/image/metrics.h"
#include "conus/codec/mesh/raycast.h"
#include "conus/core/error.h"
#include "conus/renderers/mesh_render.h"
#include "gl_test_util.h"

namespace conus::renderers {
namespace {

using test::contextFor;

constexpr int kWidth = 192, kHeight = 128;

// A floor of 4 x 4 quads (32 triangles sharing edges) wider than the frame, coloured by position
// in two ramps and a stripe, so that a bend shows in the picture and nothing is symmetric.
// `nearEdge` is its edge nearest the camera: 4 keeps every quad the frame shows in front of the
// near plane; 40 runs the floor under and behind the eye, through the near plane (edges with an end
// in front of it are not split).
Mesh floorGrid(float nearEdge = 4.0f) {
    Mesh mesh;
    constexpr int kQuads = 4;
    constexpr float kHalf = 40.0f;
    for (int j = 0; j <= kQuads; ++j)
        for (int i = 0; i <= kQuads; ++i) {
            const float x = -kHalf + 2 * kHalf * i / kQuads, z = -kHalf + (kHalf + nearEdge) * j / kQuads;
            mesh.positions.push_back({x, 0.0f, z});
            mesh.colours.push_back({0.2f + 0.6f * i / kQuads, 0.9f - 0.7f * j / kQuads, (i + 2 * j) % 3 == 0 ? 0.8f : 0.1f});
        }
    for (int j = 0; j < kQuads; ++j)
        for (int i = 0; i < kQuads; ++i) {
            const auto at = [&](int di, int dj) { return static_cast<std::uint32_t>((j + dj) * (kQuads + 1) + i + di); };
            mesh.indices.insert(mesh.indices.end(), {at(0, 0), at(1, 0), at(1, 1), at(0, 0), at(1, 1), at(0, 1)});
        }
    return mesh;
}

// Looking down at the floor at a slant: it fills every pixel.
Camera floorCamera() {
    return Camera::perspective({1.0, 5.0, 6.0}, {-0.5, 0.0, -1.0}, {0, 1, 0}, 50.0, double(kWidth) / kHeight, 0.5, 100.0);
}

// Two strong foci, composed by density as `render mesh --track` does: the whole frame bends.
codec::SamplingMap bentMap() {
    const codec::Focus foci[] = {{0.3, 0.4, 0.1, 4.0}, {0.72, 0.62, 0.08, 3.0}};
    codec::FociOptions options;
    options.aspect = double(kWidth) / kHeight;
    return codec::buildFociMap(foci, options);
}

MeshRenderOptions withBend(double maxBend, int samples = 1) {
    MeshRenderOptions options;
    options.maxBend = maxBend;
    options.samples = samples;
    return options;
}

class MeshTessellation : public ::testing::TestWithParam<Backend> {};

TEST_P(MeshTessellation, FollowsTheMapWhereItBends) {
    const Mesh mesh = floorGrid();
    const Camera camera = floorCamera();
    const auto map = std::make_shared<codec::SamplingMap>(bentMap());
    const Image reference = codec::renderMeshReference(codec::MeshScene(Mesh(mesh)), Fpc(camera, map), kWidth, kHeight);
    MeshRenderer renderer(contextFor(GetParam()), mesh);
    std::int64_t straight = 0, loose = 0, tight = 0, byDefault = 0;
    const double psnrStraight = codec::psnr(renderer.render(camera, *map, kWidth, kHeight, withBend(0), nullptr, &straight), reference);
    const double psnrLoose = codec::psnr(renderer.render(camera, *map, kWidth, kHeight, withBend(4), nullptr, &loose), reference);
    const double psnrTight = codec::psnr(renderer.render(camera, *map, kWidth, kHeight, withBend(0.25), nullptr, &tight), reference);
    const double psnrDefault =
        codec::psnr(renderer.render(camera, *map, kWidth, kHeight, withBend(kDefaultMaxBend), nullptr, &byDefault), reference);
    std::printf("floor: as built %lld triangles %.2f dB; --max-bend 4: %lld %.2f dB; default: %lld %.2f dB; 0.25: %lld %.2f dB\n",
                static_cast<long long>(straight), psnrStraight, static_cast<long long>(loose), psnrLoose,
                static_cast<long long>(byDefault), psnrDefault, static_cast<long long>(tight), psnrTight);
    EXPECT_EQ(straight, static_cast<std::int64_t>(mesh.triangleCount()));
    EXPECT_GT(loose, straight);
    EXPECT_GT(byDefault, loose);
    EXPECT_GT(tight, byDefault);
    EXPECT_LT(psnrStraight, 40.0);  // straight tiles across a bent frame
    EXPECT_GT(psnrLoose, psnrStraight + 10.0);
    EXPECT_GT(psnrDefault, psnrLoose + 5.0);
    EXPECT_GE(psnrDefault, 50.0);
    EXPECT_GE(psnrTight, psnrDefault - 0.2);
}

// Every pixel sees the floor, so every pixel must be covered: a crack between two triangles that
// split a shared edge differently (or placed its new vertices apart) would let the clear colour in.
TEST_P(MeshTessellation, LeavesNoCracksBetweenTriangles) {
    for (const float nearEdge : {4.0f, 40.0f}) {
        MeshRenderer renderer(contextFor(GetParam()), floorGrid(nearEdge));
        for (const int samples : {1, 4}) {
            const Image frame = renderer.render(floorCamera(), bentMap(), kWidth, kHeight, withBend(kDefaultMaxBend, samples));
            const int a = frame.channelIndex("A");
            int uncovered = 0;
            for (int y = 0; y < kHeight; ++y)
                for (int x = 0; x < kWidth; ++x) uncovered += frame.at(x, y, a) < 1.0f;
            EXPECT_EQ(uncovered, 0) << samples << " samples a pixel, the floor's near edge at " << nearEdge;
        }
    }
}

// Nothing is split where the map is affine (by the renderer's check, and by the levels it would
// compute: every second difference is 0).
TEST_P(MeshTessellation, AnAffineMapDrawsTheMeshAsItIs) {
    const Mesh mesh = floorGrid();
    MeshRenderer renderer(contextFor(GetParam()), mesh);
    std::int64_t drawn = 0;
    const Image identity = renderer.render(floorCamera(), codec::SamplingMap::identity(9, 7), kWidth, kHeight, {}, nullptr, &drawn);
    EXPECT_EQ(drawn, static_cast<std::int64_t>(mesh.triangleCount()));
    const Image asBuilt = renderer.render(floorCamera(), codec::SamplingMap::identity(2, 2), kWidth, kHeight, withBend(0, 4));
    EXPECT_LT(codec::meanSquaredError(identity, asBuilt), 1e-12);  // rounding in Equation 1 alone
}

// A triangle wholly beyond one side of the view volume is dropped before it is split: a second
// floor off to the side of the frame adds no triangle drawn and changes no pixel.
TEST_P(MeshTessellation, DropsTrianglesOutsideTheFrame) {
    const Mesh floor = floorGrid();
    Mesh twoFloors = floor;
    const auto first = static_cast<std::uint32_t>(floor.positions.size());
    for (std::size_t i = 0; i < floor.positions.size(); ++i) {
        twoFloors.positions.push_back(floor.positions[i] + glm::vec3(200.0f, 0.0f, 0.0f));
        twoFloors.colours.push_back(floor.colours[i]);
    }
    for (const std::uint32_t index : floor.indices) twoFloors.indices.push_back(first + index);
    std::int64_t one = 0, two = 0;
    const auto draw = [&](const Mesh& mesh, std::int64_t& drawn) {
        return MeshRenderer(contextFor(GetParam()), mesh).render(floorCamera(), bentMap(), kWidth, kHeight, {}, nullptr, &drawn);
    };
    const Image alone = draw(floor, one), beside = draw(twoFloors, two);
    EXPECT_GT(one, static_cast<std::int64_t>(floor.triangleCount()));  // the floor in view is split
    EXPECT_EQ(two, one);
    EXPECT_EQ(codec::meanSquaredError(alone, beside), 0.0);
}

TEST_P(MeshTessellation, BadBoundsAreRefused) {
    MeshRenderer renderer(contextFor(GetParam()), floorGrid());
    for (const double bad : {-0.5, std::nan(""), HUGE_VAL})
        EXPECT_THROW(renderer.render(floorCamera(), bentMap(), kWidth, kHeight, withBend(bad)), Error) << bad;
}

INSTANTIATE_TEST_SUITE_P(MeshGl, MeshTessellation, ::testing::Values(Backend::Egl, Backend::OsMesa), test::paramName);

}  // namespace
}  // namespace conus::renderers
