// `conus encode` on GL against the CPU, through the real binary: the GL encoder (8-bit sRGB upload,
// mipmaps) gives what the CPU gives, read back by OpenImageIO, and `--backend auto` says where it ran.
#include <cmath>
#include <string>

#include "cli_fixture.h"

namespace conus::test {
namespace {

// Whether this machine has a device node a hardware GL driver could use (renderers/backend.cpp's
// rule): without one, `auto` encodes on the CPU without measuring.
bool hasGpuDeviceNode() {
    std::error_code ec;
    for (const char* node : {"/dev/nvidiactl", "/dev/nvidia0", "/dev/dxg"})
        if (fs::exists(node, ec)) return true;
    for (fs::directory_iterator it("/dev/dri", ec), end; !ec && it != end; it.increment(ec))
        if (it->path().filename().string().rfind("renderD", 0) == 0) return true;
    return false;
}

double srgbCode(float v) {
    const double x = std::clamp(static_cast<double>(v), 0.0, 1.0);
    return std::round(255.0 * (x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1 / 2.4) - 0.055));
}

TEST_F(Cli, EncodeOnGlMatchesTheCpu) {
    const std::string in = makePicture(331, 229);
    const std::string common = " --focus 0.3,0.4,0.1,4 --size 120x90 --fast --float";
    const Result gl = run("encode " + in + " -o " + path("gl.exr") + common + " --backend egl");
    ASSERT_EQ(gl.exitCode, 0) << gl.err;
    EXPECT_NE(gl.err.find("(egl: "), std::string::npos) << gl.err;  // the progress line names the device
    const Result cpu = run("encode " + in + " -o " + path("cpu.exr") + common + " --backend cpu");
    ASSERT_EQ(cpu.exitCode, 0) << cpu.err;
    EXPECT_EQ(cpu.err.find("(egl: "), std::string::npos) << cpu.err;
    const ExrRead a = readExr(path("gl.exr")), b = readExr(path("cpu.exr"));
    ASSERT_EQ(a.width, 120);
    ASSERT_EQ(b.width, 120);
    double se = 0;
    std::size_t n = 0;
    for (const char* name : {"R", "G", "B"}) {
        const std::vector<float>& x = a.channels.at(name);
        const std::vector<float>& y = b.channels.at(name);
        ASSERT_EQ(x.size(), y.size());
        for (std::size_t i = 0; i < x.size(); ++i, ++n) se += std::pow(srgbCode(x[i]) - srgbCode(y[i]), 2.0);
    }
    const double psnr = se == 0 ? 99.0 : 10 * std::log10(255.0 * 255.0 / (se / n));
    std::printf("    conus encode --backend egl against --backend cpu: %.2f dB (8-bit sRGB)\n", psnr);
    // The picture's stripes run up to near the source's Nyquist rate, and at this odd size GL's mip
    // levels (rounded down) sample them on other grids than the CPU's (rounded up): 43.8 dB
    // measured on llvmpipe, where photographs give 49-57 dB (renderers_tests).
    EXPECT_GE(psnr, 40.0);
    // Without a GPU device node `auto` encodes on the CPU; with one, where its measurement says.
    const Result automatic = run("encode " + in + " -o " + path("auto.exr") + common);
    ASSERT_EQ(automatic.exitCode, 0) << automatic.err;
    if (!hasGpuDeviceNode()) EXPECT_EQ(automatic.err.find("(egl: "), std::string::npos) << automatic.err;
    EXPECT_TRUE(leftovers().empty());
}

}  // namespace
}  // namespace conus::test
