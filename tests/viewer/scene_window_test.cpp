// The 3-D modes as a user runs them: conus-view --mesh / --volume / --relief under Xvfb, driven by
// --script (orbit, drag a focus, toggle, screenshot). The window must show exactly the frame the
// GPU renderers make for the camera and map of the scene state (the CoNUS image itself), and each
// command must change the picture the way it says.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <algorithm>

#include "conus/core/display.h"
#include "conus/codec/mesh/subdivide.h"
#include "conus/codec/volume/procedural.h"
#include "conus/renderers/mesh_render.h"
#include "conus/renderers/volume_renderer.h"
#include "conus/sceneio/mesh_file.h"
#include "sanitizers.h"
#include "scene_state.h"
#include "oiio_picture.h"
#include "viewer_test_util.h"

namespace conus::viewer {
namespace {

namespace fs = std::filesystem;

constexpr int kW = 256, kH = 192;

Image readPicture(const fs::path& path) { return conus::test::readPictureWithOiio(path.string()); }

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
    if (!fs::exists(model)) GTEST_SKIP() << "shared data not found: " << model;
    const codec::Focus focus{0.45, 0.4, 0.12, 3.0};
    const fs::path dir = test::tempDir();
    // The drag starts on the focus (the frame fills the window: uv = pixel / size) and ends far off.
    const glm::dvec2 from(focus.u * kW, focus.v * kH), to(0.75 * kW, 0.7 * kH);
    const std::string script = "screenshot " + (dir / "m1.png").string() + "\n" +                                  //
                               "drag " + std::to_string(from.x) + " " + std::to_string(from.y) + " " + std::to_string(to.x) +
                               " " + std::to_string(to.y) + "\nscreenshot " + (dir / "m2.png").string() + "\n" +  //
                               "key U\nscreenshot " + (dir / "m3.png").string() + "\n" +                           //
                               "orbit 40 10\nscreenshot " + (dir / "m4.png").string() + "\n" +                   //
                               "key Z\nscreenshot " + (dir / "m5.png").string() + "\n";
    const std::string log = runScript("--mesh " + model + " --focus 0.45,0.4,0.12,3", script);
    const Image m1 = readPicture(dir / "m1.png"), m2 = readPicture(dir / "m2.png"), m3 = readPicture(dir / "m3.png"),
                m4 = readPicture(dir / "m4.png");
    ASSERT_EQ(m4.width, kW) << log;

    // The same frames, rendered offscreen from the scene state the window starts from.
    const Mesh mesh = sceneio::readMesh(model);
    const BoundingSphere sphere = boundingSphere(std::vector<glm::dvec3>(mesh.positions.begin(), mesh.positions.end()));
    SceneState state(sphere.centre, sphere.radius, {focus});
    const double aspect = double(kW) / kH;
    renderers::MeshRenderer renderer(test::context(), mesh);
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
    // Z: the live frame's depth picture (through the file viewer's path): the background is blue,
    // the model on the ramp, brighter than the frame's darkest surface.
    const Image m5 = readPicture(dir / "m5.png");
    ASSERT_EQ(m5.width, kW);
    EXPECT_GT(m5.at(1, 1, 2), m5.at(1, 1, 0) + 0.1) << "background";
    double brightest = 0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) brightest = std::max(brightest, double(m5.at(x, y, 0) + m5.at(x, y, 1)));
    EXPECT_GT(brightest, 1.6) << "the nearest surface is the ramp's bright end";
}

const std::string kSuzanne = std::string(CONUS_SHARED_DATA) + "/meshes/suzanne.obj";

// The window's screenshot of suzanne through one focus (`options` after --mesh and --focus), with
// the mesh and the camera and map the window starts from.
struct SuzanneFrame {
    Image window;
    std::string log;
    Mesh mesh;
    Camera camera;
    codec::SamplingMap map;
};

SuzanneFrame suzanneFrame(const std::string& options, const std::string& shotName) {
    const fs::path shot = test::tempDir() / shotName;
    std::string log = runScript("--mesh " + kSuzanne + " --focus 0.5,0.45,0.15,4 " + options, "screenshot " + shot.string() + "\n");
    Mesh mesh = sceneio::readMesh(kSuzanne);
    const BoundingSphere sphere = boundingSphere(std::vector<glm::dvec3>(mesh.positions.begin(), mesh.positions.end()));
    const SceneState state(sphere.centre, sphere.radius, {codec::Focus{0.5, 0.45, 0.15, 4.0}});
    const double aspect = double(kW) / kH;
    return {readPicture(shot), std::move(log), std::move(mesh), state.camera(aspect), state.map(aspect)};
}

// --max-edge: each CoNUS frame is the encoder's of the mesh subdivided for that frame's camera and map.
TEST(SceneWindow, MeshMaxEdgeSubdividesEachFrame) {
    ASSERT_TRUE(test::haveXvfb()) << "xvfb-run is needed (package xvfb)";
    if (!fs::exists(kSuzanne)) GTEST_SKIP() << "shared data not found: " << kSuzanne;
    const SuzanneFrame f = suzanneFrame("--max-edge 0.5", "edge.png");
    ASSERT_EQ(f.window.width, kW) << f.log;
    const Mesh fine = codec::subdivideForMap(f.mesh, f.camera, f.map, 0.5);
    ASSERT_GT(fine.triangleCount(), f.mesh.triangleCount()) << "the focus makes some edges long";
    renderers::MeshRenderOptions asSplit;
    asSplit.maxBend = 0;
    EXPECT_LT(compare(f.window, renderers::renderMeshGpu(test::context(), fine, f.camera, f.map, kW, kH, asSplit)).mean, 1.0 / 255);
}

// --max-bend 0: the mesh drawn as it is through the map, not the default's split frame.
TEST(SceneWindow, MeshMaxBendZeroDrawsTheMeshAsItIs) {
    ASSERT_TRUE(test::haveXvfb()) << "xvfb-run is needed (package xvfb)";
    if (!fs::exists(kSuzanne)) GTEST_SKIP() << "shared data not found: " << kSuzanne;
    const SuzanneFrame f = suzanneFrame("--max-bend 0", "straight.png");
    ASSERT_EQ(f.window.width, kW) << f.log;
    renderers::MeshRenderer renderer(test::context(), f.mesh);
    renderers::MeshRenderOptions straight;
    straight.maxBend = 0;
    const Image asBuilt = renderer.render(f.camera, f.map, kW, kH, straight);
    const Image split = renderer.render(f.camera, f.map, kW, kH);
    EXPECT_LT(compare(f.window, asBuilt).mean, 1.0 / 255);
    EXPECT_GT(compare(asBuilt, split).worst, 8.0 / 255) << "the focus bends suzanne's long edges";
}

// --screenshot in a 3-D mode: the first frame offscreen, no window, as the window would show it
// (the GPU ray caster's frame for the scene state's camera and map, the default preset).
TEST(SceneWindow, ScreenshotOfAVolumeIsItsFirstFrame) {
    const std::string spec = "procedural:shepp-logan:48";
    const fs::path shot = test::tempDir() / "volume-shot.png";
    std::string log;
    ASSERT_EQ(test::run(test::viewerBinary() + " --volume " + spec + " --focus 0.5,0.45,0.15,3 --screenshot " +
                            shot.string() + " --size " + std::to_string(kW) + "x" + std::to_string(kH),
                        &log),
              0)
        << log;
    const Volume volume = codec::proceduralVolume(spec);
    const SceneState state(0.5 * volume.extent(), 0.5 * glm::length(volume.extent()), {codec::Focus{0.5, 0.45, 0.15, 3.0}});
    const double aspect = double(kW) / kH;
    renderers::VolumeRendererGpu renderer(test::context(), volume,
                                   codec::TransferFunction::preset(codec::TransferFunction::kDefaultPreset));
    const Image frame = renderer.render(Fpc(state.camera(aspect), std::make_shared<codec::SamplingMap>(state.map(aspect))),
                                        kW, kH, {});
    EXPECT_LT(compare(readPicture(shot), frame).mean, 1.0 / 255) << log;
    // A mesh without a file: refused in one line.
    std::string refused;
    EXPECT_NE(test::run(test::viewerBinary() + " --mesh /nonexistent.obj --screenshot " + shot.string(), &refused), 0);
}

// T cycles the transfer function, U drops the map; each frame is the GPU ray caster's for the scene
// state's camera and map (the volume box's sphere: centre extent / 2, radius |extent| / 2).
TEST(SceneWindow, VolumeFramesAreTheRayCastersAndTCyclesTheLook) {
    ASSERT_TRUE(test::haveXvfb()) << "xvfb-run is needed (package xvfb)";
    const std::string spec = "procedural:shepp-logan:48";
    const codec::Focus focus{0.5, 0.45, 0.15, 3.0};
    const fs::path dir = test::tempDir();
    const std::string script = "screenshot " + (dir / "v1.png").string() + "\nkey T\nscreenshot " + (dir / "v2.png").string() +
                               "\nkey U\nscreenshot " + (dir / "v3.png").string() + "\n";
    const std::string log = runScript("--volume " + spec + " --focus 0.5,0.45,0.15,3 --status-bar", script);
    const Image v1 = readPicture(dir / "v1.png"), v2 = readPicture(dir / "v2.png"), v3 = readPicture(dir / "v3.png");
    ASSERT_EQ(v3.width, kW) << log;

    const Volume volume = codec::proceduralVolume(spec);
    SceneState state(0.5 * volume.extent(), 0.5 * glm::length(volume.extent()), {focus});
    const double aspect = double(kW) / kH;
    // The first frame has the command line's default preset (`render volume`'s too), T the next.
    const std::vector<std::string> presets = codec::TransferFunction::presetNames();
    ASSERT_GE(presets.size(), 2u);
    const auto at = std::find(presets.begin(), presets.end(), codec::TransferFunction::kDefaultPreset);
    ASSERT_NE(at, presets.end());
    const std::size_t first = static_cast<std::size_t>(at - presets.begin());
    renderers::VolumeRendererGpu renderer(test::context(), volume, codec::TransferFunction::preset(presets[first]));
    const auto render = [&](const codec::SamplingMap& map) {
        return renderer.render(Fpc(state.camera(aspect), std::make_shared<codec::SamplingMap>(map)), kW, kH, {});
    };
    const Image initial = render(state.map(aspect));
    renderer.setTransferFunction(codec::TransferFunction::preset(presets[(first + 1) % presets.size()]));
    const Image second = render(state.map(aspect));
    const Image conventional = render(codec::SamplingMap::identity(2, 2));
    // The status bar covers the bottom rows: compare above it.
    const auto top = [](const Image& im) {
        Image t = im;
        t.height = kH * 3 / 4;
        t.pixels.resize(std::size_t(t.width) * t.height * t.channelCount());
        return t;
    };
    EXPECT_LT(compare(top(v1), top(initial)).mean, 1.0 / 255) << "the CoNUS frame with the default preset";
    EXPECT_LT(compare(top(v2), top(second)).mean, 1.0 / 255) << "T: the next preset";
    EXPECT_LT(compare(top(v3), top(conventional)).mean, 1.0 / 255) << "U: the identity map";
    EXPECT_GT(meanDifference(v1, v2), 2.0 / 255);
    EXPECT_GT(compare(top(v3), top(second)).mean, 2.0 / 255);
    EXPECT_NE(log.find("(volume), tf " + presets[first]), std::string::npos) << log;
    EXPECT_NE(log.find("conus-view: tf " + presets[(first + 1) % presets.size()]), std::string::npos) << "T says the look it chose\n" << log;
}

// A relief asset and its conventional twin: U swaps them (the engraving differs, the frame around
// it does not), an orbit turns the tablet.
TEST(SceneWindow, ReliefAssetToggleAndOrbit) {
    ASSERT_TRUE(test::haveXvfb()) << "xvfb-run is needed (package xvfb)";
    const fs::path dir = test::tempDir();
    const std::string conus = std::string(CONUS_BIN_DIR) + "/conus";
    std::string log;
    for (const char* flag : {"", " --uniform"})
        ASSERT_EQ(test::run(conus + " bake relief tablet --text 'AB' -q --size 128x96 -o " +
                                (dir / (std::string("tablet") + (*flag ? "-u" : "") + ".exr")).string() + flag,
                            &log),
                  0)
            << log;
    const std::string script = "screenshot " + (dir / "r1.png").string() + "\nkey U\nscreenshot " + (dir / "r2.png").string() +
                               "\norbit 60 20\nscreenshot " + (dir / "r3.png").string() + "\n";
    log = runScript("--relief " + (dir / "tablet.exr").string() + " --uniform " + (dir / "tablet-u.exr").string(), script);
    const Image r1 = readPicture(dir / "r1.png"), r2 = readPicture(dir / "r2.png"), r3 = readPicture(dir / "r3.png");
    ASSERT_EQ(r3.width, kW) << log;
    int changed = 0, tablet = 0;
    const float background = r1.at(0, 0, 0);
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            changed += std::abs(r1.at(x, y, 0) - r2.at(x, y, 0)) > 3.0f / 255;
            tablet += std::abs(r1.at(x, y, 0) - background) > 3.0f / 255;
        }
    EXPECT_GT(tablet, kW * kH / 10) << "the tablet fills a good part of the frame";
    EXPECT_GT(changed, 20) << "the conventional asset shows the engraving differently";
    EXPECT_LT(changed, tablet / 2) << "the same tablet, the same camera";
    EXPECT_GT(meanDifference(r2, r3), 4.0 / 255) << "the orbit turned it";
}

// Bad scenes and arguments: a clear message and a non-zero status, before or after the window opens.
TEST(SceneWindow, BadScenesFailClearly) {
    const struct {
        std::string args, says;
        int status;
        bool window;
    } cases[] = {
        {"--mesh a.obj --volume b", "give one of --mesh", 2, false},
        {"--reflection asset.exr", "needs --scene", 2, false},
        {"--mesh a.obj --focus 2,0,0.1,2", "outside [0,1]^2", 2, false},
        {"--mesh a.obj --uniform b.obj", "--uniform in a 3-D mode", 2, false},
        {"--mesh /nonexistent/model.obj", "no such file", 1, true},
        {"--volume procedural:nothing", "procedural:shepp-logan", 1, true},
        {"--relief " + test::conusPath(), "is not a relief asset", 1, true},
    };
    for (const auto& c : cases) {
        std::string log;
        const std::string command = (c.window ? "xvfb-run -a -s '-screen 0 640x480x24' " : "env -u DISPLAY ") +
                                    test::viewerBinary() + " " + c.args;
        EXPECT_EQ(test::run(command, &log), c.status) << c.args << "\n" << log;
        EXPECT_NE(log.find(c.says), std::string::npos) << c.args << "\n" << log;
    }
}

// A floor and two boxes around the origin, counter-clockwise from outside.
std::string roomObj() {
    std::string text;
    int n = 0;
    const auto quad = [&](glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, glm::dvec3 d) {
        for (const glm::dvec3& p : {a, b, c, d}) text += "v " + std::to_string(p.x) + " " + std::to_string(p.y) + " " + std::to_string(p.z) + "\n";
        text += "f " + std::to_string(n + 1) + " " + std::to_string(n + 2) + " " + std::to_string(n + 3) + "\n";
        text += "f " + std::to_string(n + 1) + " " + std::to_string(n + 3) + " " + std::to_string(n + 4) + "\n";
        n += 4;
    };
    quad({-4, -1, -4}, {-4, -1, 4}, {4, -1, 4}, {4, -1, -4});
    const auto box = [&](glm::dvec3 lo, glm::dvec3 hi) {
        quad({lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z});
        quad({hi.x, lo.y, lo.z}, {lo.x, lo.y, lo.z}, {lo.x, hi.y, lo.z}, {hi.x, hi.y, lo.z});
        quad({hi.x, lo.y, hi.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {hi.x, hi.y, hi.z});
        quad({lo.x, lo.y, lo.z}, {lo.x, lo.y, hi.z}, {lo.x, hi.y, hi.z}, {lo.x, hi.y, lo.z});
        quad({lo.x, hi.y, hi.z}, {hi.x, hi.y, hi.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z});
    };
    box({1.5, -1, -0.5}, {2.5, 0.5, 0.5});
    box({-2.5, -1, -2}, {-1.8, 1, -1.3});
    const fs::path path = test::tempDir() / "room.obj";
    test::writeText(path, text);
    return path.string();
}

// A reflection asset (GPU frames) whose faces magnify the first box: U swaps them for the
// conventional ones, which changes the mirror and nothing else.
TEST(SceneWindow, ReflectionAssetToggleChangesTheMirrorOnly) {
    ASSERT_TRUE(test::haveXvfb()) << "xvfb-run is needed (package xvfb)";
    const fs::path dir = test::tempDir();
    const std::string room = roomObj(), conus = std::string(CONUS_BIN_DIR) + "/conus";
    std::string log;
    for (const char* flag : {"", " --uniform"})
        ASSERT_EQ(test::run(conus + " bake reflection " + room + " --center 0,0,0 --size 32 -q --roi-min 1.5,-1,-0.5 " +
                                "--roi-max 2.5,0.5,0.5 --magnification 4 -o " +
                                (dir / (std::string("mirror") + (*flag ? "-u" : "") + ".exr")).string() + flag,
                            &log),
                  0)
            << log;
    const std::string script = "screenshot " + (dir / "f1.png").string() + "\nkey U\nscreenshot " + (dir / "f2.png").string() + "\n";
    log = runScript("--reflection " + (dir / "mirror.exr").string() + " --uniform " + (dir / "mirror-u.exr").string() + " --scene " + room, script);
    const Image f1 = readPicture(dir / "f1.png"), f2 = readPicture(dir / "f2.png");
    ASSERT_EQ(f2.width, kW) << log;
    // The mirror sphere (radius 0.5 at the origin) is the frame's centre, a third of its height.
    int changedInside = 0, changedOutside = 0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            const bool changed = std::abs(f1.at(x, y, 0) - f2.at(x, y, 0)) + std::abs(f1.at(x, y, 1) - f2.at(x, y, 1)) > 3.0f / 255;
            const bool mirror = std::hypot(x + 0.5 - kW / 2.0, y + 0.5 - kH / 2.0) < kH / 6.0 + 2;
            (mirror ? changedInside : changedOutside) += changed;
        }
    EXPECT_GT(changedInside, 20) << "the reflection differs between the CoNUS and conventional faces";
    EXPECT_EQ(changedOutside, 0) << "the scene behind is the same";
}

}  // namespace
}  // namespace conus::viewer
