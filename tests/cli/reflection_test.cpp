// `conus bake reflection` and `conus render reflection` through the real binary.
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <fstream>

#include "cli/cli_fixture.h"
#include "conus/format/container.h"

namespace conus::test {
namespace {

using ReflectionCli = Cli;

// A box off every axis (x 0.4..1, y -0.3..0.5, z 1.5..2.2) above a floor at y = -1, as OBJ text.
void writeScene(const std::string& path) {
    std::ofstream out(path);
    const float lo[3] = {0.4f, -0.3f, 1.5f}, hi[3] = {1.0f, 0.5f, 2.2f};
    for (int c = 0; c < 8; ++c)
        out << "v " << (c & 1 ? hi[0] : lo[0]) << ' ' << (c & 2 ? hi[1] : lo[1]) << ' ' << (c & 4 ? hi[2] : lo[2]) << '\n';
    out << "v -4 -1 -4\nv -4 -1 4\nv 4 -1 4\nv 4 -1 -4\n";
    // Box faces (1-based corners), counter-clockwise from outside, then the floor facing up.
    out << "f 1 3 4\nf 1 4 2\nf 5 6 8\nf 5 8 7\nf 1 2 6\nf 1 6 5\nf 3 7 8\nf 3 8 4\nf 1 5 7\nf 1 7 3\nf 2 4 8\nf 2 8 6\n";
    out << "f 9 10 11\nf 9 11 12\n";
}

// The mean absolute difference of two pictures over every channel, by OpenImageIO.
double meanError(const std::string& a, const std::string& b) {
    return OIIO::ImageBufAlgo::compare(OIIO::ImageBuf(a), OIIO::ImageBuf(b), 0.0f, 0.0f).meanerror;
}

TEST_F(ReflectionCli, BakeValidatesAndRenders) {
    const std::string scene = path("scene.obj"), conus = path("asset"), uniform = path("uniform");
    writeScene(scene);
    Result r = run("bake reflection " + scene + " --center 0,0,0 --size 32 --roi-min 0.4,-0.3,1.5 --roi-max 1,0.5,2.2 -o " + conus);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    r = run("bake reflection " + scene + " --center 0,0,0 --size 32 --uniform -o " + uniform);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    for (const char* face : {"px", "nx", "py", "ny", "pz", "nz"}) {
        const std::string file = conus + "/" + face + ".exr";
        EXPECT_EQ(run("validate " + file).exitCode, 0) << file;
        const format::ConusFile read = format::readConusFile(file);
        EXPECT_EQ(read.dataKind, format::DataKind::DepthImage);
        EXPECT_EQ(read.image.width, 32);
        ASSERT_TRUE(read.camera);
    }
    // The +z face sees the region of interest: a focus map; the uniform one keeps the identity.
    EXPECT_GT(format::readConusFile(conus + "/pz.exr").map.columns, 2);
    EXPECT_EQ(format::readConusFile(uniform + "/pz.exr").map.columns, 2);

    const std::string common = " --scene " + scene + " --camera -0.8,0.5,3,0,0,0,22 --size 64x64 --radius 0.5";
    ASSERT_EQ(run("render reflection " + conus + common + " -o " + path("conus.png")).exitCode, 0);
    ASSERT_EQ(run("render reflection " + uniform + common + " -o " + path("uniform.png")).exitCode, 0);
    ASSERT_EQ(run("render reflection " + conus + common + " --reference -o " + path("truth.png")).exitCode, 0);
    const double conusError = meanError(path("conus.png"), path("truth.png"));
    EXPECT_GT(conusError, 0.0);  // the faces are an approximation...
    EXPECT_LT(conusError, 0.02);  // ...of the traced reflection
    EXPECT_GT(meanError(path("conus.png"), path("uniform.png")), 0.0);
    // The GLSL renderer draws the CPU reference's frame (the scene behind rasterized rather than
    // traced: its silhouettes may move a pixel; the rest is float rounding under 8-bit PNG steps).
    r = run("render reflection " + conus + common + " --backend egl -o " + path("gl.png"));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.out.find("egl"), std::string::npos) << r.out;
    ASSERT_EQ(run("render reflection " + conus + common + " --backend cpu -o " + path("cpu.png")).exitCode, 0);
    EXPECT_LT(meanError(path("gl.png"), path("cpu.png")), 2e-3);
    EXPECT_LT(meanError(path("gl.png"), path("cpu.png")), 0.1 * conusError);
}

TEST_F(ReflectionCli, BadInputIsOneLineAndNonZero) {
    const std::string scene = path("scene.obj");
    writeScene(scene);
    Result r = run("render reflection " + path("missing") + " --scene " + scene + " --camera 0,0,-3,0,0,0,30 -o " + path("f.png"));
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.err.find("not a reflection asset"), std::string::npos) << r.err;
    r = run("bake reflection " + scene + " --center 0,nan,0 -o " + path("a"));
    EXPECT_NE(r.exitCode, 0);
    r = run("bake reflection " + scene + " --roi-min 0,0,0 -o " + path("a"));
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.err.find("go together"), std::string::npos) << r.err;
    r = run("render reflection " + path("a") + " --scene " + scene + " --camera 0,0,-3,0,0,0,30 --reflector cone -o " + path("f.png"));
    EXPECT_NE(r.exitCode, 0);
}

}  // namespace
}  // namespace conus::test
