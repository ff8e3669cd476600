// `conus render volume` through the real binary; outputs read back with OpenImageIO and the
// project's reader.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>

#include "cli/cli_fixture.h"
#include "conus/format/container.h"

namespace conus::test {
namespace {

using Volume = Cli;

TEST_F(Volume, RenderWritesACameraDepthImage) {
    const Result r = run("render volume procedural:shepp-logan:48 -o " + path("head.exr") +
                         " --size 80x60 --focus 0.5,0.45,0.12,3 --backend cpu --picture " + path("head.png"));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.out.find("wrote"), std::string::npos);
    const ExrRead exr = readExr(path("head.exr"));
    ASSERT_NO_FATAL_FAILURE(expectCameraDepthImage(exr, 80, 60));
    const format::ConusFile file = format::readConusFile(path("head.exr"));
    ASSERT_TRUE(file.camera.has_value());
    const Camera camera = format::toCamera(*file.camera);
    // Where the phantom is seen, Z lies between near and far; where not, Z is far.
    const auto& a = exr.channels.at("A");
    const auto& z = exr.channels.at("Z");
    int seen = 0;
    // (Z is where the opacity first reaches 0.5: every pixel past it has one.)
    for (std::size_t p = 0; p < a.size(); ++p) {
        if (a[p] >= 0.5f) {
            ++seen;
            EXPECT_GT(z[p], camera.near());
            EXPECT_LT(z[p], camera.far());
        }
        if (a[p] == 0.0f) {
            EXPECT_FLOAT_EQ(z[p], float(camera.far()));
        }
    }
    EXPECT_GT(seen, 80 * 60 / 10);
    EXPECT_EQ(imageSize(path("head.png")), std::make_pair(80, 60));
    EXPECT_TRUE(leftovers().empty());
}

// The default camera frames what the transfer function shows: the phantom fills the uniform
// frame's height, uncut (it sits in a larger box, which framed whole left it half the height and
// 40% of the width).
TEST_F(Volume, DefaultCameraFillsTheFrameWithTheHead) {
    ASSERT_EQ(run("render volume procedural:shepp-logan:48 -o " + path("u.exr") + " --size 80x80 --uniform --backend cpu")
                  .exitCode,
              0);
    const ExrRead exr = readExr(path("u.exr"));
    const auto& a = exr.channels.at("A");
    int top = 80, bottom = -1;
    for (int y = 0; y < 80; ++y)
        for (int x = 0; x < 80; ++x)
            if (a[static_cast<std::size_t>(y) * 80 + x] > 0.5f) {
                top = std::min(top, y);
                bottom = std::max(bottom, y);
            }
    EXPECT_GT(bottom - top + 1, 0.9 * 80);
    // Nothing at the frame's edge rows: the head is not cut.
    for (int x = 0; x < 80; ++x) {
        EXPECT_EQ(a[static_cast<std::size_t>(x)], 0.0f);
        EXPECT_EQ(a[static_cast<std::size_t>(79) * 80 + x], 0.0f);
    }
}

TEST_F(Volume, GpuAndCpuBackendsAgreeOnARawBrick) {
    // A uint16 brick with a bright off-centre blob and a ramp, written here.
    const int w = 24, h = 18, d = 20;
    std::vector<std::uint16_t> samples;
    for (int z = 0; z < d; ++z)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const double r = std::hypot(x - 15.0, y - 7.0, z - 9.0);
                samples.push_back(static_cast<std::uint16_t>(std::max(0.0, 3000.0 - 300.0 * r) + 20.0 * x));
            }
    {
        std::ofstream out(path("brick.raw"), std::ios::binary);
        out.write(reinterpret_cast<const char*>(samples.data()), std::streamsize(samples.size() * 2));
    }
    {
        std::ofstream tf(path("tf.txt"));
        tf << "# value r g b a\n0 0 0 0 0\n0.3 0.1 0.4 0.9 0.05\n1 1 0.9 0.3 0.8\n";
    }
    const std::string spec = "raw:24x18x20:uint16:1,1,1.5:" + path("brick.raw");
    for (const char* backend : {"cpu", "egl"}) {
        const Result r = run("render volume " + spec + " -o " + path(std::string(backend) + ".exr") +
                             " --size 64x48 --tf " + path("tf.txt") + " --focus 0.6,0.4,0.15,4 --backend " + backend);
        ASSERT_EQ(r.exitCode, 0) << r.err;
    }
    const ExrRead cpu = readExr(path("cpu.exr")), gpu = readExr(path("egl.exr"));
    ASSERT_EQ(cpu.width, 64);
    EXPECT_GE(psnrRgb(cpu, gpu), 40.0);
    double alpha = 0;
    for (float a : cpu.channels.at("A")) alpha += a;
    EXPECT_GT(alpha, 64 * 48 * 0.05);
}

TEST_F(Volume, BadInputGetsOneLineAndANonZeroExit) {
    {
        std::ofstream out(path("short.raw"), std::ios::binary);
        out << "0123456789";
    }
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"render volume raw:10x10x10:uint8:" + path("short.raw") + " -o " + path("a.exr"), "bytes"},
        {"render volume procedural:klein-bottle -o " + path("a.exr"), "procedural"},
        {"render volume procedural:shepp-logan:16 -o " + path("a.exr") + " --tf nosuchpreset", "preset"},
        {"render volume " + path("missing.nrrd") + " -o " + path("a.exr"), "no such file"},
        {"render volume procedural:shepp-logan:16 -o " + path("a.exr") + " --range 5,1", "--range"},
        {"render volume procedural:shepp-logan:16 -o " + path("a.exr") + " --camera 1,2,3", "camera"},
    };
    for (const auto& [args, words] : cases) {
        const Result r = run(args);
        EXPECT_NE(r.exitCode, 0) << args;
        EXPECT_NE(r.err.find(words), std::string::npos) << args << ": " << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    }
    EXPECT_FALSE(fs::exists(path("a.exr")));
    EXPECT_TRUE(leftovers().empty());
}

// A focus sliding across the volume: every frame is a CoNUS depth image with its own map, and no
// node of the map jumps between frames (the largest step is bounded by k times the focus's own
// step, with a margin).
TEST_F(Volume, AnimateMovesTheFocusWithoutJumps) {
    const int frames = 6;
    const Result r = run("volume animate procedural:marschner-lobb:24 --out-dir " + path("frames") +
                         " --from 0.3,0.5 --to 0.7,0.45 --frames 6 --size 48x36 --radius 0.12 --k 3 --backend cpu --tf shells");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const double focusStep = std::hypot(0.4, 0.05) / (frames - 1);
    std::vector<float> previous;
    double largest = 0;
    for (int f = 0; f < frames; ++f) {
        char name[32];
        std::snprintf(name, sizeof name, "frames/frame_%04d", f);
        EXPECT_EQ(imageSize(path(std::string(name) + ".png")), std::make_pair(48, 36));
        const format::ConusFile file = format::readConusFile(path(std::string(name) + ".exr"));
        ASSERT_EQ(file.dataKind, format::DataKind::DepthImage);
        const std::vector<float>& nodes = file.map.xy;  // x, y per node
        if (!previous.empty()) {
            ASSERT_EQ(nodes.size(), previous.size());
            double step = 0;
            for (std::size_t i = 0; i + 1 < nodes.size(); i += 2)
                step = std::max(step, std::hypot(double(nodes[i] - previous[i]), double(nodes[i + 1] - previous[i + 1])));
            EXPECT_GT(step, 0.1 * focusStep) << "frame " << f << ": the map should follow the focus";
            largest = std::max(largest, step);
        }
        previous = nodes;
    }
    std::printf("largest node step %.4f for a focus step of %.4f\n", largest, focusStep);
    // Inside an ideal magnifier of power k the map is c + k (p - c): moving the centre c by D moves
    // those nodes by (k - 1) D; the density-built map's rim moves somewhat more (measured: 3.04 D
    // for k = 3). A jump would be many times that; the bound is k D with a margin.
    EXPECT_LT(largest, 1.15 * 3 * focusStep);
    EXPECT_NE(r.out.find("largest node step"), std::string::npos);
}

}  // namespace
}  // namespace conus::test
