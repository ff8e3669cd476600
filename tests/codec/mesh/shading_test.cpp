// The shading rule: which albedo wins, the headlight formula, bilinear repeat texture lookups.
#include "conus/codec/mesh/shading.h"

#include <gtest/gtest.h>

namespace conus::codec {
namespace {

Image checker2x2() {
    Image t = makeImage(2, 2, {"R", "G", "B"});
    const float values[2][2] = {{0.1f, 0.5f}, {0.9f, 0.3f}};  // [y][x]
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 2; ++x) {
            t.at(x, y, 0) = values[y][x];
            t.at(x, y, 1) = 1 - values[y][x];
            t.at(x, y, 2) = 0.25f * (x + 1) * (y + 1);
        }
    return t;
}

TEST(Shading, Headlight) {
    const glm::vec3 albedo(0.2f, 0.5f, 0.9f), n(0, 0, 1);
    EXPECT_EQ(shadeHeadlight(albedo, n, {0, 0, 1}), albedo);
    EXPECT_EQ(shadeHeadlight(albedo, n, {0, 0, -1}), albedo);  // two-sided
    const glm::vec3 grazing = shadeHeadlight(albedo, n, {1, 0, 0});
    EXPECT_NEAR(grazing.g, 0.5f * kAmbient, 1e-7f);
    const glm::vec3 at60 = shadeHeadlight(albedo, n, glm::normalize(glm::vec3(std::sqrt(3.0f), 0, 1)));
    EXPECT_NEAR(at60.b, 0.9f * (kAmbient + (1 - kAmbient) * 0.5f), 1e-6f);
}

TEST(Shading, DirectionToTheEye) {
    const Camera persp = Camera::perspective({1, 2, 3}, {0, 0, 0}, {0, 1, 0}, 45, 1, 0.1, 10);
    const glm::dvec3 l = directionToEye(persp, {0.5, -1, 0});
    EXPECT_NEAR(glm::length(l - glm::normalize(glm::dvec3(0.5, 3, 3))), 0, 1e-12);
    const Camera ortho = Camera::orthographic({1, 2, 3}, {0, 0, 0}, {0, 1, 0}, 2, 1, -1, 10);
    EXPECT_NEAR(glm::length(directionToEye(ortho, {5, 5, 5}) + ortho.forward()), 0, 1e-12);
}

TEST(Shading, TextureIsBilinearBetweenTexelCentresAndRepeats) {
    const Image t = checker2x2();
    // Texel centres.
    EXPECT_NEAR(sampleTexture(t, {0.25f, 0.25f}).r, 0.1f, 1e-6f);
    EXPECT_NEAR(sampleTexture(t, {0.75f, 0.25f}).r, 0.5f, 1e-6f);
    EXPECT_NEAR(sampleTexture(t, {0.25f, 0.75f}).r, 0.9f, 1e-6f);
    EXPECT_NEAR(sampleTexture(t, {0.75f, 0.75f}).b, 1.0f, 1e-6f);
    // Between two centres: the mean.
    EXPECT_NEAR(sampleTexture(t, {0.5f, 0.25f}).r, 0.3f, 1e-6f);
    // A corner: all four, wrapped.
    EXPECT_NEAR(sampleTexture(t, {0.0f, 0.0f}).r, (0.1f + 0.5f + 0.9f + 0.3f) / 4, 1e-6f);
    // Repeat: whole periods away is the same.
    const glm::vec3 a = sampleTexture(t, {0.3f, 0.6f}), b = sampleTexture(t, {2.3f, -1.4f});
    EXPECT_NEAR(glm::length(a - b), 0.0f, 1e-5f);
    // A quarter of the way from (0.25,0.25) to (0.75,0.25).
    EXPECT_NEAR(sampleTexture(t, {0.375f, 0.25f}).g, 1 - (0.75f * 0.1f + 0.25f * 0.5f), 1e-6f);
}

TEST(Shading, AlbedoPrefersColoursThenTextureThenGrey) {
    Mesh m;
    m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    m.indices = {0, 1, 2};
    EXPECT_EQ(meshAlbedo(m, 0, 0.3f, 0.3f), glm::vec3(kDefaultAlbedo));
    m.uvs = {{0.25f, 0.25f}, {0.75f, 0.25f}, {0.25f, 0.75f}};
    m.texture = checker2x2();
    EXPECT_NEAR(meshAlbedo(m, 0, 1, 0).r, 0.5f, 1e-6f);  // corner 1's UV: texel (1,0)
    EXPECT_NEAR(meshAlbedo(m, 0, 0, 1).r, 0.9f, 1e-6f);
    m.colours = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    const glm::vec3 c = meshAlbedo(m, 0, 0.2f, 0.3f);
    EXPECT_NEAR(c.r, 0.5f, 1e-6f);
    EXPECT_NEAR(c.g, 0.2f, 1e-6f);
    EXPECT_NEAR(c.b, 0.3f, 1e-6f);
    EXPECT_EQ(meshChannelNames(), (std::vector<std::string>{"R", "G", "B", "A", "Z"}));
}

}  // namespace
}  // namespace conus::codec
