// The mipmapped GL encoder (gpu_image.h) against the CPU's anisotropic kernel and analytic
// expectations, on varied asymmetric pictures (partial alpha, any channel count), and `auto`'s
// choice of device for encodes (Device::choose with CpuPath::Measured).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "conus/codec/builders/foci.h"
#include "conus/codec/image/encode.h"
#include "conus/codec/image/metrics.h"
#include "conus/renderers/backend.h"
#include "conus/renderers/gpu_image.h"
#include "gl_test_util.h"

namespace conus::renderers {
namespace {

using test::contextFor;

// The bound on what a viewer sees: GL against the CPU, both rounded to 8-bit sRGB codes.
constexpr double kSrgb8Psnr = 45.0;
// Where the driver's own anisotropic filter takes part.
constexpr double kNearPsnr = 30.0;

double toSrgb(double v) { return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055; }
double toLinear(double s) { return s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4); }
int code8(double v) { return static_cast<int>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0)); }

// PSNR of two images as 8-bit codes: colour through the sRGB curve, alpha and other channels as
// they are; peak 255.
double psnrSrgb8(const Image& a, const Image& b) {
    EXPECT_EQ(a.channels, b.channels);
    double sum = 0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i) {
        const std::string& name = a.channels[i % a.channels.size()];
        const bool colour = name == "R" || name == "G" || name == "B";
        const int ca = code8(colour ? toSrgb(std::max(0.0f, a.pixels[i])) : a.pixels[i]);
        const int cb = code8(colour ? toSrgb(std::max(0.0f, b.pixels[i])) : b.pixels[i]);
        sum += double(ca - cb) * (ca - cb);
    }
    const double mse = sum / a.pixels.size();
    return mse == 0 ? 99.0 : 10 * std::log10(255.0 * 255.0 / mse);
}

// The picture as an 8-bit file gives it: every value its sRGB code's linear value.
Image rounded8Bit(Image image) {
    for (float& v : image.pixels) v = static_cast<float>(toLinear(code8(toSrgb(std::max(0.0f, v))) / 255.0));
    return image;
}

// photoLike with an alpha channel that varies (0 .. 1, a transparent hole, a soft ramp), colours
// premultiplied as CoNUS keeps them.
Image withPartialAlpha(int w, int h, unsigned seed) {
    Image im = test::photoLike(w, h, {"R", "G", "B", "A"}, seed);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const double u = (x + 0.5) / w, v = (y + 0.5) / h;
            double a = std::clamp(0.2 + 0.9 * u * (1.0 - 0.4 * v), 0.0, 1.0);
            if ((u - 0.7) * (u - 0.7) + (v - 0.3) * (v - 0.3) < 0.01) a = 0;
            im.at(x, y, 3) = static_cast<float>(a);
            for (int c = 0; c < 3; ++c) im.at(x, y, c) = static_cast<float>(std::clamp<double>(im.at(x, y, c), 0, 1) * a);
        }
    return im;
}

codec::EncodeOptions sized(int w, int h) {
    codec::EncodeOptions o;
    o.width = w;
    o.height = h;
    return o;  // the default filter: anisotropic
}

class GpuEncodeMip : public ::testing::TestWithParam<Backend> {
protected:
    Context& context() { return contextFor(GetParam()); }

    // GL (the mipmapped encoder with `gpu`) against the CPU's anisotropic kernel, 8-bit sRGB PSNR.
    double psnrAgainstCpu(const Image& source, const codec::SamplingMap& map, int w, int h, GpuEncodeOptions gpu,
                          const std::string& expectPath) {
        gpu.kernel = GpuEncodeKernel::Mipmapped;
        const Image cpu = codec::encodeImage(source, map, sized(w, h));
        GpuTimings t;
        const Image gl = encodeImageGpu(context(), source, map, sized(w, h), &t, gpu);
        EXPECT_NE(t.path.find(expectPath), std::string::npos) << t.path;
        const double psnr = psnrSrgb8(cpu, gl);
        std::printf("    %dx%d %s -> %dx%d, map %dx%d, %s, %s: %.2f dB (8-bit sRGB) against the CPU; upload %.0f, draw "
                    "%.0f, readback %.0f ms\n",
                    source.width, source.height, source.channelCount() == 4 ? "RGBA" : "RGB", w, h, map.columns(),
                    map.rows(), enumName(GetParam()), t.path.c_str(), psnr, t.uploadMs, t.drawMs, t.readbackMs);
        return psnr;
    }
};

// The CPU's anisotropic kernel on both of GL's sampling ways (a trilinear sample per tap, and the
// sampler's anisotropic filter for up to four taps), on focus maps, random maps and a jittered grid.
TEST_P(GpuEncodeMip, MatchesTheCpuAnisotropicKernel) {
    const Image opaque = rounded8Bit(test::photoLike(533, 389, {"R", "G", "B"}, 3));
    const Image alpha = withPartialAlpha(401, 517, 5);
    const std::vector<codec::SamplingMap> maps = {
        codec::buildFociMap(std::vector<codec::Focus>{{0.3, 0.35, 0.08, 4}, {0.7, 0.6, 0.06, 3}}), test::randomFociMap(2),
        test::jitteredMap(7, 5, 0.3, 4)};
    for (const codec::SamplingMap& map : maps) {
        EXPECT_GE(psnrAgainstCpu(opaque, map, 181, 127, {}, "srgb8, anisotropy 1"), kSrgb8Psnr);
        EXPECT_GE(psnrAgainstCpu(alpha, map, 133, 170, {}, "half, anisotropy 1"), kSrgb8Psnr);
    }
}

// The sampler's anisotropic filter for up to four taps at once: the driver's own filter within each
// sample (llvmpipe's is an elliptical Gaussian, wider than the box), so only near the CPU kernel.
TEST_P(GpuEncodeMip, TheSamplersAnisotropicFilterStaysNearTheCpuKernel) {
    const Image opaque = rounded8Bit(test::photoLike(533, 389, {"R", "G", "B"}, 3));
    GpuEncodeOptions gpu;
    gpu.anisotropy = 4;
    EXPECT_GE(psnrAgainstCpu(opaque, test::jitteredMap(7, 5, 0.3, 4), 181, 127, gpu, "srgb8, anisotropy 4"), kNearPsnr);
    EXPECT_GE(psnrAgainstCpu(opaque, test::randomFociMap(2), 181, 127, gpu, "srgb8, anisotropy 4"), kNearPsnr);
}

// An 8-bit picture goes up as 8-bit sRGB, exactly: the half-float upload of the same picture
// gives the same encode to well under a code.
TEST_P(GpuEncodeMip, EightBitPicturesUploadAsSrgb8Exactly) {
    const Image source = rounded8Bit(test::photoLike(300, 200, {"R", "G", "B"}, 11));
    const codec::SamplingMap map = test::randomFociMap(1);
    GpuEncodeOptions srgb, half;
    half.upload = GpuUpload::Half;
    GpuTimings ts, th;
    const Image a = encodeImageGpu(context(), source, map, sized(120, 90), &ts, srgb);
    const Image b = encodeImageGpu(context(), source, map, sized(120, 90), &th, half);
    EXPECT_NE(ts.path.find("srgb8"), std::string::npos) << ts.path;
    EXPECT_NE(th.path.find("half"), std::string::npos) << th.path;
    const double psnr = psnrSrgb8(a, b);
    std::printf("    srgb8 against half upload: %.2f dB (8-bit sRGB)\n", psnr);
    EXPECT_GE(psnr, 48.0);
    // Not 8-bit values: half floats, unless 8-bit is forced (then it is rounded, and stays close).
    Image smooth = test::photoLike(300, 200, {"R", "G", "B"}, 11);
    for (float& v : smooth.pixels) v = std::clamp(v, 0.0f, 1.0f);  // what 8-bit can hold
    GpuTimings t;
    encodeImageGpu(context(), smooth, map, sized(120, 90), &t);
    EXPECT_NE(t.path.find("half"), std::string::npos) << t.path;
    GpuEncodeOptions forced;
    forced.upload = GpuUpload::Srgb8;
    const Image rounded = encodeImageGpu(context(), smooth, map, sized(120, 90), &t, forced);
    EXPECT_NE(t.path.find("srgb8"), std::string::npos) << t.path;
    EXPECT_GE(psnrSrgb8(rounded, codec::encodeImage(smooth, map, sized(120, 90))), kSrgb8Psnr);
}

// Under the identity map at integer power-of-two ratios the kernel is the exact area average
// (each CoNUS pixel the mean of its source block), whatever the picture; a constant picture stays
// that constant everywhere, also under a focus map.
TEST_P(GpuEncodeMip, IdentityMapGivesTheAreaAverage) {
    GpuEncodeOptions gpu;
    gpu.kernel = GpuEncodeKernel::Mipmapped;
    for (const int ratio : {2, 4, 8}) {
        const Image source = withPartialAlpha(64 * ratio, 48 * ratio, 9);
        const Image gl = encodeImageGpu(context(), source, codec::SamplingMap::identity(9, 9), sized(64, 48), nullptr, gpu);
        const Image average = codec::areaDownsample(source, 64, 48);
        const double psnr = codec::psnr(gl, average);
        std::printf("    identity map, %d:1: %.2f dB (linear) against the area average\n", ratio, psnr);
        EXPECT_GE(psnr, 70.0);
    }
    Image flat = makeImage(300, 170, {"R", "G", "B", "A"});
    const float value[4] = {0.25f, 0.5f, 0.125f, 0.75f};  // exact in half floats
    for (std::size_t i = 0; i < flat.pixels.size(); ++i) flat.pixels[i] = value[i % 4];
    const Image gl = encodeImageGpu(context(), flat, test::randomFociMap(3), sized(97, 61), nullptr, gpu);
    float worst = 0;
    for (std::size_t i = 0; i < gl.pixels.size(); ++i) worst = std::max(worst, std::abs(gl.pixels[i] - value[i % 4]));
    EXPECT_LE(worst, 1e-5f);
}

// Passes of four channels: 1, 2 and 5 channels (Y; Y, A; R, G, B, A, Z) against the CPU.
TEST_P(GpuEncodeMip, HandlesAnyChannelCount) {
    const codec::SamplingMap map = test::randomFociMap(4);
    GpuEncodeOptions gpu;
    gpu.kernel = GpuEncodeKernel::Mipmapped;
    for (const std::vector<std::string>& channels :
         {std::vector<std::string>{"Y"}, {"Y", "A"}, {"R", "G", "B", "A", "Z"}}) {
        const Image source = test::photoLike(250, 190, channels, 13);
        const Image cpu = codec::encodeImage(source, map, sized(100, 80));
        const Image gl = encodeImageGpu(context(), source, map, sized(100, 80), nullptr, gpu);
        ASSERT_EQ(gl.channels, channels);
        EXPECT_GE(codec::psnr(cpu, gl), 40.0) << channels.size() << " channels";
    }
    // 8-bit forced: the R, G, B, A pass only; Z stays half.
    Image source = test::photoLike(250, 190, {"R", "G", "B", "A", "Z"}, 13);
    for (float& v : source.pixels) v = std::clamp(v, 0.0f, 1.0f);
    gpu.upload = GpuUpload::Srgb8;
    GpuTimings t;
    const Image gl = encodeImageGpu(context(), source, map, sized(100, 80), &t, gpu);
    EXPECT_NE(t.path.find("srgb8+half"), std::string::npos) << t.path;
    EXPECT_GE(psnrSrgb8(codec::encodeImage(source, map, sized(100, 80)), gl), kSrgb8Psnr);
}

// Auto takes the kernel the CPU takes: mipmapped for the anisotropic filter under a map that is
// not uniform; the EWA encoder for the EWA filter, under the identity, and past the texture limit.
TEST_P(GpuEncodeMip, AutoTakesTheCpusKernel) {
    const Image source = test::photoLike(160, 120);
    const auto path = [&](const codec::SamplingMap& map, codec::EncodeFilter filter) {
        codec::EncodeOptions o = sized(64, 48);
        o.filter = filter;
        GpuTimings t;
        encodeImageGpu(context(), source, map, o, &t);
        return t.path;
    };
    EXPECT_EQ(path(test::randomFociMap(1), codec::EncodeFilter::Anisotropic).rfind("mipmapped", 0), 0u);
    EXPECT_EQ(path(test::randomFociMap(1), codec::EncodeFilter::Ewa), "ewa");
    EXPECT_EQ(path(codec::SamplingMap::identity(5, 5), codec::EncodeFilter::Anisotropic), "ewa");
}

INSTANTIATE_TEST_SUITE_P(Backends, GpuEncodeMip, ::testing::Values(Backend::Egl, Backend::OsMesa), test::paramName);

// `auto` for encodes: GL exactly where the probe says GL is faster, asked of a real context (here
// llvmpipe, with the answer given); the CPU when the probe says no, or there is none; a backend
// asked for by name whatever the probe says.
TEST(EncodeDevice, AutoFollowsTheProbe) {
    int asked = 0;
    const auto probe = [&](bool faster) {
        return SpeedProbe{[&asked, faster](Context& context) {
                              ++asked;
                              EXPECT_FALSE(context.renderer().empty());
                              return faster;
                          },
                          true};
    };
    EXPECT_TRUE(Device::choose(Backend::Auto, CpuPath::Measured, "encoding", probe(true)).onGpu());
    EXPECT_FALSE(Device::choose(Backend::Auto, CpuPath::Measured, "encoding", probe(false)).onGpu());
    EXPECT_EQ(asked, 2);
    EXPECT_FALSE(Device::choose(Backend::Auto, CpuPath::Measured, "encoding").onGpu());
    EXPECT_FALSE(Device::choose(Backend::Cpu, CpuPath::Measured, "encoding", probe(true)).onGpu());
    EXPECT_TRUE(Device::choose(Backend::Egl, CpuPath::Measured, "encoding", probe(false)).onGpu());
    EXPECT_EQ(asked, 2);
}

// The real probe measures both paths once per process and then keeps its answer.
TEST(EncodeDevice, TheProbeMeasuresOnce) {
    Context& context = contextFor(Backend::Egl);
    const EncodeSpeed first = measureEncodeSpeed(context);
    EXPECT_GT(first.glMs, 0.0);
    EXPECT_GT(first.cpuMs, 0.0);
    const EncodeSpeed again = measureEncodeSpeed(context);
    EXPECT_EQ(again.glMs, first.glMs);
    EXPECT_EQ(again.cpuMs, first.cpuMs);
    // The probe itself leaves a software rasterizer unmeasured: the CPU.
    EXPECT_EQ(encodeSpeedProbe().glFaster(context), first.glFaster() && !prefersCpu(context));
    std::printf("    probe on %s: GL %.1f ms, CPU %.1f ms: auto takes %s\n", context.renderer().c_str(), first.glMs,
                first.cpuMs, first.glFaster() ? "GL" : "the CPU");
}

}  // namespace
}  // namespace conus::renderers
