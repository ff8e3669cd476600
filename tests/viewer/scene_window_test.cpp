// The 3-D modes as a user runs them: conus-view --mesh / --volume / --relief under Xvfb, driven by
// --script (orbit, drag a focus, toggle, screenshot). The window must show exactly the frame the
// GPU renderers make for the camera and map of the scene state (the CoNUS image itself), and each
// command must change the picture the way it says.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include "conus/core/display.h"
#include "conus/renderers/mesh_render.h"
#include "conus/sceneio/mesh_file.h"
#include "sanitizers.h"
#include "scene_state.h"
#include "viewer_test_util.h"

namespace conus::viewer {
namespace {

namespace fs = std::filesystem;

constexpr int kW = 256, kH = 192;

Image readPicture(const fs::path& path) {
    auto in = OIIO::ImageInput::open(path.string());
    if (!in) return {};
    const OIIO::ImageSpec spec = in->spec();
    Image im = makeImage(spec.width, spec.height, std::vector<std::string>(spec.nchannels, "C"));
    in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, im.pixels.data());
    return im;
}

// Runs conus-view with `args` and the script under Xvfb in a kW x kH window; the log.
std::string runScript(const std::string& args, const std::string& script) {
    const fs::path path = test::tempDir() / "scene-script.txt";
    test::writeText(path, script);
    std::string log;
    const std::string command = "xvfb-run -a -s '-screen 0 1024x768x24' " + conus::testing::glxLeakCheckPrefix() +
                                test::viewerBinary() + " " + args + " --window " + std::to_string(kW) + "x" +
                                std::to_string(kH) + " --script " + path.string();
    EXPECT_EQ(test::run(command, &log), 0) << log;
    return log;
}

// Worst and mean difference (display values) between a screenshot and a linear frame shown through
// the sRGB curve.
struct Difference {
    double worst = 0, mean = 0;
};
Difference compare(const Image& shot, const Image& frame) {
    Difference d;
    EXPECT_EQ(shot.width, frame.width);
    EXPECT_EQ(shot.height, frame.height);
    if (shot.width != frame.width || shot.height != frame.height) return {1, 1};
    for (int y = 0; y < frame.height; ++y)
        for (int x = 0; x < frame.width; ++x)
            for (int c = 0; c < 3; ++c) {
                const double e = std::abs(shot.at(x, y, c) - linearToSrgbDisplay(frame.at(x, y, c)));
                d.worst = std::max(d.worst, e);
                d.mean += e;
            }
    d.mean /= 3.0 * frame.width * frame.height;
    return d;
}

double meanDifference(const Image& a, const Image& b) {
    double sum = 0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i) sum += std::abs(a.pixels[i] - b.pixels[i]);
    return sum / double(a.pixels.size());
}

TEST(SceneWindow, MeshFramesAreTheEncodersAndFollowTheCommands) {
    ASSERT_TRUE(test::haveXvfb()) << "xvfb-run is needed (package xvfb)";
    const std::string model = std::string(CONUS_SHARED_DATA) + "/meshes/spot.obj";
    const codec::Focus focus{0.45, 0.4, 0.12, 3.0};
    const fs::path dir = test::tempDir();
    // The drag starts on the focus (the frame fills the window: uv = pixel / size) and ends far off.
    const glm::dvec2 from(focus.u * kW, focus.v * kH), to(0.75 * kW, 0.7 * kH);
    const std::string script = "screenshot " + (dir / "m1.png").string() + "\n" +                                  //
                               "drag " + std::to_string(from.x) + " " + std::to_string(from.y) + " " + std::to_string(to.x) +
                               " " + std::to_string(to.y) + "\nscreenshot " + (dir / "m2.png").string() + "\n" +  //
                               "key U\nscreenshot " + (dir / "m3.png").string() + "\n" +                           //
                               "orbit 40 10\nscreenshot " + (dir / "m4.png").string() + "\n";
    const std::string log = runScript("--mesh " + model + " --focus 0.45,0.4,0.12,3", script);
    const Image m1 = readPicture(dir / "m1.png"), m2 = readPicture(dir / "m2.png"), m3 = readPicture(dir / "m3.png"),
                m4 = readPicture(dir / "m4.png");
    ASSERT_EQ(m4.width, kW) << log;

    // The same frames, rendered offscreen from the scene state the window starts from.
    const Mesh mesh = sceneio::readMesh(model);
    const BoundingSphere sphere = boundingSphere(std::vector<glm::dvec3>(mesh.positions.begin(), mesh.positions.end()));
    SceneState state(sphere.centre, sphere.radius, {focus});
    const double aspect = double(kW) / kH;
    gl::MeshRenderer renderer(test::context(), mesh);
    const Image conus = renderer.render(state.camera(aspect), state.map(aspect), kW, kH);
    const Image conventional = renderer.render(state.camera(aspect), codec::SamplingMap::identity(2, 2), kW, kH);
    state.rotate(40, 10);
    const Image orbited = renderer.render(state.camera(aspect), codec::SamplingMap::identity(2, 2), kW, kH);

    const Difference d1 = compare(m1, conus), d3 = compare(m3, conventional), d4 = compare(m4, orbited);
    EXPECT_LT(d1.mean, 1.0 / 255) << "the window shows the CoNUS frame itself";
    EXPECT_LT(d1.worst, 4.0 / 255);
    EXPECT_LT(d3.mean, 1.0 / 255) << "U: the conventional frame (identity map)";
    EXPECT_LT(d4.mean, 1.0 / 255) << "orbit: the camera turned 40 degrees";
    // And the frames differ from each other: the focus moved, the map went, the camera turned.
    EXPECT_GT(meanDifference(m1, m2), 2.0 / 255) << "dragging the focus changes the picture";
    EXPECT_GT(compare(m1, conventional).mean, 2.0 / 255) << "CoNUS and conventional differ";
    EXPECT_GT(meanDifference(m3, m4), 4.0 / 255);
}

}  // namespace
}  // namespace conus::viewer
