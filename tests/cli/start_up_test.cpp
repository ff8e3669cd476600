// What `conus` loads before it does anything. OpenImageIO (with its ~260 libraries), OpenCV's
// detectors and OSMesa (with LLVM) load when a command first needs them (core/plugin.h), never at
// start-up; a plain PNG source is read with libpng and loads none of them. Read from the dynamic
// loader's own log (LD_DEBUG=files), not from timings.
#include <gtest/gtest.h>

#include <cstdlib>
#include <sstream>
#include <string>

#include "cli_fixture.h"

using namespace conus::test;

namespace {

// Whether the loader's log names `library` as a file it loaded (by name or by path: "file=...").
bool loads(const Result& r, const std::string& library) {
    std::istringstream log(r.err);
    for (std::string line; std::getline(log, line);) {
        const std::size_t file = line.find("file=");
        if (file != std::string::npos && line.find(library, file) != std::string::npos) return true;
    }
    return false;
}

TEST_F(Cli, StartUpLoadsNoHeavyLibraryUntilACommandNeedsIt) {
    const std::string picture = makePicture(64, 48);
    const std::string tiff = makePicture(64, 48, "in.tif");
    ::setenv("LD_DEBUG", "files", 1);
    const Result help = run("--help");
    const Result backends = run("info --backends");
    const Result uniform = run("uniform " + picture + " -o " + (m_dir / "u.exr").string() + " --size 32x24 -q");
    const Result uniformTiff = run("uniform " + tiff + " -o " + (m_dir / "t.exr").string() + " --size 32x24 -q");
    ::unsetenv("LD_DEBUG");
    ASSERT_EQ(help.exitCode, 0) << help.err;
    ASSERT_EQ(backends.exitCode, 0) << backends.err;
    ASSERT_EQ(uniform.exitCode, 0) << uniform.err;
    ASSERT_EQ(uniformTiff.exitCode, 0) << uniformTiff.err;
    ASSERT_TRUE(loads(help, "libconus_codec")) << "the loader's log was not captured:\n" << help.err;
    for (const char* heavy : {"libOpenImageIO", "libopencv_", "libOSMesa", "libLLVM", "libgdal", "libavcodec"})
        EXPECT_FALSE(loads(help, heavy)) << "conus --help loaded " << heavy;
    // Each loads with the command that needs it, and only then.
    EXPECT_TRUE(loads(backends, "libOSMesa"));
    EXPECT_FALSE(loads(backends, "libOpenImageIO"));
    EXPECT_FALSE(loads(uniform, "libOpenImageIO"));  // a plain 8-bit RGB PNG: libpng directly
    EXPECT_TRUE(loads(uniform, "libpng"));
    EXPECT_TRUE(loads(uniformTiff, "libOpenImageIO"));
    EXPECT_TRUE(loads(uniformTiff, "libconus_imageio_oiio"));
    EXPECT_FALSE(loads(uniformTiff, "libopencv_objdetect"));  // the face detector's module is not loaded
}

}  // namespace
