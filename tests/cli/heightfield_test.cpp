// `conus heightfield` and the height-field decode through the real binary: a round trip, and the
// default map against the uniform one from the ground map's own viewer.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "cli/cli_fixture.h"
#include "conus/format/container.h"

namespace conus::test {
namespace {

TEST_F(Cli, HeightFieldEncodeDecodeAndCompare) {
    Result r = run("heightfield encode procedural:256:7 -o " + path("t.exr") + " --size 64x64");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(run("validate " + path("t.exr")).exitCode, 0);
    const auto file = conus::format::readConusFile(path("t.exr"));
    EXPECT_EQ(file.dataKind, conus::format::DataKind::HeightField);
    EXPECT_GE(file.image.channelIndex("Z"), 0);

    r = run("decode " + path("t.exr") + " --camera viewer -o " + path("frame.png") + " --size 160x90");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(imageSize(path("frame.png")), std::make_pair(160, 90));
    r = run("decode " + path("t.exr") + " --camera viewer -o " + path("cpu.png") + " --backend cpu");
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.err.find("needs GL"), std::string::npos) << r.err;

    r = run("render heightfield " + path("t.exr") + " -o " + path("cmp.png") + " --size 160x90 --compare procedural:256:7");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.out.find("PSNR vs full resolution: CoNUS"), std::string::npos) << r.out;

    // An image is not a height field: asking for a 3-D frame of it says so.
    ASSERT_NO_FATAL_FAILURE(makeUniformFile());
    r = run("decode " + path("u.exr") + " --camera viewer -o " + path("x.png"));
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.err.find("not a CoNUS height field"), std::string::npos) << r.err;
}

// The default height field beats the uniform one of the same sample count from the ground map's
// own viewer, on several terrains and a real DEM (matplotlib's Jacksboro fault, a Debian package).
TEST_F(Cli, TheDefaultHeightFieldBeatsUniformFromItsViewer) {
    const std::vector<std::pair<std::string, std::string>> dems{
        {"procedural:512:1", "128x128"}, {"procedural:512:7", "128x128"}, {"procedural:512:11", "128x128"},
        {"procedural:512:23", "128x128"},
        {"/usr/share/matplotlib/mpl-data/sample_data/jacksboro_fault_dem.npz", "96x96"}};
    for (const auto& [dem, size] : dems) {
        SCOPED_TRACE(dem);
        Result r = run("heightfield encode " + dem + " -o " + path("t.exr") + " --size " + size);
        ASSERT_EQ(r.exitCode, 0) << r.err;
        EXPECT_NE(r.out.find("terrain rows"), std::string::npos) << r.out;
        r = run("render heightfield " + path("t.exr") + " -o " + path("cmp.png") + " --size 320x180 --compare " + dem);
        ASSERT_EQ(r.exitCode, 0) << r.err;
        const std::size_t line = r.out.find("PSNR vs full resolution:");
        ASSERT_NE(line, std::string::npos) << r.out;
        double conusDb = 0, uniformDb = 0;
        ASSERT_EQ(std::sscanf(r.out.c_str() + line, "PSNR vs full resolution: CoNUS %lf dB, uniform %lf dB", &conusDb, &uniformDb), 2)
            << r.out;
        EXPECT_GT(conusDb, uniformDb + 0.3) << r.out;
    }
}

}  // namespace
}  // namespace conus::test
