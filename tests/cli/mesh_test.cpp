// `conus render mesh|animate` through the real binary; outputs read back with OpenImageIO.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>

#include "cli/cli_fixture.h"
#include "sceneio/test_meshes.h"
#include "conus/format/container.h"

namespace conus::test {
namespace {

// A unit cube centred at (0.2, 0, 0) with a colour per corner (OBJ's "v x y z r g b"), and a
// small triangle floating in front of it so the picture has no symmetry.
std::string writeObj(const fs::path& path) {
    std::ofstream obj(path);
    for (int k = 0; k < 8; ++k)
        obj << "v " << (k & 1 ? 0.7 : -0.3) << ' ' << (k & 2 ? 0.5 : -0.5) << ' ' << (k & 4 ? 0.5 : -0.5) << ' '
            << (k & 1 ? 0.9 : 0.2) << ' ' << (k & 2 ? 0.8 : 0.3) << ' ' << (k & 4 ? 0.7 : 0.1) << '\n';
    obj << "v -0.6 0.4 0.9 1 1 0\nv -0.2 0.4 0.9 1 1 0\nv -0.4 0.7 0.9 1 1 0\n";
    obj << "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\nf 9 10 11\n";
    return path.string();
}

double covered(const ExrRead& r) {
    double sum = 0;
    for (float a : r.channels.at("A")) sum += a;
    return sum;
}

using Mesh = Cli;

TEST_F(Mesh, RenderWritesACameraDepthImageThatOpenImageIoReads) {
    const std::string obj = writeObj(m_dir / "cube.obj");
    const Result r = run("render mesh " + obj + " -o " + path("cube.exr") +
                         " --size 96x64 --focus 0.35,0.4,0.12,3 --backend egl --camera 0.4,0.6,3,0.1,0,0,40");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.out.find("wrote"), std::string::npos);
    EXPECT_NE(r.out.find("where the map bends"), std::string::npos);  // the GPU path splits where the map bends by default
    const ExrRead exr = readExr(path("cube.exr"));
    ASSERT_NO_FATAL_FAILURE(expectCameraDepthImage(exr, 96, 64));
    EXPECT_EQ(exr.spec.get_string_attribute("conus:projection"), "perspective");
    EXPECT_NE(exr.spec.find_attribute("worldToCamera"), nullptr);
    EXPECT_NE(exr.spec.find_attribute("worldToNDC"), nullptr);
    // The eye is about 3 units from the cube: covered pixels lie 2..3.6 deep, misses at far.
    const auto& z = exr.channels.at("Z");
    const auto& a = exr.channels.at("A");
    float far = 0;
    int hits = 0;
    for (std::size_t p = 0; p < z.size(); ++p) {
        if (a[p] == 1.0f) {
            ++hits;
            EXPECT_GT(z[p], 1.9f);
            EXPECT_LT(z[p], 3.7f);
        }
        if (a[p] == 0.0f) far = std::max(far, z[p]);
    }
    EXPECT_GT(hits, 96 * 64 / 10);
    EXPECT_GT(far, 3.5f);
    EXPECT_TRUE(leftovers().empty());

    // The project's reader gives back the camera asked for, and exrheader (OpenEXR's own tool)
    // shows the standard matrices and the data kind.
    const format::ConusFile file = format::readConusFile(path("cube.exr"));
    EXPECT_EQ(file.dataKind, format::DataKind::DepthImage);
    EXPECT_EQ(file.depth.kind, format::DepthKind::CameraDepth);
    EXPECT_EQ(file.depth.units, "m");
    ASSERT_TRUE(file.camera.has_value());
    const Camera camera = format::toCamera(*file.camera);
    EXPECT_NEAR(glm::distance(camera.eye(), glm::dvec3(0.4, 0.6, 3.0)), 0.0, 1e-4);
    EXPECT_NEAR(camera.verticalFovDegrees(), 40.0, 1e-3);
    EXPECT_NEAR(glm::dot(camera.forward(), glm::normalize(glm::dvec3(0.1, 0, 0) - glm::dvec3(0.4, 0.6, 3.0))), 1.0, 1e-6);
    EXPECT_FLOAT_EQ(file.depth.far, far);
    const std::string header = path("header.txt");
    ASSERT_EQ(std::system(("exrheader " + path("cube.exr") + " >" + header).c_str()), 0);
    const std::string text = slurp(header);
    EXPECT_NE(text.find("worldToCamera"), std::string::npos);
    EXPECT_NE(text.find("worldToNDC"), std::string::npos);
    EXPECT_NE(text.find("\"depthimage\""), std::string::npos) << text;
}

TEST_F(Mesh, DecodeGivesColourAndNearestDepth) {
    const std::string obj = writeObj(m_dir / "cube.obj");
    ASSERT_EQ(run("render mesh " + obj + " -o " + path("cube.exr") +
                  " --size 96x64 --focus 0.35,0.4,0.12,3 --backend egl --camera 0.4,0.6,3,0.1,0,0,40").exitCode, 0);
    const Result r = run("decode " + path("cube.exr") + " -o " + path("view.exr") + " --size 192x128");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.out.find("nearest"), std::string::npos) << r.out;
    const ExrRead view = readExr(path("view.exr"));
    ASSERT_TRUE(view.channels.count("Z"));
    ASSERT_TRUE(view.channels.count("R"));
    // Every decoded depth is one the CoNUS image holds (nearest, never a blend of two surfaces).
    const ExrRead conus = readExr(path("cube.exr"));
    std::vector<float> held = conus.channels.at("Z");
    std::sort(held.begin(), held.end());
    for (float z : view.channels.at("Z")) EXPECT_TRUE(std::binary_search(held.begin(), held.end(), z)) << z;
    // Colour and coverage decode too: the model covers a good part of the view.
    double covered = 0;
    for (float a : view.channels.at("A")) covered += a;
    EXPECT_GT(covered, 192 * 128 / 10);
    const Result png = run("decode " + path("cube.exr") + " -o " + path("view.png") + " --size 96x64");
    ASSERT_EQ(png.exitCode, 0) << png.err;
    EXPECT_EQ(imageSize(path("view.png")), std::make_pair(96, 64));
}

TEST_F(Mesh, GpuAgreesWithTheEmbreeReference) {
    const std::string obj = writeObj(m_dir / "cube.obj");
    const std::string common = " --size 96x64 --focus 0.35,0.4,0.12,3 --camera 0.4,0.6,3,0.1,0,0,40 --samples 4";
    ASSERT_EQ(run("render mesh " + obj + " -o " + path("gpu.exr") + common + " --backend osmesa --max-edge 0.25").exitCode, 0);
    const Result ref = run("render mesh " + obj + " -o " + path("ref.exr") + common + " --reference");
    ASSERT_EQ(ref.exitCode, 0) << ref.err;
    EXPECT_NE(ref.out.find("cpu"), std::string::npos);
    EXPECT_GE(psnrRgb(readExr(path("gpu.exr")), readExr(path("ref.exr"))), 30.0);
}

TEST_F(Mesh, AFocusEnlargesTheModelAndUniformIsTheBaseline) {
    const std::string obj = writeObj(m_dir / "cube.obj");
    const std::string common = " --size 96x64 --camera 0.4,0.6,6,0.1,0,0,30 --backend egl";
    ASSERT_EQ(run("render mesh " + obj + " -o " + path("u.exr") + common + " --uniform").exitCode, 0);
    ASSERT_EQ(run("render mesh " + obj + " -o " + path("f.exr") + common + " --focus 0.5,0.5,0.15,4").exitCode, 0);
    EXPECT_GT(covered(readExr(path("f.exr"))), 2.0 * covered(readExr(path("u.exr"))));
    // Foci compose by density, as encode, volume and map compose them.
    ASSERT_EQ(run("render mesh " + obj + " -o " + path("two.exr") + common + " --focus 0.3,0.5,0.1,3 --focus 0.7,0.5,0.1,3")
                  .exitCode,
              0);
    const format::ConusFile two = format::readConusFile(path("two.exr"));
    ASSERT_TRUE(two.analytic);
    EXPECT_EQ(two.analytic->composition, "density");
}

TEST_F(Mesh, DefaultCameraFramesTheModel) {
    const std::string obj = writeObj(m_dir / "cube.obj");
    const Result r = run("render mesh " + obj + " -o " + path("d.exr") + " --size 64x64 --uniform -q");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_TRUE(r.err.empty()) << r.err;  // -q: no progress
    const ExrRead exr = readExr(path("d.exr"));
    // Framed: the model covers a good part of the frame and touches no border.
    EXPECT_GT(covered(exr), 64 * 64 * 0.15);
    const auto& a = exr.channels.at("A");
    for (int i = 0; i < 64; ++i) {
        EXPECT_EQ(a[i], 0.0f);
        EXPECT_EQ(a[63 * 64 + i], 0.0f);
        EXPECT_EQ(a[i * 64], 0.0f);
        EXPECT_EQ(a[i * 64 + 63], 0.0f);
    }
}

TEST_F(Mesh, CityWithTrackedCars) {
    const Result r = run("render mesh city -o " + path("c.exr") + " --size 128x72 --track 0,2 --time 2 --backend egl");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const ExrRead exr = readExr(path("c.exr"));
    EXPECT_EQ(exr.width, 128);
    EXPECT_EQ(exr.spec.get_string_attribute("conus:mapKind"), "foci");
}

// The triangles before and after of the line "subdivided A -> B triangles ..." or "drew A triangles
// as B ..." (0, 0 when absent).
std::pair<long, long> triangleCounts(const std::string& out, const char* format) {
    long before = 0, after = 0;
    const std::string lead(format, std::string(format).find(' ') + 1);
    const std::size_t at = out.find(lead);
    if (at != std::string::npos) std::sscanf(out.c_str() + at, format, &before, &after);
    return {before, after};
}

// The city through two tracked cars at the default size, as `conus render mesh` draws it by default
// (split on the GPU where the map bends), against the Embree reference, beside no split and the
// uniform CPU split to half a map cell (--max-edge 0.5).
TEST_F(Mesh, TheCityFollowsTheMapWhereItBends) {
    const std::string city = "render mesh city --track 0,2 --time 1 -o ";
    const Result bend = run(city + path("bend.exr") + " --backend egl");
    ASSERT_EQ(bend.exitCode, 0) << bend.err;
    EXPECT_NE(bend.out.find("where the map bends"), std::string::npos) << bend.out;
    const Result none = run(city + path("none.exr") + " --backend egl --max-bend 0");
    ASSERT_EQ(none.exitCode, 0) << none.err;
    EXPECT_EQ(none.out.find("drew"), std::string::npos);
    EXPECT_EQ(none.out.find("subdivided"), std::string::npos);
    const Result edge = run(city + path("edge.exr") + " --backend egl --max-edge 0.5");
    ASSERT_EQ(edge.exitCode, 0) << edge.err;
    ASSERT_EQ(run(city + path("ref.exr") + " --reference").exitCode, 0);
    const ExrRead ref = readExr(path("ref.exr"));
    const double psnrBend = psnrRgb(readExr(path("bend.exr")), ref), psnrNone = psnrRgb(readExr(path("none.exr")), ref),
                 psnrEdge = psnrRgb(readExr(path("edge.exr")), ref);
    const auto [before, drawn] = triangleCounts(bend.out, "drew %ld triangles as %ld");
    const auto [edgeBefore, afterEdge] = triangleCounts(edge.out, "subdivided %ld -> %ld");
    std::printf("city: none %ld triangles %.2f dB; bend %ld drawn %.2f dB; --max-edge 0.5 %ld %.2f dB\n", before, psnrNone,
                drawn, psnrBend, afterEdge, psnrEdge);
    EXPECT_EQ(before, 878);
    EXPECT_EQ(edgeBefore, 878);
    EXPECT_GT(drawn, before);
    EXPECT_GE(psnrBend, 40.0);
    EXPECT_LT(psnrNone, 25.0);  // the ground's straight inside covers the buildings
    EXPECT_GT(psnrEdge, psnrBend - 1.0);
    // The same picture from the 878 triangles uploaded, where --max-edge uploads its split mesh,
    // and under half the triangles drawn.
    EXPECT_GT(afterEdge, 100 * before);
    EXPECT_LT(drawn, afterEdge / 2);
}

TEST_F(Mesh, BadInputIsOneLineAndNonZero) {
    const std::string obj = writeObj(m_dir / "cube.obj");
    const struct {
        std::string args, says;
    } cases[] = {
        {"render mesh " + path("missing.obj") + " -o " + path("x.exr"), "missing.obj"},
        {"render mesh " + obj + " -o " + path("x.png"), ".exr"},
        {"render mesh " + obj + " -o " + path("x.exr") + " --track 0", "city"},
        {"render mesh " + obj + " -o " + path("x.exr") + " --camera 1,2,3", "7 values"},
        {"render mesh " + obj + " -o " + path("x.exr") + " --camera 0,0,-5,0,0,-10,40", "behind"},
        {"render mesh city -o " + path("x.exr") + " --track 99", "cars"},
        {"mesh animate " + obj + " --out-dir " + path("d") + " --frames 2", "city"},
        {"render mesh " + path("past.gltf") + " -o " + path("x.exr"), "indexes past"},
    };
    test::writeGltfCube(path("past.gltf"), 9);
    for (const auto& c : cases) {
        const Result r = run(c.args + " -q");  // -q: only the error line
        EXPECT_NE(r.exitCode, 0) << c.args;
        EXPECT_NE(r.err.find(c.says), std::string::npos) << c.args << ": " << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    }
    EXPECT_FALSE(fs::exists(path("x.exr")));
    EXPECT_TRUE(leftovers().empty());
    // A degenerate triangle is dropped, and the warning says so even with -q.
    writeText(path("flat.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\n");
    const Result r = run("render mesh " + path("flat.obj") + " -o " + path("flat.exr") + " --uniform --size 32x32 -q");
    EXPECT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.err.find("dropped 1 of 2 triangles, degenerate"), std::string::npos) << r.err;
}

TEST_F(Mesh, AnimateWritesFramesAContactSheetAndAVideo) {
    const Result r = run("mesh animate city --frames 3 --fps 4 --out-dir " + path("seq") +
                         " --track 0,2 --size 96x54 --backend egl");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    for (int i = 0; i < 3; ++i) {
        const std::string stem = path("seq/frame_000" + std::to_string(i));
        EXPECT_EQ(readExr(stem + ".exr").channels.count("Z"), 1u);
        EXPECT_EQ(imageSize(stem + ".png"), std::make_pair(96, 54));
    }
    EXPECT_GT(imageSize(path("seq/contact_sheet.png")).first, 3 * 96);
    if (std::system("command -v ffmpeg >/dev/null 2>&1") == 0) {
        EXPECT_NE(r.out.find("sequence.mp4"), std::string::npos) << r.out;
        EXPECT_GT(fs::file_size(path("seq/sequence.mp4")), 100u);
    } else {
        EXPECT_NE(r.out.find("no MP4"), std::string::npos) << r.out;
    }
}

TEST_F(Mesh, AnimateSaysPlainlyWhenFfmpegIsMissing) {
    const std::string command = "env PATH=/nonexistent " + std::string(CONUS_BIN_DIR) +
                                "/conus mesh animate city --frames 1 --out-dir " + path("seq") +
                                " --size 48x32 --backend egl -q >" + path("out.txt") + " 2>&1";
    ASSERT_EQ(std::system(command.c_str()), 0);
    EXPECT_NE(slurp(path("out.txt")).find("no MP4: ffmpeg is not on PATH"), std::string::npos);
    EXPECT_FALSE(fs::exists(path("seq/sequence.mp4")));
}

}  // namespace
}  // namespace conus::test
