// renderReflectionFrame's rays a pixel (ReflectionFrameOptions::samples): one ray is the pixel's
// centre ray; N x N rays converge on the pixel's mean where one ray aliases a texture finer than
// the frame's pixels.
#include "conus/codec/depth/reflection.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "codec/mesh/mesh_test_scenes.h"
#include "conus/codec/mesh/shading.h"
#include "conus/core/error.h"

namespace conus::codec {
namespace {

// A floor at y = -1 (half side 4) striped black and white, `repeat` pairs of stripes across it,
// before a square plane mirror z = 0 facing +z (half side 1) that reflects it; the camera above,
// looking down into the mirror, off its axis.
Mesh stripedFloor(float repeat) {
    Image stripes{2, 1, {"R", "G", "B"}, {0.0f, 0.0f, 0.0f, 1.0f, 1.0f, 1.0f}};
    return test::plane(-1.0f, 4.0f, repeat, stripes);
}
ReflectionFrameOptions mirrorOptions(int samples) {
    ReflectionFrameOptions o;
    o.reflector = test::planeMirrorZ(1.0);
    o.samples = samples;
    o.threads = 1;
    return o;
}
const Camera kCamera = Camera::perspective({0.3, 0.8, 2.5}, {0.0, -0.1, 0.0}, {0, 1, 0}, 40.0, 1.0, 1e-3, 100.0);

// RMS of the colour difference over the pixels where `truth` shows the mirror.
double mirrorRms(const Image& frame, const Image& truth, int* count = nullptr) {
    double sum = 0;
    int n = 0;
    for (int y = 0; y < truth.height; ++y)
        for (int x = 0; x < truth.width; ++x) {
            if (truth.at(x, y, 3) == 0.0f) continue;
            ++n;
            for (int c = 0; c < 3; ++c) sum += std::pow(double(frame.at(x, y, c)) - truth.at(x, y, c), 2);
        }
    if (count) *count = n;
    return std::sqrt(sum / (3.0 * std::max(n, 1)));
}

// One ray a pixel is the ray through the pixel's centre: each pixel the colour of that ray, as
// traced against the mesh (mirror) or shaded (the floor seen directly), exactly.
TEST(ReflectionFrame, OneRayAPixelIsThePixelsCentreRay) {
    const MeshScene scene(stripedFloor(16.0f));
    const ReflectionFrameOptions o = mirrorOptions(1);
    constexpr int kW = 40, kH = 28;  // not square: x and y scale apart
    const Image frame = renderReflectionFrame(scene, nullptr, o.reflector.centre, kCamera, kW, kH, o);
    int mirror = 0, direct = 0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            const glm::dvec2 uv((x + 0.5) / kW, (y + 0.5) / kH);
            const float m = frame.at(x, y, 3);
            glm::vec3 expected;
            if (m == 2.0f) {
                const auto hit = hitReflector(o.reflector, kCamera.ray(uv));
                ASSERT_TRUE(hit) << x << "," << y;
                const auto seen = traceReflectionReference(scene, hit->reflected, o.reflector.centre);
                ASSERT_TRUE(seen) << x << "," << y;
                expected = *seen;
                ++mirror;
            } else if (m == 0.0f) {
                const std::array<float, 5> shaded = shadeRay(scene, kCamera, uv);
                expected = glm::vec3(shaded[0], shaded[1], shaded[2]);
                ++direct;
            } else {
                continue;  // the sky in the mirror
            }
            for (int c = 0; c < 3; ++c) ASSERT_EQ(frame.at(x, y, c), expected[c]) << x << "," << y << " channel " << c;
        }
    EXPECT_GT(mirror, kW * kH / 4);
    EXPECT_GT(direct, 0);
}

// Stripes finer than the pixels: against a 12x12-ray render, one ray a pixel is far off (it takes
// one stripe's colour where the pixel shows several), 3x3 rays much closer and 6x6 closer still.
// The mirror's outline (M) stays where one ray puts it.
TEST(ReflectionFrame, RaysAPixelConvergeWhereOneRayAliases) {
    const MeshScene scene(stripedFloor(96.0f));
    constexpr int kSize = 32;
    const auto render = [&](int samples) {
        const ReflectionFrameOptions o = mirrorOptions(samples);
        return renderReflectionFrame(scene, nullptr, o.reflector.centre, kCamera, kSize, kSize, o);
    };
    const Image one = render(1), three = render(3), six = render(6), fine = render(12);
    int count = 0;
    const double e1 = mirrorRms(one, fine, &count), e3 = mirrorRms(three, fine), e6 = mirrorRms(six, fine);
    ASSERT_GT(count, kSize * kSize / 4);
    std::printf("[ info ] RMS against 12x12 rays a pixel: 1 ray %.4f, 3x3 %.4f, 6x6 %.4f\n", e1, e3, e6);
    EXPECT_GT(e1, 0.1);  // the stripes alias at one ray a pixel
    EXPECT_LT(e3, 0.5 * e1);
    EXPECT_LT(e6, 0.7 * e3);
    // The mask of an odd count is its centre ray's, so 3x3 marks the mirror where one ray does.
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) EXPECT_EQ(three.at(x, y, 3), one.at(x, y, 3)) << x << "," << y;
}

TEST(ReflectionFrame, ACountOfRaysOutsideOneToSixteenIsRefused) {
    const MeshScene scene(stripedFloor(4.0f));
    for (int samples : {0, -1, kMaxFrameSamples + 1}) {
        const ReflectionFrameOptions o = mirrorOptions(samples);
        EXPECT_THROW(renderReflectionFrame(scene, nullptr, o.reflector.centre, kCamera, 8, 8, o), Error) << samples;
    }
}

}  // namespace
}  // namespace conus::codec
