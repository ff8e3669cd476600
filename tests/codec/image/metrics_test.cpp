#include "conus/codec/image/metrics.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "conus/core/error.h"

namespace conus::codec {
namespace {

Image filled(int w, int h, std::vector<std::string> channels, std::vector<float> value) {
    Image im;
    im.width = w;
    im.height = h;
    im.channels = std::move(channels);
    for (int p = 0; p < w * h; ++p) im.pixels.insert(im.pixels.end(), value.begin(), value.end());
    return im;
}

TEST(Metrics, IdenticalImagesHaveZeroErrorAndInfinitePsnr) {
    const Image a = filled(7, 5, {"R", "G", "B"}, {0.1f, 0.2f, 0.3f});
    EXPECT_EQ(meanSquaredError(a, a), 0.0);
    EXPECT_EQ(psnr(a, a), std::numeric_limits<double>::infinity());
}

TEST(Metrics, KnownErrorGivesKnownPsnr) {
    const Image a = filled(8, 4, {"Y"}, {0.0f});
    const Image b = filled(8, 4, {"Y"}, {0.1f});
    EXPECT_NEAR(meanSquaredError(a, b), 0.01, 1e-8);
    EXPECT_NEAR(psnr(a, b), 20.0, 1e-5);
    EXPECT_NEAR(psnr(a, b, 10.0), 40.0, 1e-5);
}

TEST(Metrics, ChannelsMatchByNameAndAlphaIsIgnored) {
    const Image a = filled(3, 3, {"R", "G", "B", "A"}, {0.1f, 0.2f, 0.3f, 1.0f});
    // Same colour in another order, different alpha: no error.
    const Image b = filled(3, 3, {"B", "A", "R", "G"}, {0.3f, 0.0f, 0.1f, 0.2f});
    EXPECT_NEAR(meanSquaredError(a, b), 0.0, 1e-12);
    // Only G differs (by 0.3): mean over the three colour channels.
    const Image c = filled(3, 3, {"R", "G", "B", "Z"}, {0.1f, 0.5f, 0.3f, 7.0f});
    EXPECT_NEAR(meanSquaredError(a, c), 0.09 / 3, 1e-7);
}

TEST(Metrics, AlphaCountsWhenItIsAllThereIs) {
    const Image a = filled(2, 2, {"A"}, {1.0f});
    const Image b = filled(2, 2, {"A"}, {0.5f});
    EXPECT_NEAR(meanSquaredError(a, b), 0.25, 1e-12);
}

TEST(Metrics, RejectsDifferentSizesAndDisjointChannels) {
    const Image a = filled(4, 4, {"R"}, {0.0f});
    EXPECT_THROW(meanSquaredError(a, filled(4, 5, {"R"}, {0.0f})), conus::Error);
    EXPECT_THROW(psnr(a, filled(5, 4, {"R"}, {0.0f})), conus::Error);
    try {
        meanSquaredError(a, filled(4, 4, {"G"}, {0.0f}));
        FAIL() << "no shared channel must throw";
    } catch (const conus::Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::InvalidArgument);
    }
}

// Every value distinct, so a crop that reads the wrong row, column or channel cannot match.
Image numbered(int width, int height) {
    Image im = makeImage(width, height, {"R", "G", "B"});
    for (std::size_t i = 0; i < im.pixels.size(); ++i) im.pixels[i] = static_cast<float>(i);
    return im;
}

TEST(Crop, TakesTheRectangleWithEveryChannel) {
    const Image im = numbered(7, 5);
    const Image c = crop(im, 2, 1, 4, 3);
    ASSERT_EQ(c.width, 4);
    ASSERT_EQ(c.height, 3);
    EXPECT_EQ(c.channels, im.channels);
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 4; ++x)
            for (int ch = 0; ch < 3; ++ch) EXPECT_EQ(c.at(x, y, ch), im.at(2 + x, 1 + y, ch)) << x << "," << y << "," << ch;
    // The crop's bottom-right value is the source's pixel (5, 3), channel B: (3 * 7 + 5) * 3 + 2.
    EXPECT_EQ(c.at(3, 2, 2), 80.0f);
}

TEST(Crop, WholeImageIsACopy) {
    const Image im = numbered(3, 2);
    EXPECT_EQ(crop(im, 0, 0, 3, 2).pixels, im.pixels);
}

TEST(Crop, RefusesRectanglesOutsideTheImage) {
    const Image im = numbered(4, 4);
    EXPECT_THROW(crop(im, 1, 0, 4, 1), Error);
    EXPECT_THROW(crop(im, 0, 3, 1, 2), Error);
    EXPECT_THROW(crop(im, -1, 0, 1, 1), Error);
    EXPECT_THROW(crop(im, 0, 0, 0, 1), Error);
    EXPECT_THROW(crop(im, 2147483647, 0, 1, 1), Error);
}

}  // namespace
}  // namespace conus::codec
