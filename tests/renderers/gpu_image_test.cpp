#include "conus/core/map_rules.h"
#include "conus/renderers/gpu_image.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <filesystem>
#include <vector>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include "conus/codec/image/decode.h"
#include "conus/codec/image/encode.h"
#include "conus/codec/builders/foci.h"
#include "conus/codec/image/metrics.h"
#include "conus/core/error.h"
#include "gl_test_util.h"

namespace conus::renderers {
namespace {

using test::contextFor;

constexpr double kEncodePsnr = 45.0;
constexpr double kDecodePsnr = 50.0;

// The GL encoder is the EWA filter's twin: the CPU reference it is compared with is that filter.
codec::EncodeOptions encodeSize(int w, int h) {
    codec::EncodeOptions o;
    o.width = w;
    o.height = h;
    o.filter = codec::EncodeFilter::Ewa;
    return o;
}

codec::DecodeOptions decodeView(codec::View view, int w, int h) {
    codec::DecodeOptions o;
    o.view = view;
    o.width = w;
    o.height = h;
    return o;
}

codec::SamplingMap twoFoci() {
    const std::vector<codec::Focus> foci = {{0.3, 0.35, 0.08, 4}, {0.7, 0.6, 0.06, 3}};
    return codec::buildFociMap(foci);
}

// The skimage sample photos when installed (OpenImageIO reads them), as float RGB; empty if not.
Image readPhoto(const std::string& name) {
    const std::string path = "/usr/lib/python3/dist-packages/skimage/data/" + name;
    if (!std::filesystem::exists(path)) return {};
    auto in = OIIO::ImageInput::open(path);
    if (!in) return {};
    const OIIO::ImageSpec& spec = in->spec();
    std::vector<float> all(static_cast<std::size_t>(spec.width) * spec.height * spec.nchannels);
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data())) return {};
    Image im = makeImage(spec.width, spec.height, {"R", "G", "B"});
    for (std::size_t i = 0; i < static_cast<std::size_t>(spec.width) * spec.height; ++i)
        for (int c = 0; c < 3; ++c) im.pixels[i * 3 + c] = all[i * spec.nchannels + std::min(c, spec.nchannels - 1)];
    return im;
}

// Lowers the GPU paths' texture limit (CONUS_GL_MAX_TEXTURE) for its lifetime.
class TextureLimit {
public:
    explicit TextureLimit(const std::string& value) {
        if (const char* old = std::getenv(kVariable)) m_old = old;
        setenv(kVariable, value.c_str(), 1);
    }
    ~TextureLimit() {
        if (m_old.empty()) unsetenv(kVariable);
        else setenv(kVariable, m_old.c_str(), 1);
    }
    TextureLimit(const TextureLimit&) = delete;
    TextureLimit& operator=(const TextureLimit&) = delete;

private:
    static constexpr const char* kVariable = "CONUS_GL_MAX_TEXTURE";
    std::string m_old;
};

class GpuImage : public ::testing::TestWithParam<Backend> {
protected:
    Context& context() { return contextFor(GetParam()); }

    double encodePsnr(const Image& source, const codec::SamplingMap& map, int w, int h) {
        const Image cpu = codec::encodeImage(source, map, encodeSize(w, h));
        const Image gpu = encodeImageGpu(context(), source, map, encodeSize(w, h));
        EXPECT_EQ(gpu.channels, source.channels);
        const double psnr = codec::psnr(cpu, gpu);
        std::printf("    encode %dx%d -> %dx%d, map %dx%d, %s: PSNR %.2f dB\n", source.width, source.height, w, h,
                    map.columns(), map.rows(), enumName(GetParam()), psnr);
        return psnr;
    }

    double decodePsnr(const Image& conus, const codec::SamplingMap& map, codec::View view, int w, int h) {
        const Image cpu = codec::decodeImage(conus, map, decodeView(view, w, h));
        const Image gpu = decodeImageGpu(context(), conus, map, decodeView(view, w, h));
        EXPECT_EQ(gpu.channels, conus.channels);
        const double psnr = codec::psnr(cpu, gpu);
        std::printf("    decode %dx%d view (%.2f,%.2f)-(%.2f,%.2f) -> %dx%d, %s: PSNR %.2f dB\n", conus.width,
                    conus.height, view.u0, view.v0, view.u1, view.v1, w, h, enumName(GetParam()), psnr);
        return psnr;
    }
};

TEST_P(GpuImage, RunsOnTheBackendAskedFor) {
    EXPECT_EQ(context().backend(), GetParam());
    EXPECT_FALSE(context().renderer().empty());
}

TEST_P(GpuImage, EncodeMatchesCpuWithIdentityMap) {
    const Image source = test::photoLike(512, 512);
    // Integer ratios (exact box filters on the CPU), a non-integer ratio, and magnification.
    EXPECT_GE(encodePsnr(source, codec::SamplingMap::identity(map_rules::kDefaultSide, map_rules::kDefaultSide), 256, 256), kEncodePsnr);
    EXPECT_GE(encodePsnr(source, codec::SamplingMap::identity(2, 2), 128, 128), kEncodePsnr);
    EXPECT_GE(encodePsnr(source, codec::SamplingMap::identity(17, 9), 300, 200), kEncodePsnr);
    EXPECT_GE(encodePsnr(source, codec::SamplingMap::identity(9, 9), 640, 600), kEncodePsnr);
}

TEST_P(GpuImage, EncodeMatchesCpuWithFocusMap) {
    const Image source = test::photoLike(512, 512);
    EXPECT_GE(encodePsnr(source, twoFoci(), 256, 256), kEncodePsnr);
    EXPECT_GE(encodePsnr(source, twoFoci(), 128, 160), kEncodePsnr);
}

TEST_P(GpuImage, EncodeMatchesCpuWithRandomMaps) {
    const Image source = test::photoLike(384, 320, {"R", "G", "B"}, 3);
    for (unsigned seed = 1; seed <= 4; ++seed) {
        SCOPED_TRACE(seed);
        EXPECT_GE(encodePsnr(source, test::randomFociMap(seed), 192, 160), kEncodePsnr);
        EXPECT_GE(encodePsnr(source, test::jitteredMap(5 + seed, 4 + seed, 0.3, seed), 200, 180), kEncodePsnr);
    }
}

TEST_P(GpuImage, EncodeMatchesCpuOnPhotos) {
    for (const char* name : {"astronaut.png", "motorcycle_left.png"}) {
        SCOPED_TRACE(name);
        Image photo = readPhoto(name);
        if (photo.empty()) {
            std::printf("    %s not installed: a procedural image stands in\n", name);
            photo = test::photoLike(512, 384, {"R", "G", "B"}, 11);
        }
        const codec::SamplingMap map = codec::buildFociMap(std::vector<codec::Focus>{{0.45, 0.3, 0.1, 3}});
        EXPECT_GE(encodePsnr(photo, map, photo.width / 2, photo.height / 2), kEncodePsnr);
        EXPECT_GE(encodePsnr(photo, test::randomFociMap(5), photo.width / 3, photo.height / 3), kEncodePsnr);
        EXPECT_GE(encodePsnr(photo, codec::SamplingMap::identity(33, 33), photo.width / 2, photo.height / 2),
                  kEncodePsnr);
    }
}

TEST_P(GpuImage, EncodeHandlesAnyChannelCount) {
    const Image full = test::photoLike(256, 192, {"R", "G", "B", "A", "Z", "N"}, 5);
    for (int count : {1, 2, 3, 4, 5, 6}) {
        SCOPED_TRACE(count);
        Image source = makeImage(
            full.width, full.height, std::vector<std::string>(full.channels.begin(), full.channels.begin() + count));
        for (std::size_t i = 0; i < static_cast<std::size_t>(source.width) * source.height; ++i)
            for (int c = 0; c < count; ++c) source.pixels[i * count + c] = full.pixels[i * 6 + c];
        const codec::SamplingMap map = twoFoci();
        const Image cpu = codec::encodeImage(source, map, encodeSize(128, 96));
        const Image gpu = encodeImageGpu(context(), source, map, encodeSize(128, 96));
        ASSERT_EQ(gpu.channels, source.channels);
        // Per channel: each pass must land in its own channels.
        for (int c = 0; c < count; ++c) {
            Image a = makeImage(128, 96, {"Y"}), b = makeImage(128, 96, {"Y"});
            for (std::size_t i = 0; i < a.pixels.size(); ++i) {
                a.pixels[i] = cpu.pixels[i * count + c];
                b.pixels[i] = gpu.pixels[i * count + c];
            }
            EXPECT_GE(codec::psnr(a, b), kEncodePsnr) << "channel " << c;
        }
    }
}

// The edges of a checkerboard land where Equation 1 puts them: a vertical source edge at u = e
// crosses CoNUS row y where distort(e, v).y is that row's centre, at x = distort(e, v).x.
TEST_P(GpuImage, CheckerboardEdgesFollowEquation1) {
    constexpr int kSource = 512, kSquare = 64, kW = 256, kH = 256;
    Image board = makeImage(kSource, kSource, {"Y"});
    for (int y = 0; y < kSource; ++y)
        for (int x = 0; x < kSource; ++x) board.at(x, y) = float(((x / kSquare) + (y / kSquare)) % 2);
    const codec::SamplingMap map = codec::buildFociMap(std::vector<codec::Focus>{{0.4, 0.45, 0.1, 4}});
    const Image conus = encodeImageGpu(context(), board, map, encodeSize(kW, kH));

    int checked = 0;
    double worst = 0;
    for (int edge = 1; edge < kSource / kSquare; ++edge) {
        const double e = double(edge * kSquare) / kSource;
        for (int square = 0; square < kSource / kSquare; ++square) {
            // Mid-square in v, away from the horizontal edges; find the CoNUS row there.
            const double vMid = (square + 0.5) * kSquare / kSource;
            const int row = std::clamp(int(map.distort({e, vMid}).y * kH), 0, kH - 1);
            const double rowV = (row + 0.5) / kH;
            double lo = 0, hi = 1;  // v with distort(e, v).y == rowV: y grows with v along the edge
            for (int k = 0; k < 60; ++k) {
                const double mid = 0.5 * (lo + hi);
                (map.distort({e, mid}).y < rowV ? lo : hi) = mid;
            }
            const double expected = map.distort({e, lo}).x * kW - 0.5;  // in pixel-centre units
            // The 0.5 crossing of the row nearest the expected position.
            double best = 1e9;
            for (int x = std::max(0, int(expected) - 4); x < std::min(kW - 1, int(expected) + 5); ++x) {
                const double a = conus.at(x, row) - 0.5, b = conus.at(x + 1, row) - 0.5;
                if (a * b > 0 || a == b) continue;
                const double crossing = x + a / (a - b);
                if (std::abs(crossing - expected) < std::abs(best - expected)) best = crossing;
            }
            ASSERT_LT(best, 1e8) << "no edge near x = " << expected << " on row " << row;
            worst = std::max(worst, std::abs(best - expected));
            EXPECT_LE(std::abs(best - expected), 1.0) << "edge u = " << e << ", row " << row;
            ++checked;
        }
    }
    std::printf("    %d edge crossings, worst %.3f CoNUS pixels from Eq. 1\n", checked, worst);
    EXPECT_EQ(checked, 7 * 8);
}

// Runs `check(map, conus)` for a photo-like source encoded to w x h through each test map: two
// foci, then two random focus sets.
template <class Check>
void forEachEncodedMap(int w, int h, Check check) {
    const Image source = test::photoLike(512, 512);
    for (unsigned seed = 0; seed < 3; ++seed) {
        SCOPED_TRACE(seed);
        const codec::SamplingMap map = seed == 0 ? twoFoci() : test::randomFociMap(seed);
        check(map, codec::encodeImage(source, map, encodeSize(w, h)));
    }
}

TEST_P(GpuImage, DecodeMatchesCpu) {
    forEachEncodedMap(256, 256, [&](const codec::SamplingMap& map, const Image& conus) {
        EXPECT_GE(decodePsnr(conus, map, {}, 512, 512), kDecodePsnr);                      // full frame
        EXPECT_GE(decodePsnr(conus, map, {0.25, 0.3, 0.45, 0.5}, 320, 240), kDecodePsnr);  // zoomed in
        EXPECT_GE(decodePsnr(conus, map, {0, 0, 1, 1}, 96, 80), kDecodePsnr);              // zoomed out: taps
        EXPECT_GE(decodePsnr(conus, map, {-0.2, -0.1, 1.1, 1.3}, 300, 280), kDecodePsnr);  // past the edges
        EXPECT_GE(decodePsnr(conus, map, {1, 1, 0, 0}, 200, 200), kDecodePsnr);            // mirrored
    });
    const Image source = test::photoLike(512, 512);
    const codec::SamplingMap jittered = test::jitteredMap(7, 6, 0.3, 9);
    const Image conus = codec::encodeImage(source, jittered, encodeSize(200, 220));
    EXPECT_GE(decodePsnr(conus, jittered, {}, 400, 300), kDecodePsnr);
}

// The pyramid decode: the CPU's levels uploaded as the texture's mip chain, one trilinear tap at
// the level both compute from the map's Jacobian (codec::pyramidLevel and its GLSL twin).
TEST_P(GpuImage, PyramidDecodeMatchesCpu) {
    forEachEncodedMap(256, 200, [&](const codec::SamplingMap& map, const Image& conus) {
        const codec::ImagePyramid pyramid = codec::buildPyramid(conus);
        for (const codec::View view : {codec::View{}, codec::View{0.25, 0.3, 0.45, 0.5}, codec::View{-0.2, -0.1, 1.1, 1.3}}) {
            for (const int w : {97, 180, 400}) {
                codec::DecodeOptions options = decodeView(view, w, w * 3 / 4);
                options.pyramid = &pyramid;
                const Image cpu = codec::decodeImage(conus, map, options);
                const Image gpu = decodeImageGpu(context(), conus, map, options);
                ASSERT_EQ(gpu.channels, conus.channels);
                const double psnr = codec::psnr(cpu, gpu);
                std::printf("    pyramid decode (%.2f,%.2f)-(%.2f,%.2f) -> %dx%d, %s: PSNR %.2f dB\n", view.u0, view.v0,
                            view.u1, view.v1, w, w * 3 / 4, enumName(GetParam()), psnr);
                EXPECT_GE(psnr, kDecodePsnr);
            }
        }
    });
    // A pyramid of another image is refused, as by the CPU decoder.
    const Image other = test::photoLike(64, 64);
    const codec::ImagePyramid wrong = codec::buildPyramid(other);
    codec::DecodeOptions options = decodeView({}, 32, 32);
    options.pyramid = &wrong;
    EXPECT_THROW(decodeImageGpu(context(), test::photoLike(128, 128), twoFoci(), options), Error);
}

TEST_P(GpuImage, DecodeHandlesAnyChannelCount) {
    const Image conus = test::photoLike(128, 128, {"R", "G", "B", "A", "Z"}, 4);
    const codec::SamplingMap map = twoFoci();
    const Image cpu = codec::decodeImage(conus, map, decodeView({}, 160, 120));
    const Image gpu = decodeImageGpu(context(), conus, map, decodeView({}, 160, 120));
    ASSERT_EQ(gpu.channels, conus.channels);
    EXPECT_GE(codec::psnr(cpu, gpu), kDecodePsnr);
    // Z is left out of psnr(); compare it directly, within what the texture unit's bilinear weights
    // resolve: hardware keeps them to 8 fractional bits or so, a step between neighbours off by up
    // to 1/512 of it (an H200 strays 0.00106 here, llvmpipe far less).
    float worst = 0;
    for (std::size_t i = 4; i < cpu.pixels.size(); i += 5) worst = std::max(worst, std::abs(cpu.pixels[i] - gpu.pixels[i]));
    EXPECT_LT(worst, 2e-3f);
}

TEST_P(GpuImage, ReportsTimings) {
    const Image source = test::photoLike(256, 256);
    GpuTimings t;
    t.uploadMs = t.drawMs = t.readbackMs = -1;
    const Image conus = encodeImageGpu(context(), source, twoFoci(), encodeSize(128, 128), &t);
    EXPECT_GT(t.uploadMs, 0);
    EXPECT_GT(t.drawMs, 0);
    EXPECT_GE(t.readbackMs, 0);
    t = {-1, -1, -1};
    decodeImageGpu(context(), conus, twoFoci(), decodeView({}, 200, 100), &t);
    EXPECT_GT(t.uploadMs, 0);
    EXPECT_GT(t.drawMs, 0);
    EXPECT_GE(t.readbackMs, 0);
}

TEST_P(GpuImage, RejectsBadArguments) {
    const Image source = test::photoLike(64, 64);
    const codec::SamplingMap map = codec::SamplingMap::identity(2, 2);
    const auto code = [](auto&& fn) {
        try {
            fn();
        } catch (const Error& e) {
            return e.code();
        }
        return ErrorCode::Io;  // "did not throw"
    };
    EXPECT_EQ(code([&] { encodeImageGpu(context(), Image{}, map, encodeSize(8, 8)); }),
              ErrorCode::InvalidArgument);
    EXPECT_EQ(code([&] { encodeImageGpu(context(), source, map, encodeSize(0, 8)); }), ErrorCode::InvalidArgument);
    EXPECT_EQ(code([&] { decodeImageGpu(context(), source, map, decodeView({0.5, 0, 0.5, 1}, 8, 8)); }),
              ErrorCode::InvalidArgument);
    Image broken = source;
    broken.pixels.pop_back();
    EXPECT_EQ(code([&] { decodeImageGpu(context(), broken, map, decodeView({}, 8, 8)); }), ErrorCode::InvalidArgument);
    // An output wider than any texture the context can hold: refused clearly (only sources tile).
    EXPECT_EQ(code([&] { encodeImageGpu(context(), source, map, encodeSize(context().maxTextureSize() + 1, 1)); }),
              ErrorCode::LimitExceeded);
    {
        const TextureLimit limit("lots");
        EXPECT_EQ(code([&] { encodeImageGpu(context(), source, map, encodeSize(8, 8)); }), ErrorCode::InvalidArgument);
    }
}

// Sources over the texture limit are tiled: the limit lowered to 512 texels cuts a 700 x 500
// source (and its pyramid) into tiles, and the result matches the CPU reference and the untiled GPU.
// (512, not less: the two-focus map's long footprints need margins of 86 texels on every level.)
TEST_P(GpuImage, EncodeTilesSourcesOverTheLimit) {
    const Image source = test::photoLike(700, 500);
    struct Case {
        const char* name;
        codec::SamplingMap map;
        int width, height;
    };
    const std::vector<Case> cases = {{"two foci", twoFoci(), 256, 184},
                                     {"identity, ratio 4", codec::SamplingMap::identity(33, 33), 175, 125},
                                     {"identity, ratio 2.9", codec::SamplingMap::identity(9, 5), 240, 172},
                                     {"random foci", test::randomFociMap(3), 200, 150}};
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        const Image cpu = codec::encodeImage(source, c.map, encodeSize(c.width, c.height));
        const Image untiled = encodeImageGpu(context(), source, c.map, encodeSize(c.width, c.height));
        Image tiled;
        {
            const TextureLimit limit("512");
            tiled = encodeImageGpu(context(), source, c.map, encodeSize(c.width, c.height));
        }
        ASSERT_EQ(tiled.channels, source.channels);
        float worst = 0;
        for (std::size_t i = 0; i < tiled.pixels.size(); ++i)
            worst = std::max(worst, std::abs(tiled.pixels[i] - untiled.pixels[i]));
        const double vsCpu = codec::psnr(cpu, tiled), vsUntiled = codec::psnr(untiled, tiled);
        std::printf("    tiled encode 700x500 -> %dx%d (%s), limit 512, %s: PSNR %.2f dB vs CPU, %.2f dB vs untiled "
                    "GPU (largest difference %.2g), untiled vs CPU %.2f dB\n",
                    c.width, c.height, c.name, enumName(GetParam()), vsCpu, vsUntiled, worst,
                    codec::psnr(cpu, untiled));
        EXPECT_GE(vsCpu, kEncodePsnr);
        EXPECT_GE(vsUntiled, 60.0);
        EXPECT_LT(worst, 0.01f);  // no pixel left out or drawn from the wrong tile
    }
    // A source past the real GL_MAX_TEXTURE_SIZE: a 1-texel strip, tiled along its length.
    const int wide = context().maxTextureSize() + 1;
    Image strip = makeImage(wide, 1, {"Y"});
    for (int x = 0; x < wide; ++x) strip.at(x, 0) = float(x % 97) / 97.0f;
    const codec::SamplingMap map = codec::SamplingMap::identity(2, 2);
    const Image cpu = codec::encodeImage(strip, map, encodeSize(64, 1));
    const Image gpu = encodeImageGpu(context(), strip, map, encodeSize(64, 1));
    EXPECT_GE(codec::psnr(cpu, gpu), kEncodePsnr);
}

// Decode is not tiled: a CoNUS image over the limit is refused with a message naming the limit.
TEST_P(GpuImage, DecodeRefusesImagesOverTheLimit) {
    const Image conus = test::photoLike(300, 200);
    const TextureLimit limit("256");
    try {
        decodeImageGpu(context(), conus, twoFoci(), decodeView({}, 100, 100));
        ADD_FAILURE() << "a 300x200 CoNUS image passed the texture limit 256";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::LimitExceeded);
        EXPECT_NE(std::string(e.what()).find("256"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("CONUS_GL_MAX_TEXTURE"), std::string::npos) << e.what();
    }
    // Within the limit it still decodes.
    EXPECT_NO_THROW(decodeImageGpu(context(), test::photoLike(200, 150), twoFoci(), decodeView({}, 100, 100)));
}

INSTANTIATE_TEST_SUITE_P(Backends, GpuImage, ::testing::Values(Backend::Egl, Backend::OsMesa), test::paramName);

}  // namespace
}  // namespace conus::renderers
