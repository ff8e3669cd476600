// Depth images in the viewer, on a real file: `conus render mesh` of a square floor (the plane
// y = 0) seen from above and in front through a focus. The inspector's 3-D point must lie on the
// plane where the camera's exact ray meets it, the Z picture must be bright near and dark far with
// the background marked, and the window (under Xvfb) must show and inspect the same.
#include <algorithm>
#include <cstdlib>
#include <regex>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include "conus/codec/image/decode.h"
#include "depth_view.h"
#include "document.h"
#include "inspector.h"
#include "sanitizers.h"
#include "oiio_picture.h"
#include "viewer_test_util.h"

namespace conus::viewer {
namespace {

namespace fs = std::filesystem;

constexpr double kHalf = 1.0;  // the floor is [-1, 1] x [-1, 1] at y = 0
constexpr int kWidth = 192, kHeight = 144;
const char* const kCamera = "0.3,1.6,2.4,0,0,-0.2,45";  // eye, look-at, vertical field of view
const char* const kFocus = "0.55,0.6,0.12,3";

// The floor as an OBJ, split into a 16 x 16 grid of quads so the rasterized plane follows Equation 1's curves.
std::string floorObj() {
    const fs::path path = test::tempDir() / "floor.obj";
    if (fs::exists(path)) return path.string();
    std::string text;
    constexpr int n = 16;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i)
            text += "v " + std::to_string(-kHalf + 2 * kHalf * i / n) + " 0 " + std::to_string(-kHalf + 2 * kHalf * j / n) + "\n";
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const int a = j * (n + 1) + i + 1, b = a + 1, c = a + n + 1, d = c + 1;
            // Counter-clockwise seen from above (+y).
            text += "f " + std::to_string(a) + " " + std::to_string(c) + " " + std::to_string(b) + "\n";
            text += "f " + std::to_string(b) + " " + std::to_string(c) + " " + std::to_string(d) + "\n";
        }
    test::writeText(path, text);
    return path.string();
}

std::string conusBinary() { return std::string(CONUS_BIN_DIR) + "/conus"; }

// Rendered once per process by the real command, with the `add` composition the probe's
// tolerances below were set for (density, `render mesh`'s default, compresses this context more:
// 2.4e-3 of the distance at the worst probe).
const std::string& floorDepthImage() {
    static const std::string path = [] {
        const std::string out = (test::tempDir() / "floor.exr").string();
        std::string log;
        const int status = test::run(conusBinary() + " render mesh " + floorObj() + " -o " + out + " --size " +
                                         std::to_string(kWidth) + "x" + std::to_string(kHeight) + " --camera " + kCamera +
                                         " --focus " + kFocus + " --max-edge 0.5 --compose add --quiet",
                                     &log);
        EXPECT_EQ(status, 0) << log;
        return out;
    }();
    return path;
}

// Where the camera's ray through undistorted uv meets the plane y = 0 (nullopt: it does not, in front).
std::optional<glm::dvec3> rayOnFloor(const Camera& camera, glm::dvec2 uv) {
    const Ray ray = camera.ray(uv);
    if (!(ray.direction.y < 0)) return std::nullopt;
    return ray.origin + ray.direction * (-ray.origin.y / ray.direction.y);
}

TEST(DepthView, InspectorGivesThePointOnThePlane) {
    const Document doc = loadDocument(floorDepthImage());
    ASSERT_TRUE(doc.ok()) << doc.error;
    ASSERT_TRUE(doc.file->camera.has_value());
    const Camera camera = format::toCamera(*doc.file->camera);
    int onFloor = 0, background = 0;
    for (int j = 1; j < 24; ++j)
        for (int i = 1; i < 24; ++i) {
            const glm::dvec2 uv(i / 24.0, j / 24.0);  // undistorted, as the cursor gives it
            const Probe p = probe(*doc.file, *doc.map, uv);
            ASSERT_TRUE(p.depthImage);
            // The CoNUS pixel the probe read, undistorted by the exact inverse: its ray is the one to test.
            const glm::dvec2 centre((p.conusPixel.x + 0.5) / kWidth, (p.conusPixel.y + 0.5) / kHeight);
            const glm::dvec2 sampleUv = doc.map->undistort(centre);
            const std::optional<glm::dvec3> expected = rayOnFloor(camera, sampleUv);
            const bool inside = expected && std::abs(expected->x) < kHalf - 0.03 && std::abs(expected->z) < kHalf - 0.03;
            const bool outside = !expected || std::abs(expected->x) > kHalf + 0.03 || std::abs(expected->z) > kHalf + 0.03;
            if (inside) {
                ASSERT_TRUE(p.world.has_value()) << "uv " << uv.x << "," << uv.y;
                EXPECT_NEAR(p.world->y, 0.0, 2e-3) << "on the plane";
                EXPECT_LT(glm::length(*p.world - *expected), 2e-3 * glm::length(*expected - camera.eye()))
                    << "uv " << uv.x << "," << uv.y;
                // The point lies on the cursor's side: it projects back to the sample's undistorted position.
                const glm::dvec3 back = camera.project(*p.world);
                EXPECT_LT(glm::length(glm::dvec2(back) - sampleUv), 1e-4);
                EXPECT_NE(formatProbe(p).find(" P=("), std::string::npos);
                ++onFloor;
            } else if (outside) {
                EXPECT_FALSE(p.world.has_value()) << "background at uv " << uv.x << "," << uv.y;
                EXPECT_NE(formatProbe(p).find(" P=background"), std::string::npos);
                ++background;
            }
        }
    EXPECT_GT(onFloor, 100);
    EXPECT_GT(background, 20);
}

double luminance(const Image& im, int x, int y) { return 0.2126 * im.at(x, y, 0) + 0.7152 * im.at(x, y, 1) + 0.0722 * im.at(x, y, 2); }

TEST(DepthView, PictureIsBrightNearDarkFarAndMarksTheBackground) {
    const format::ConusFile file = format::readConusFile(floorDepthImage());
    const format::ConusFile picture = depthPicture(file);
    ASSERT_EQ(picture.image.width, file.image.width);
    EXPECT_EQ(picture.map.xy, file.map.xy) << "the same map: the viewer decodes it like the colour";
    const int z = file.image.channelIndex("Z");
    std::vector<std::pair<float, double>> byDepth;  // (Z, picture luminance)
    int background = 0;
    for (int y = 0; y < file.image.height; ++y)
        for (int x = 0; x < file.image.width; ++x) {
            if (validDepth(file, x, y)) {
                byDepth.emplace_back(file.image.at(x, y, z), luminance(picture.image, x, y));
            } else {
                ++background;
                for (int c = 0; c < 3; ++c) EXPECT_EQ(picture.image.at(x, y, c), kDepthBackground[c]);
            }
        }
    ASSERT_GT(byDepth.size(), 1000u);
    EXPECT_GT(background, 1000);
    std::sort(byDepth.begin(), byDepth.end());
    // The inferno ramp's luminance rises along it; near is its bright end: luminance falls with Z.
    for (std::size_t k = 1; k < byDepth.size(); ++k)
        ASSERT_LE(byDepth[k].second, byDepth[k - 1].second + 1e-6) << "Z " << byDepth[k - 1].first << " -> " << byDepth[k].first;
    EXPECT_GT(byDepth.front().second, 0.8) << "the nearest is the ramp's bright end";
    EXPECT_LT(byDepth.back().second, 0.01) << "the farthest is its dark end";
}

TEST(DepthView, NoZChannelIsAnError) {
    EXPECT_THROW(depthPicture(test::conusFile()), Error);
    EXPECT_FALSE(probe(test::conusFile(), codec::SamplingMap::fromGrid(test::conusFile().map), {0.5, 0.5}).depthImage);
}

Image readPicture(const fs::path& path) { return conus::test::readPictureWithOiio(path.string()); }

// Mean luminance of the screenshot's pixels (a fitted view: pixel (x, y) shows undistorted
// ((x+.5)/W, (y+.5)/H)) where the camera sees the floor at depths within [lo, hi).
double meanAt(const Image& shot, const format::ConusFile& file, double lo, double hi) {
    const Camera camera = format::toCamera(*file.camera);
    double sum = 0;
    int n = 0;
    for (int y = 0; y < shot.height; ++y)
        for (int x = 0; x < shot.width; ++x) {
            const glm::dvec2 uv((x + 0.5) / shot.width, (y + 0.5) / shot.height);
            const std::optional<glm::dvec3> p = rayOnFloor(camera, uv);
            if (!p || std::abs(p->x) > kHalf - 0.05 || std::abs(p->z) > kHalf - 0.05) continue;
            const double depth = camera.project(*p).z;
            if (depth < lo || depth >= hi) continue;
            sum += luminance(shot, x, y);
            ++n;
        }
    return n ? sum / n : -1;
}

TEST(DepthView, ScreenshotInZModeIsBrightNearDarkFar) {
    const fs::path out = test::tempDir() / "floor-z.png";
    std::string log;
    ASSERT_EQ(test::run("env -u DISPLAY " + test::viewerBinary() + " " + floorDepthImage() + " --mode z --screenshot " +
                            out.string() + " --size " + std::to_string(kWidth) + "x" + std::to_string(kHeight),
                        &log),
              0)
        << log;
    const Image shot = readPicture(out);
    ASSERT_EQ(shot.width, kWidth);
    const format::ConusFile file = format::readConusFile(floorDepthImage());
    const DepthSpan span = depthSpan(file);
    const double third = (span.farthest - span.nearest) / 3;
    const double nearMean = meanAt(shot, file, span.nearest, span.nearest + third);
    const double farMean = meanAt(shot, file, span.farthest - third, span.farthest);
    ASSERT_GE(nearMean, 0);
    ASSERT_GE(farMean, 0);
    EXPECT_GT(nearMean, farMean + 0.3) << "near " << nearMean << " far " << farMean;
    // The top-left corner sees past the floor: the background's blue.
    EXPECT_GT(shot.at(2, 2, 2), shot.at(2, 2, 0) + 0.1);
}

// The window: Z key, `inspect` of the floor and of the sky, the status bar's mode.
TEST(DepthView, WindowInspectsThePointUnderTheCursor) {
    ASSERT_TRUE(test::haveXvfb()) << "xvfb-run is needed (package xvfb)";
    const fs::path script = test::tempDir() / "depth.txt";
    const fs::path shot = test::tempDir() / "depth-window.png";
    // The window is the frame's size: the fitted view maps window pixel (x, y) to uv ((x+.5)/W, (y+.5)/H).
    test::writeText(script, "key Z\ninspect 96 110\ninspect 3 3\nscreenshot " + shot.string() + "\n");
    std::string log;
    const std::string command = "xvfb-run -a -s '-screen 0 1024x768x24' " + conus::testing::glxLeakCheckPrefix() +
                                test::viewerBinary() + " " + floorDepthImage() + " --window " + std::to_string(kWidth) + "x" +
                                std::to_string(kHeight) + " --script " + script.string();
    ASSERT_EQ(test::run(command, &log), 0) << log;
    const std::regex point(R"(P=\(([-0-9.e]+),([-0-9.e]+),([-0-9.e]+)\))");
    std::smatch m;
    ASSERT_TRUE(std::regex_search(log, m, point)) << log;
    const glm::dvec3 p(std::stod(m[1]), std::stod(m[2]), std::stod(m[3]));
    // The window says which undistorted position it inspected; the file, probed there, gives the point.
    const std::regex position(R"(u,v=\(([-0-9.e]+),([-0-9.e]+)\))");
    std::smatch at;
    ASSERT_TRUE(std::regex_search(log, at, position)) << log;
    const glm::dvec2 uv(std::stod(at[1]), std::stod(at[2]));
    EXPECT_NEAR(uv.x, 96.0 / kWidth, 1.0 / kWidth);
    EXPECT_NEAR(uv.y, 110.0 / kHeight, 1.0 / kHeight);
    const Document doc = loadDocument(floorDepthImage());
    const Probe expected = probe(*doc.file, *doc.map, uv);
    ASSERT_TRUE(expected.world.has_value());
    EXPECT_LT(glm::length(p - *expected.world), 1e-3) << log;
    EXPECT_NEAR(p.y, 0.0, 2e-3);
    EXPECT_NE(log.find("P=background"), std::string::npos) << log;
    const Image window = readPicture(shot);
    ASSERT_EQ(window.width, kWidth);
    EXPECT_GT(luminance(window, 96, 120), luminance(window, 96, 60)) << "the near floor (lower) is brighter than the far";
}

}  // namespace
}  // namespace conus::viewer
