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

}  // namespace
}  // namespace conus::codec
