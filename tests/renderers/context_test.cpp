#include "conus/renderers/context.h"

#include <cstdlib>
#include <string>

#include <gtest/gtest.h>

#include "conus/codec/map/sampling_map.h"
#include "conus/core/error.h"
#include "conus/renderers/backend.h"
#include "conus/renderers/gpu_image.h"
#include "gl_test_util.h"
#include "error_code.h"

namespace conus::renderers {
namespace {

// Sets an environment variable for one scope.
class ScopedEnv {
public:
    ScopedEnv(const char* name, const char* value) : m_name(name) {
        if (const char* old = std::getenv(name)) m_old = old;
        setenv(name, value, 1);
    }
    ~ScopedEnv() {
        if (m_old.empty()) unsetenv(m_name);
        else setenv(m_name, m_old.c_str(), 1);
    }

private:
    const char* m_name;
    std::string m_old;
};

using conus::test::codeOf;

TEST(ParseBackend, AcceptsEveryNameInAnyCase) {
    EXPECT_EQ(parseEnum<Backend>("auto"), Backend::Auto);
    EXPECT_EQ(parseEnum<Backend>("egl"), Backend::Egl);
    EXPECT_EQ(parseEnum<Backend>("OSMesa"), Backend::OsMesa);
    EXPECT_EQ(parseEnum<Backend>("CPU"), Backend::Cpu);
    for (Backend b : {Backend::Auto, Backend::Egl, Backend::OsMesa, Backend::Cpu})
        EXPECT_EQ(parseEnum<Backend>(enumName(b)), b);
}

TEST(ParseBackend, RejectsUnknownNamesListingTheValidOnes) {
    for (const char* bad : {"vulkan", "", "egl ", "gl"}) {
        std::string message;
        EXPECT_EQ(codeOf([&] { parseEnum<Backend>(bad); }, &message), ErrorCode::InvalidArgument) << bad;
        EXPECT_NE(message.find("osmesa"), std::string::npos) << message;
    }
}

TEST(Context, CpuBackendHasNoContext) {
    std::string message;
    EXPECT_EQ(codeOf([] { Context::create(Backend::Cpu); }, &message), ErrorCode::InvalidArgument);
    EXPECT_NE(message.find("cpu"), std::string::npos) << message;
}

// Both backends work on every machine CI runs on (Mesa llvmpipe): not working is a failure.
TEST(Context, ProbeFindsEglAndOsMesaWorking) {
    const std::vector<BackendStatus> statuses = probeBackends();
    ASSERT_EQ(statuses.size(), 3u);
    EXPECT_EQ(statuses[0].backend, Backend::Egl);
    EXPECT_EQ(statuses[1].backend, Backend::OsMesa);
    EXPECT_EQ(statuses[2].backend, Backend::Cpu);
    for (const BackendStatus& s : statuses) {
        std::printf("    %-6s works=%d renderer='%s' version='%s' (%s)\n", enumName(s.backend), s.works,
                    s.renderer.c_str(), s.version.c_str(), s.reason.c_str());
        EXPECT_TRUE(s.works) << enumName(s.backend) << ": " << s.reason;
    }
    // OSMesa is always Mesa's software rasterizer; EGL is too unless it found a hardware device.
    EXPECT_NE(statuses[1].renderer.find("llvmpipe"), std::string::npos) << statuses[1].renderer;
    if (statuses[0].reason.find("(hardware)") == std::string::npos) {
        EXPECT_NE(statuses[0].renderer.find("llvmpipe"), std::string::npos) << statuses[0].renderer;
    }
    for (int i = 0; i < 2; ++i) EXPECT_NE(statuses[i].version.find("4.5"), std::string::npos) << statuses[i].version;
}

TEST(Context, AutoPrefersEgl) {
    auto context = Context::create(Backend::Auto);
    EXPECT_EQ(context->backend(), Backend::Egl);
    EXPECT_FALSE(context->renderer().empty());
    EXPECT_GE(context->maxTextureSize(), 4096);
    EXPECT_NE(context->description().find("EGL"), std::string::npos) << context->description();
}

TEST(Context, DisabledBackendGivesAClearErrorAndAutoFallsBack) {
    {
        ScopedEnv env("CONUS_GL_DISABLE", "egl");
        std::string message;
        EXPECT_EQ(codeOf([] { Context::create(Backend::Egl); }, &message), ErrorCode::Unsupported);
        EXPECT_NE(message.find("egl: disabled by CONUS_GL_DISABLE"), std::string::npos) << message;
        auto fallback = Context::create(Backend::Auto);
        EXPECT_EQ(fallback->backend(), Backend::OsMesa);
        const auto statuses = probeBackends();
        EXPECT_FALSE(statuses[0].works);
        EXPECT_TRUE(statuses[1].works);
    }
    {
        ScopedEnv env("CONUS_GL_DISABLE", "EGL,osmesa");
        std::string message;
        EXPECT_EQ(codeOf([] { Context::create(Backend::Auto); }, &message), ErrorCode::Unsupported);
        EXPECT_NE(message.find("egl: disabled"), std::string::npos) << message;
        EXPECT_NE(message.find("osmesa: disabled"), std::string::npos) << message;
    }
    EXPECT_EQ(Context::create(Backend::Auto)->backend(), Backend::Egl);
}

// Each EGL platform on its own: the device platform's software device, then surfaceless.
TEST(Context, EglSurfacelessPlatformWorksWhenTheDevicePlatformIsRefused) {
    const Image source = test::photoLike(96, 64);
    const codec::SamplingMap map = test::randomFociMap(2);
    codec::EncodeOptions options;
    options.width = 48;
    options.height = 40;
    auto device = Context::create(Backend::Egl);
    EXPECT_NE(device->description().find("device platform"), std::string::npos) << device->description();
    const Image a = encodeImageGpu(*device, source, map, options);
    ScopedEnv env("CONUS_GL_DISABLE", "egl-device");
    auto surfaceless = Context::create(Backend::Egl);
    EXPECT_NE(surfaceless->description().find("surfaceless platform"), std::string::npos)
        << surfaceless->description();
    EXPECT_NE(surfaceless->description().find("egl-device: disabled by CONUS_GL_DISABLE"), std::string::npos)
        << surfaceless->description();
    EXPECT_EQ(encodeImageGpu(*surfaceless, source, map, options).pixels, a.pixels);
}

// EGL really failing (no vendor library for glvnd to load), not only disabled: the error names EGL
// and why. Runs in a fresh process (a threadsafe death test re-executes the binary), since EGL
// reads its vendor configuration once per process.
TEST(ContextDeathTest, BrokenEglGivesAClearErrorAndAutoFallsBackToOsMesa) {
    GTEST_FLAG_SET(death_test_style, "threadsafe");
    EXPECT_EXIT(
        {
            setenv("__EGL_VENDOR_LIBRARY_FILENAMES", "/nonexistent/egl_vendor.json", 1);
            setenv("__EGL_VENDOR_LIBRARY_DIRS", "/nonexistent", 1);
            try {
                Context::create(Backend::Egl);
                std::fprintf(stderr, "EGL unexpectedly worked\n");
                std::exit(1);
            } catch (const Error& e) {
                std::fprintf(stderr, "refused: %s\n", e.what());
                if (e.code() != ErrorCode::Unsupported) std::exit(2);
            }
            auto context = Context::create(Backend::Auto);
            std::exit(context->backend() == Backend::OsMesa ? 0 : 3);
        },
        ::testing::ExitedWithCode(0), "refused: no OpenGL 4.5 context \\(egl: ");
}

// EGL and OSMesa contexts alive together, used in turn: each call must bind its own context and
// function table (Mesa shares one dispatch between them), and both give identical results.
TEST(Context, BackendsInterleaveInOneProcess) {
    auto egl = Context::create(Backend::Egl);
    auto osmesa = Context::create(Backend::OsMesa);
    const Image source = test::photoLike(128, 96);
    const codec::SamplingMap map = test::randomFociMap(3);
    codec::EncodeOptions options;
    options.width = 64;
    options.height = 48;
    const Image a = encodeImageGpu(*egl, source, map, options);
    const Image b = encodeImageGpu(*osmesa, source, map, options);
    const Image c = encodeImageGpu(*egl, source, map, options);
    osmesa.reset();
    const Image d = encodeImageGpu(*egl, source, map, options);
    EXPECT_EQ(a.pixels, b.pixels);
    EXPECT_EQ(a.pixels, c.pixels);
    EXPECT_EQ(a.pixels, d.pixels);
}

}  // namespace
TEST(Device, TheOneDispatchChoosesByTheOrderedListAndTheSoftwareRule) {
    EXPECT_TRUE(isSoftwareRasterizer("llvmpipe (LLVM 15.0.6, 256 bits)"));
    EXPECT_TRUE(isSoftwareRasterizer("softpipe"));
    EXPECT_FALSE(isSoftwareRasterizer("NVIDIA H100 80GB HBM3/PCIe/SSE2"));
    // The CPU by name, where there is a CPU path; refused, naming the work, where there is none.
    EXPECT_FALSE(Device::choose(Backend::Cpu, CpuPath::Available, "encoding").onGpu());
    std::string message;
    EXPECT_EQ(codeOf([&] { Device::choose(Backend::Cpu, CpuPath::None, "terrain rendering"); }, &message),
              ErrorCode::InvalidArgument);
    EXPECT_NE(message.find("terrain rendering needs GL"), std::string::npos) << message;
    // GL by name is GL; auto without a CPU path is GL on any rasterizer.
    EXPECT_EQ(Device::choose(Backend::OsMesa, CpuPath::Available, "encoding").backend(), Backend::OsMesa);
    const Device needsGl = Device::choose(Backend::Auto, CpuPath::None, "terrain rendering");
    ASSERT_TRUE(needsGl.onGpu());
    // auto with a CPU path: the CPU on a software rasterizer, the GPU on hardware.
    const Device automatic = Device::choose(Backend::Auto, CpuPath::Available, "encoding");
    EXPECT_EQ(automatic.onGpu(), !prefersCpu(needsGl.context()));
    EXPECT_EQ(automatic.describe() == "cpu", !automatic.onGpu());
    // auto where the CPU path measured faster than any GPU (image encode, decode): the CPU, with GL
    // working beside it; GL by name still GL.
    EXPECT_FALSE(Device::choose(Backend::Auto, CpuPath::Faster, "decoding").onGpu());
    EXPECT_EQ(Device::choose(Backend::OsMesa, CpuPath::Faster, "decoding").backend(), Backend::OsMesa);
    // No GL at all: auto falls back to the CPU where it can, and says why where it cannot.
    ScopedEnv off("CONUS_GL_DISABLE", "egl,osmesa");
    EXPECT_FALSE(Device::choose(Backend::Auto, CpuPath::Available, "encoding").onGpu());
    EXPECT_EQ(codeOf([&] { Device::choose(Backend::Auto, CpuPath::None, "terrain rendering"); }, &message),
              ErrorCode::Unsupported);
}

TEST(Device, RunTakesThePathOfTheDevice) {
    const Device cpu = Device::cpu();
    EXPECT_EQ(cpu.run([] { return 1; }, [](Context&) { return 2; }), 1);
    const Device gpu = Device::on(Context::create(Backend::OsMesa));
    EXPECT_EQ(gpu.run([] { return 1; }, [](Context& c) { return c.backend() == Backend::OsMesa ? 2 : 3; }), 2);
    EXPECT_EQ(codeOf([&] { cpu.context(); }), ErrorCode::InvalidArgument);
}

}  // namespace conus::renderers
