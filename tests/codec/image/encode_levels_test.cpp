// codec::EncodeLevels: the encoder's levels of a source kept from one encode to the next give the
// same CoNUS image, bit for bit, as an encode that builds them afresh, for another map, another
// filter and another source (which empties them first); levels built ahead of any encode
// (buildEncodeLevels) are every level, and give the same image too.
#include <algorithm>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "conus/codec/builders/foci.h"
#include "conus/codec/image/encode.h"
#include "test_images.h"

namespace conus::codec {
namespace {

using namespace conus::test;

SamplingMap focusAt(double u, double v, double aspect) {
    const std::vector<Focus> foci = {{u, v, 0.07, 5}};
    FociOptions options;
    options.aspect = aspect;
    return buildFociMap(foci, options);
}

EncodeOptions sized(int w, int h, EncodeFilter filter, EncodeLevels* kept) {
    EncodeOptions o;
    o.width = w;
    o.height = h;
    o.filter = filter;
    o.keptLevels = kept;
    return o;
}

TEST(EncodeLevels, KeptLevelsGiveTheSameImageAsFreshOnes) {
    // Odd sides, so that every level's area weights are uneven; the context's footprints reach the
    // coarse levels.
    const Image source = photoLike(613, 419);
    const double aspect = 613.0 / 419.0;
    EncodeLevels kept;
    EXPECT_EQ(kept.bytes(), 0);

    const SamplingMap first = focusAt(0.3, 0.4, aspect);
    const Image fresh1 = encodeImage(source, first, sized(160, 110, EncodeFilter::Anisotropic, nullptr));
    const Image kept1 = encodeImage(source, first, sized(160, 110, EncodeFilter::Anisotropic, &kept));
    EXPECT_EQ(kept1.pixels, fresh1.pixels);
    const std::int64_t built = kept.bytes();
    // Level 1 alone is a quarter of the source's pixels; the encode needed more than it.
    EXPECT_GT(built, static_cast<std::int64_t>(source.pixels.size() / 4 * sizeof(float)));
    EXPECT_LT(built, static_cast<std::int64_t>(source.pixels.size() / 2 * sizeof(float)));

    // Another focus, size and filter from the kept levels: as a fresh encode.
    const SamplingMap second = focusAt(0.72, 0.61, aspect);
    for (const EncodeFilter filter : {EncodeFilter::Anisotropic, EncodeFilter::Ewa}) {
        const Image fresh2 = encodeImage(source, second, sized(200, 97, filter, nullptr));
        const Image kept2 = encodeImage(source, second, sized(200, 97, filter, &kept));
        EXPECT_EQ(kept2.pixels, fresh2.pixels);
    }
    EXPECT_GE(kept.bytes(), built);

    // Another source of the same size and channels: its own levels, not the first one's.
    const Image other = photoLike(613, 419, {"R", "G", "B"}, 11);
    const Image freshOther = encodeImage(other, first, sized(160, 110, EncodeFilter::Anisotropic, nullptr));
    const Image keptOther = encodeImage(other, first, sized(160, 110, EncodeFilter::Anisotropic, &kept));
    EXPECT_EQ(keptOther.pixels, freshOther.pixels);
    EXPECT_NE(keptOther.pixels, kept1.pixels);

    kept.clear();
    EXPECT_EQ(kept.bytes(), 0);
}

TEST(EncodeLevels, LevelsBuiltAheadAreEveryLevelAndGiveTheSameImage) {
    const Image source = photoLike(613, 419);
    EncodeLevels kept;
    buildEncodeLevels(source, kept);
    // Levels 1.. down to 1x1, each side halved rounding up: 307x210, 154x105, ... 1x1.
    std::int64_t expected = 0;
    for (int w = 613, h = 419; w > 1 || h > 1;) {
        w = std::max(1, (w + 1) / 2);
        h = std::max(1, (h + 1) / 2);
        expected += std::int64_t(w) * h * source.channelCount() * std::int64_t(sizeof(float));
    }
    EXPECT_EQ(kept.bytes(), expected);

    const SamplingMap map = focusAt(0.66, 0.35, 613.0 / 419.0);
    for (const EncodeFilter filter : {EncodeFilter::Anisotropic, EncodeFilter::Ewa}) {
        const Image fresh = encodeImage(source, map, sized(170, 121, filter, nullptr));
        const Image fromBuilt = encodeImage(source, map, sized(170, 121, filter, &kept));
        EXPECT_EQ(fromBuilt.pixels, fresh.pixels);
    }
    EXPECT_EQ(kept.bytes(), expected);  // nothing more to build
}

}  // namespace
}  // namespace conus::codec
