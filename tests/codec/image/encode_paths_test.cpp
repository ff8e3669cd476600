// The CPU encoder's two ways to the same pixels: the AVX2 tap loop against its baseline twin, and
// a picture kept as 8-bit codes against the linear picture it stands for (image, budget, detail).
#include "conus/codec/image/encode.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "conus/codec/builders/foci.h"
#include "conus/codec/builders/foci_budget.h"
#include "conus/codec/builders/frame_budget.h"
#include "conus/codec/builders/importance.h"
#include "conus/codec/image/metrics.h"
#include "conus/core/error.h"
#include "conus/core/map_rules.h"
#include "encode_cases.h"
#include "test_images.h"
#include "../../../codec/src/image/encode_pvt.h"

namespace conus::codec {
namespace {

using namespace conus::test;

// The anisotropic kernel's AVX2 tap loop (two taps a register, fused multiply-adds) and its
// baseline twin give the same pixels to float rounding, for 3 and 4 channels, on a photo-like
// picture under maps whose footprints stretch and turn every way (and where the processor has no
// AVX2, the default is the baseline: the two agree exactly).
TEST(EncodeAnisotropic, Avx2TapsMatchTheBaseline) {
    for (const bool alpha : {false, true}) {
        const SamplingMap map = twoFoci(1.5, alpha ? FociComposition::Add : FociComposition::Density);
        const Image src = alpha ? photoLike(360, 240, {"R", "G", "B", "A"}) : photoLike(360, 240);
        detail::forceBaselineEncode(true);
        const Image baseline = encodeImage(src, map, sized(150, 100));
        detail::forceBaselineEncode(false);
        const Image chosen = encodeImage(src, map, sized(150, 100));
        const float worst = maxAbsDifference(baseline, chosen);
        std::printf("[ info ] %d channels: AVX2 %s, largest difference from the baseline taps %.3g\n",
                    src.channelCount(), detail::encodeAvx2Available() ? "used" : "not available", worst);
        EXPECT_LT(worst, 2e-6f);
        if (!detail::encodeAvx2Available()) {
            EXPECT_EQ(worst, 0.0f);
        }
    }
}

// An asymmetric 8-bit picture: a ramp along x, another along y, a diagonal edge, noise; alpha (when
// asked) from fully transparent to opaque across a disc off the centre.
EightBitImage eightBitPicture(int w, int h, std::vector<std::string> channels, unsigned seed) {
    EightBitImage p{w, h, std::move(channels), {}};
    const int ch = p.channelCount();
    p.codes.resize(std::size_t(w) * h * ch);
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> grain(-24, 24);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < ch; ++c) {
                int v;
                if (p.channels[c] == "A") {
                    const double d = std::hypot(x - 0.3 * w, y - 0.6 * h) / (0.5 * w);
                    v = static_cast<int>(std::lround(255.0 * std::clamp(1.2 - d, 0.0, 1.0)));
                } else {
                    v = (x * 255) / w * (c + 1) / 3 + (y * 97) / h + (x + 2 * y > w ? 60 : 0) + grain(rng);
                }
                p.codes[(std::size_t(y) * w + x) * ch + c] = static_cast<std::uint8_t>(std::clamp(v, 0, 255));
            }
    return p;
}

TEST(EncodeEightBit, CodesMeanTheSrgbCurveAndAlphaAsStored) {
    const EightBitImage p{2, 1, {"R", "A"}, {128, 128, 255, 0}};
    const Image linear = linearImage(p);
    EXPECT_NEAR(linear.at(0, 0, 0), std::pow((128 / 255.0 + 0.055) / 1.055, 2.4), 1e-7);
    EXPECT_NEAR(linear.at(0, 0, 1), 128 / 255.0, 1e-7);
    EXPECT_EQ(linear.at(1, 0, 0), 1.0f);
    EXPECT_EQ(linear.at(1, 0, 1), 0.0f);
    EXPECT_THROW(linearImage(EightBitImage{2, 2, {"Y"}, {1, 2, 3}}), Error);
    EXPECT_THROW(encodeImage(EightBitImage{2, 2, {"Y"}, {1, 2, 3}}, SamplingMap::identity(2, 2), sized(1, 1)), Error);
}

// The 8-bit source's encode is the float picture's, to float rounding, whichever kernel, map, size
// parity (an odd side builds level 1 from level 0 made linear whole) and channels.
TEST(EncodeEightBit, EqualsTheEncodeOfTheLinearPicture) {
    struct Case {
        int w, h;
        std::vector<std::string> channels;
    };
    const Case cases[] = {{256, 192, {"R", "G", "B", "A"}}, {256, 192, {"R", "G", "B"}}, {203, 151, {"R", "G", "B", "A"}}, {160, 120, {"Y"}}};
    for (const Case& c : cases) {
        const EightBitImage codes = eightBitPicture(c.w, c.h, c.channels, 7u + c.w);
        const Image linear = linearImage(codes);
        const int W = c.w / 4, H = c.h / 4;
        for (const SamplingMap& map : {twoFoci(double(c.w) / c.h), SamplingMap::identity(5, 5)})
            for (EncodeFilter filter : kFilters) {
                const Image fromCodes = encodeImage(codes, map, sized(W, H, 0, filter));
                const Image fromFloat = encodeImage(linear, map, sized(W, H, 0, filter));
                ASSERT_EQ(fromCodes.channels, fromFloat.channels);
                ASSERT_EQ(fromCodes.pixels.size(), fromFloat.pixels.size());
                EXPECT_LT(maxAbsDifference(fromCodes, fromFloat), 2e-6f)
                    << c.w << "x" << c.h << " " << c.channels.size() << " channels, " << enumName(filter);
                // Not trivially equal: the picture is there (the foci map magnifies, so level 0 is read).
                float lo = 1, hi = 0;
                for (float v : fromCodes.pixels) lo = std::min(lo, v), hi = std::max(hi, v);
                EXPECT_LT(lo, 0.1f);
                EXPECT_GT(hi, 0.5f);
            }
    }
}

// A picture wider than the detail rule reads (1024 px) is area-downsampled first; from codes its
// rows of luminance are made as the downsample reads them, and the detail is still that of the
// display picture bit for bit (a scale that is not a whole number, so rows are shared).
TEST(EncodeEightBit, DetailOfAPictureLargerThanItsDownsampleIsTheDisplayPictures) {
    for (const std::vector<std::string>& channels : {std::vector<std::string>{"R", "G", "B"}, std::vector<std::string>{"Y"}}) {
        const EightBitImage codes = eightBitPicture(1500, 701, channels, 5u);
        Image display = makeImage(codes.width, codes.height, codes.channels);
        for (std::size_t i = 0; i < codes.codes.size(); ++i) display.pixels[i] = codeToUnit()[codes.codes[i]];
        const Image detail = detailImportance(codes);
        const Image detailOfDisplay = detailImportance(display);
        EXPECT_EQ(detail.width, 1024);
        ASSERT_EQ(detail.pixels.size(), detailOfDisplay.pixels.size());
        EXPECT_EQ(maxAbsDifference(detail, detailOfDisplay), 0.0f);
        EXPECT_GT(*std::max_element(detail.pixels.begin(), detail.pixels.end()), 0.1f);  // not a flat picture
    }
}

// The budget reads the codes as the linear picture: the same model (bit for bit), so the same k;
// the detail of code / 255 is the detail of that display picture.
TEST(EncodeEightBit, BudgetModelAndDetailAreTheLinearPictures) {
    for (const std::vector<std::string>& channels : {std::vector<std::string>{"R", "G", "B"}, std::vector<std::string>{"R", "G", "B", "A"}}) {
        const EightBitImage codes = eightBitPicture(256, 192, channels, 11u);
        const Image linear = linearImage(codes);
        Image display = makeImage(codes.width, codes.height, codes.channels);
        for (std::size_t i = 0; i < codes.codes.size(); ++i) display.pixels[i] = codeToUnit()[codes.codes[i]];
        const Image detail = detailImportance(codes);
        const Image detailOfDisplay = detailImportance(display);
        ASSERT_EQ(detail.pixels.size(), detailOfDisplay.pixels.size());
        EXPECT_EQ(maxAbsDifference(detail, detailOfDisplay), 0.0f);
        const std::vector<Focus> foci = {{0.3, 0.4, 0.15, 8}};
        FociOptions fo;
        fo.aspect = 256.0 / 192.0;
        FrameModelOptions options;
        options.fitIterations = 0;
        options.confirm = false;
        const Image importance = fociImportance(foci, fo.aspect, 64, 48);
        const FrameErrorModel fromCodes(codes, 64, 48, importance, options), fromLinear(linear, 64, 48, importance, options);
        const SamplingMap map = buildFociMap(foci, fo);
        EXPECT_EQ(fromCodes.tileErrors(map), fromLinear.tileErrors(map));
        EXPECT_EQ(fromCodes.uniformErrors(), fromLinear.uniformErrors());
        EXPECT_EQ(fromCodes.predict(map).frameLoss, fromLinear.predict(map).frameLoss);
        const FociBudget a = fociForFrameLoss(foci, fo, fromCodes, 0.05, false), b = fociForFrameLoss(foci, fo, fromLinear, 0.05, false);
        ASSERT_EQ(a.given.size(), 1u);
        EXPECT_EQ(a.given[0].k, b.given[0].k);
        EXPECT_LT(a.given[0].k, 7.9);  // the budget binds: k is chosen, not the asked one
        EXPECT_THROW(fromCodes.confirmed(map), Error);
    }
}

}  // namespace
}  // namespace conus::codec
