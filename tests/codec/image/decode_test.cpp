#include "conus/codec/image/decode.h"

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "../../../codec/src/image/decode_pvt.h"
#include "conus/codec/image/encode.h"
#include "conus/codec/builders/foci.h"
#include "conus/codec/image/metrics.h"
#include "conus/core/error.h"
#include "codec/image/decode_views.h"
#include "test_images.h"

namespace conus::codec {
namespace {

using test::noise;
using test::texture;
using test::zonePlate;

using test::maxAbsDifference;

SamplingMap twoFoci() {
    const std::vector<Focus> foci = {{0.3, 0.35, 0.08, 4}, {0.7, 0.6, 0.06, 3}};
    return buildFociMap(foci);
}

using test::viewOf;

TEST(Decode, RowSteppingEqualsEquationOne) {
    const SamplingMap maps[] = {twoFoci(), buildFociMap(std::vector<Focus>{{0.5, 0.5, 0.2, 6}}),
                                SamplingMap::identity(7, 3)};
    const View views[] = {{0, 0, 1, 1}, {0.21, 0.3, 0.43, 0.41}, {-0.2, -0.1, 1.3, 1.2}, {0.9, 0.8, 0.1, 0.2}};
    for (const SamplingMap& map : maps)
        for (const View& view : views)
            for (int y : {0, 17, 333, 539}) {
                const int W = 961, H = 540;
                const auto row = detail::distortViewRow(map, view, W, H, y);
                const double v = view.v0 + (y + 0.5) / H * (view.v1 - view.v0);
                for (int x = 0; x < W; ++x) {
                    const double u = view.u0 + (x + 0.5) / W * (view.u1 - view.u0);
                    const glm::dvec2 expected = map.distort({u, v});
                    ASSERT_NEAR(row[x].x, expected.x, 1e-9) << x << "," << y;
                    ASSERT_NEAR(row[x].y, expected.y, 1e-9) << x << "," << y;
                }
            }
}

TEST(Decode, IdentityMapEqualsResizeBilinear) {
    const Image conus = noise(200, 150, {"R", "G", "B", "A"}, 2);
    const SamplingMap map = SamplingMap::identity(9, 7);
    const View views[] = {{0, 0, 1, 1}, {0.2, 0.3, 0.6, 0.5}, {-0.2, -0.1, 1.1, 1.3}};
    for (const View& view : views) {
        const Image dec = decodeImage(conus, map, viewOf(view, 300, 240));
        const Image ref = resizeBilinear(conus, view, 300, 240);
        EXPECT_EQ(dec.channels, conus.channels);
        EXPECT_LT(maxAbsDifference(dec, ref), 1e-5f) << view.u0 << "," << view.v0;
    }
    // A channel count without a fixed kernel, and one channel.
    for (const auto& channels : {std::vector<std::string>{"R", "G", "B", "A", "Z"}, std::vector<std::string>{"Y"}}) {
        const Image im = noise(120, 90, channels, 6);
        const View view{0.1, 0.2, 0.7, 0.9};
        EXPECT_LT(maxAbsDifference(decodeImage(im, map, viewOf(view, 200, 150)), resizeBilinear(im, view, 200, 150)),
                  1e-5f);
    }
}

TEST(Decode, MatchesPerPixelEquationOneWhenMagnifying) {
    const Image conus = noise(256, 256, {"R", "G", "B"}, 3);
    const SamplingMap map = twoFoci();
    const View view{0.1, 0.2, 0.5, 0.5};
    const int W = 640, H = 480;
    const Image dec = decodeImage(conus, map, viewOf(view, W, H));
    float worst = 0;
    for (int y = 0; y < H; y += 3)
        for (int x = 0; x < W; x += 3) {
            const glm::dvec2 pd = map.distort({view.u0 + (x + 0.5) / W * (view.u1 - view.u0),
                                               view.v0 + (y + 0.5) / H * (view.v1 - view.v0)});
            const double px = pd.x * 256 - 0.5, py = pd.y * 256 - 0.5;
            const int x0 = std::clamp(static_cast<int>(std::floor(px)), 0, 254);
            const int y0 = std::clamp(static_cast<int>(std::floor(py)), 0, 254);
            const double fx = std::clamp(px - x0, 0.0, 1.0), fy = std::clamp(py - y0, 0.0, 1.0);
            for (int c = 0; c < 3; ++c) {
                const double e = (1 - fy) * ((1 - fx) * conus.at(x0, y0, c) + fx * conus.at(x0 + 1, y0, c)) +
                                 fy * ((1 - fx) * conus.at(x0, y0 + 1, c) + fx * conus.at(x0 + 1, y0 + 1, c));
                worst = std::max(worst, static_cast<float>(std::abs(dec.at(x, y, c) - e)));
            }
        }
    EXPECT_LT(worst, 1e-5f);
}

TEST(Decode, IdentityRoundTripMatchesBaseline) {
    const Image src = noise(512, 512, {"R", "G", "B", "A"}, 4);
    const Image small = areaDownsample(src, 128, 128);
    const Image enc = encodeImage(src, SamplingMap::identity(17, 17), {128, 128, 0, {}});
    const Image dec = decodeImage(enc, SamplingMap::identity(17, 17), viewOf({}, 512, 512));
    EXPECT_LT(maxAbsDifference(dec, resizeBilinear(small, {}, 512, 512)), 1e-5f);
}

// The point of CoNUS: at 1/16 of the pixels, a k=4 focus keeps the detail a uniform image loses.
TEST(Decode, FocusRegionBeatsUniformImageOfTheSameSize) {
    const int S = 1024, C = 256;
    const std::vector<Focus> foci = {{0.5, 0.5, 0.08, 4}};
    const SamplingMap map = buildFociMap(foci);
    // The view: the 96x96 source pixels around the focus centre, decoded at source resolution.
    const int x0 = 464, side = 96;
    const View view{x0 / double(S), x0 / double(S), (x0 + side) / double(S), (x0 + side) / double(S)};
    struct Input {
        const char* name;
        Image image;
    };
    const Input inputs[] = {{"zone plate", zonePlate(S, 0.9)}, {"texture", texture(S, 7)}};
    for (const Input& in : inputs) {
        const Image truth = crop(in.image, x0, x0, side, side);
        const Image enc = encodeImage(in.image, map, {C, C, 0, {}});
        const Image fromConus = decodeImage(enc, map, viewOf(view, side, side));
        const Image fromUniform = resizeBilinear(areaDownsample(in.image, C, C), view, side, side);
        const double conusDb = psnr(fromConus, truth), uniformDb = psnr(fromUniform, truth);
        RecordProperty(std::string(in.name) + "_conus_db", std::to_string(conusDb));
        RecordProperty(std::string(in.name) + "_uniform_db", std::to_string(uniformDb));
        std::printf("[ info ] %s: focus %.2f dB, uniform %.2f dB\n", in.name, conusDb, uniformDb);
        EXPECT_GT(conusDb - uniformDb, 3.0) << in.name << ": CoNUS " << conusDb << " dB, uniform " << uniformDb << " dB";
    }
}

TEST(Decode, ZoomedOutViewAveragesInsteadOfAliasing) {
    // A one-pixel checkerboard: any honest view coarser than the image is flat grey.
    Image conus = makeImage(512, 512, {"Y"});
    for (int y = 0; y < 512; ++y)
        for (int x = 0; x < 512; ++x) conus.at(x, y) = static_cast<float>((x + y) % 2);
    for (const SamplingMap& map : {SamplingMap::identity(5, 5), twoFoci()}) {
        const Image dec = decodeImage(conus, map, viewOf({}, 72, 60));
        double energy = 0;
        for (float v : dec.pixels) energy += (v - 0.5) * (v - 0.5);
        EXPECT_LT(std::sqrt(energy / dec.pixels.size()), 0.03);
    }
    // Zoomed out past the image: clamped columns and rows stay inside the image and in range.
    const Image wide = decodeImage(conus, twoFoci(), viewOf({-0.5, -0.3, 1.5, 1.4}, 50, 40));
    for (float v : wide.pixels) ASSERT_TRUE(v >= 0.0f && v <= 1.0f) << v;
    // The single-tap baseline does alias here, which is what the test guards against.
    const Image aliased = resizeBilinear(conus, {}, 72, 60);
    double energy = 0;
    for (float v : aliased.pixels) energy += (v - 0.5) * (v - 0.5);
    EXPECT_GT(std::sqrt(energy / aliased.pixels.size()), 0.1);
}

TEST(Decode, ThreadCountDoesNotChangeTheResult) {
    const Image conus = noise(300, 200, {"R", "G", "B", "A"}, 5);
    const SamplingMap map = twoFoci();
    for (const View& view : {View{}, View{0.2, 0.25, 0.4, 0.45}}) {
        const Image one = decodeImage(conus, map, viewOf(view, 333, 222, nullptr, 1));
        const Image two = decodeImage(conus, map, viewOf(view, 333, 222, nullptr, 2));
        EXPECT_EQ(one.pixels, two.pixels);
        EXPECT_EQ(resizeBilinear(conus, view, 333, 222, 1).pixels, resizeBilinear(conus, view, 333, 222, 2).pixels);
    }
    // Zoomed out: the multi-tap path.
    EXPECT_EQ(decodeImage(conus, map, viewOf({}, 97, 61, nullptr, 1)).pixels, decodeImage(conus, map, viewOf({}, 97, 61, nullptr, 2)).pixels);
}

TEST(Decode, RejectsBadArguments) {
    const Image conus = noise(16, 16, {"Y"});
    const SamplingMap map = SamplingMap::identity(2, 2);
    EXPECT_THROW(decodeImage(conus, map, viewOf({}, 0, 10)), conus::Error);
    EXPECT_THROW(decodeImage(conus, map, viewOf({}, 10, -1)), conus::Error);
    EXPECT_THROW(decodeImage(conus, map, viewOf({}, kMaxImageSide + 1, 1)), conus::Error);
    EXPECT_THROW(decodeImage(Image{}, map, viewOf({}, 10, 10)), conus::Error);
    EXPECT_THROW(decodeImage(conus, map, viewOf({0.5, 0, 0.5, 1}, 10, 10)), conus::Error);
    EXPECT_THROW(decodeImage(conus, map, viewOf({0, NAN, 1, 1}, 10, 10)), conus::Error);
    EXPECT_THROW(resizeBilinear(conus, {}, 0, 0), conus::Error);
    EXPECT_THROW(resizeBilinear(Image{}, {}, 4, 4), conus::Error);
}

TEST(Decode, MemoryIsCheckedBeforeAllocating) {
    // A 24x16 image whose source is 65536x16384 (a hostile reproducer): the frame alone is 12 GB.
    const Image conus = noise(24, 16, {"R", "G", "B"});
    const SamplingMap map = SamplingMap::identity(2, 2);
    try {
        decodeImage(conus, map, viewOf({}, 65536, 16384));
        FAIL() << "decoded";
    } catch (const conus::Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::LimitExceeded);
        EXPECT_NE(std::string(e.what()).find("decode memory limit"), std::string::npos) << e.what();
    }
    EXPECT_NO_THROW(checkDecodeMemory(conus, 4096, 4096));
    EXPECT_THROW(checkDecodeMemory(conus, 64, 64, 1000), conus::Error);
    // The pyramid's third of the image again counts: a limit the image and frame fit under, the
    // image, its pyramid and the frame do not.
    const std::int64_t plain = (std::int64_t{conus.width} * conus.height + 64 * 64) * conus.channelCount() * 4;
    EXPECT_NO_THROW(checkDecodeMemory(conus, 64, 64, plain));
    EXPECT_THROW(checkDecodeMemory(conus, 64, 64, plain, true), conus::Error);
}

}  // namespace
}  // namespace conus::codec
