#include "conus/renderers/terrain.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "conus/codec/depth/heightfield.h"
#include "conus/codec/image/metrics.h"
#include "conus/core/error.h"
#include "gl_test_util.h"

namespace conus::renderers {
namespace {

using test::contextFor;

constexpr int kFrameWidth = 256, kFrameHeight = 192;

// Metres: eye 150 m up, the field from 200 m to 6 km in front of the viewer.
codec::GroundParams testGround() { return {150.0, 200.0, 6000.0, 60.0}; }

class Terrain : public ::testing::TestWithParam<Backend> {};

TEST_P(Terrain, FlatFieldHorizonWhereTheCameraPutsIt) {
    Context& context = contextFor(GetParam());
    const codec::GroundParams ground = testGround();
    const glm::dvec2 extent = codec::fieldExtent(ground);
    Image dem = makeImage(32, 32, {"Z"});
    const Image colour = codec::terrainColours(dem, extent);
    const Mesh mesh = codec::undistortHeightField(codec::uniformHeightField(dem, colour, 32, 32), extent);

    // Level camera 600 m up at the viewer: the far edge (distance `far`) lies atan(600 / far)
    // below the horizon, i.e. (h/2) * tan(angle) / tan(fovY/2) rows below the frame's middle.
    const glm::dvec3 eye{0.5 * extent.x, 600.0, extent.y + ground.near};
    const double fovYDegrees = 50.0;
    const Camera camera = Camera::perspective(eye, eye + glm::dvec3(0, 0, -1), {0, 1, 0}, fovYDegrees,
                                              double(kFrameWidth) / kFrameHeight, 1.0, 1e5);
    TerrainLook look;
    const Image frame = renderTerrain(context, mesh, camera, kFrameWidth, kFrameHeight, look);
    ASSERT_EQ(frame.width, kFrameWidth);
    ASSERT_EQ(frame.channels, (std::vector<std::string>{"R", "G", "B"}));
    const double predicted = 0.5 * kFrameHeight + 0.5 * kFrameHeight * (600.0 / ground.far) /
                                                      std::tan(0.5 * fovYDegrees * 3.14159265358979 / 180.0);
    // The edge: where the centre column stops being (mostly) sky, top row first.
    const int x = kFrameWidth / 2;
    double edge = -1;
    for (int y = 0; y < kFrameHeight; ++y) {
        const double skyness = (frame.at(x, y, 2) - frame.at(x, kFrameHeight - 1, 2)) /
                               (look.sky.b - frame.at(x, kFrameHeight - 1, 2));
        if (skyness < 1.0 - 1e-3) {
            edge = y + skyness;  // a partly covered pixel says where inside it the edge runs
            break;
        }
    }
    EXPECT_NEAR(edge, predicted, 1.0) << "predicted row " << predicted;
    EXPECT_NEAR(frame.at(x, 0, 0), look.sky.r, 1e-6);
    EXPECT_NEAR(frame.at(0, kFrameHeight - 1, 1), frame.at(kFrameWidth - 1, kFrameHeight - 1, 1), 1e-4);
    // The ground is lit from above: darker than its colour, brighter than ambient alone.
    EXPECT_LT(frame.at(x, kFrameHeight - 1, 1), colour.at(0, 0, 1) + 1e-4);
    EXPECT_GT(frame.at(x, kFrameHeight - 1, 1), look.ambient * colour.at(0, 0, 1));
}

TEST_P(Terrain, RendererKeepsMeshAcrossFramesAndSizes) {
    Context& context = contextFor(GetParam());
    codec::TerrainOptions options;
    options.width = options.height = 64;
    const Image dem = codec::generateTerrain(options);
    const glm::dvec2 extent = codec::fieldExtent(testGround());
    const Mesh mesh =
        codec::undistortHeightField(codec::uniformHeightField(dem, codec::terrainColours(dem, extent), 64, 64), extent);
    TerrainRenderer renderer(context, mesh);
    const Camera camera = viewerCamera(testGround(), dem.at(32, 63), 64.0 / 48.0);
    const Image a = renderer.render(camera, 64, 48);
    const Image b = renderer.render(camera, 32, 24);
    const Image c = renderer.render(camera, 64, 48);
    EXPECT_EQ(a.pixels, c.pixels);
    EXPECT_EQ(b.width, 32);
    EXPECT_THROW(renderer.render(camera, 0, 10), Error);
    EXPECT_THROW(viewerCamera(testGround(), dem.at(32, 63), 0.0), Error) << "a camera without an aspect";
    EXPECT_THROW(renderTerrain(context, Mesh{}, camera, 8, 8), Error);
}

// Figure 5 of the paper: frames near the viewer from the CoNUS height field are closer to the
// full-resolution reference than frames from a uniform height field of the same sample count.
TEST_P(Terrain, ConusBeatsUniformNearTheViewer) {
    Context& context = contextFor(GetParam());
    const codec::GroundParams ground = testGround();
    const glm::dvec2 extent = codec::fieldExtent(ground);
    codec::TerrainOptions options;
    options.width = options.height = 512;
    options.seed = 11;
    const Image dem = codec::generateTerrain(options);
    const Image colour = codec::terrainColours(dem, extent);
    const int samples = 128;
    codec::HeightFieldOptions encode;
    encode.ground = ground;
    encode.width = encode.height = samples;
    const Mesh full = codec::undistortHeightField(codec::uniformHeightField(dem, colour, 512, 512), extent);
    const Mesh conus = codec::undistortHeightField(codec::encodeHeightField(dem, colour, encode));
    const Mesh uniform =
        codec::undistortHeightField(codec::uniformHeightField(dem, colour, samples, samples), extent);

    TerrainRenderer fullRenderer(context, full), conusRenderer(context, conus), uniformRenderer(context, uniform);
    const double groundHeight = dem.at(255, 511);
    const double aspect = double(kFrameWidth) / kFrameHeight;
    const std::array<Camera, 3> poses = {viewerCamera(ground, groundHeight, aspect),
                                         viewerCamera(ground, groundHeight, aspect, 300.0, 10.0),
                                         viewerCamera(ground, groundHeight, aspect, -200.0, -15.0)};
    for (std::size_t i = 0; i < poses.size(); ++i) {
        const Image reference = fullRenderer.render(poses[i], kFrameWidth, kFrameHeight);
        const double conusPsnr = codec::psnr(conusRenderer.render(poses[i], kFrameWidth, kFrameHeight), reference);
        const double uniformPsnr = codec::psnr(uniformRenderer.render(poses[i], kFrameWidth, kFrameHeight), reference);
        std::printf("pose %zu: PSNR vs full resolution: CoNUS %.2f dB, uniform %.2f dB\n", i, conusPsnr, uniformPsnr);
        if (i == 0) {
            EXPECT_GT(conusPsnr, uniformPsnr + 1.0);
        }
    }
}

INSTANTIATE_TEST_SUITE_P(TerrainGl, Terrain, ::testing::Values(Backend::Egl, Backend::OsMesa), test::paramName);

// The real DEM (matplotlib's Jacksboro fault sample, Debian python-matplotlib-data) through the
// `conus heightfield` command: encode, render with --compare, CoNUS beats uniform.
TEST(TerrainRealDem, JacksboroThroughTheCli) {
    const std::string dem = "/usr/share/matplotlib/mpl-data/sample_data/jacksboro_fault_dem.npz";
    const std::string conus = std::string(CONUS_BIN_DIR) + "/conus";
    if (!std::filesystem::exists(dem)) GTEST_SKIP() << "skipped: " << dem << " is missing (apt-get install python-matplotlib-data)";
    if (!std::filesystem::exists(conus)) GTEST_SKIP() << "skipped: " << conus << " is not built";
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "conus_terrain_test";
    std::filesystem::create_directories(dir);
    const std::string exr = (dir / "jacksboro.exr").string(), png = (dir / "frame.png").string(),
                      log = (dir / "log.txt").string();
    const std::string encode = conus + " heightfield encode " + dem + " -o " + exr +
                               " --size 128x128 --eye-height 1500 --near 500 --far 30000 > " + log + " 2>&1";
    ASSERT_EQ(std::system(encode.c_str()), 0) << encode;
    const std::string render = conus + " render heightfield " + exr + " -o " + png + " --size 256x192 --compare " +
                               dem + " > " + log + " 2>&1";
    ASSERT_EQ(std::system(render.c_str()), 0) << render;
    std::ifstream in(log);
    std::stringstream text;
    text << in.rdbuf();
    double conusPsnr = 0, uniformPsnr = 0;
    const std::string all = text.str();
    const auto at = all.find("PSNR vs full resolution: CoNUS ");
    ASSERT_NE(at, std::string::npos) << all;
    ASSERT_EQ(std::sscanf(all.c_str() + at, "PSNR vs full resolution: CoNUS %lf dB, uniform %lf dB", &conusPsnr,
                          &uniformPsnr),
              2)
        << all;
    std::printf("Jacksboro: CoNUS %.2f dB, uniform %.2f dB\n", conusPsnr, uniformPsnr);
    EXPECT_GT(conusPsnr, uniformPsnr);
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace conus::renderers
