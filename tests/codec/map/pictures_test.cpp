// Pictures of maps and of frames (map/pictures.h): what `conus info --density-png`, `map`, `demo`
// and `mesh animate` write.
#include "conus/codec/map/pictures.h"

#include <gtest/gtest.h>

#include <vector>

#include "conus/codec/builders/foci.h"
#include "conus/core/error.h"

namespace conus::codec {
namespace {

float luminance(const Image& image, int x, int y) { return image.at(x, y, 0) + image.at(x, y, 1) + image.at(x, y, 2); }

// The heat map is hot where the map samples densely: at an off-centre focus, not in a far corner.
TEST(Pictures, TheDensityPictureIsHotAtTheFocus) {
    const std::vector<Focus> foci{{0.7, 0.3, 0.1, 4}};
    FociOptions options;
    options.aspect = 1.5;
    const SamplingMap map = buildFociMap(foci, options);
    const Image picture = densityPicture(map, 150, 100, 0, nullptr, 1.5);
    ASSERT_EQ(picture.width, 150);
    ASSERT_EQ(picture.height, 100);
    ASSERT_EQ(picture.channelCount(), 3);
    EXPECT_GT(luminance(picture, 105, 30), luminance(picture, 10, 90) + 0.5f);
    const DensityStats stats = densityStats(map);
    EXPECT_GT(stats.max, 4.0);
    EXPECT_LT(stats.min, 1.0);
    EXPECT_NEAR(stats.mean, 1.0, 0.05);  // a map's density averages 1 over the plane
}

// Tiles in rows of `columns`, 4 pixels apart, in order; refused without tiles or columns.
TEST(Pictures, TheContactSheetPlacesTilesInRows) {
    std::vector<Image> tiles;
    for (int k = 0; k < 5; ++k) {
        Image tile = makeImage(6, 3, {"R", "G", "B"});
        for (float& p : tile.pixels) p = 0.1f * float(k + 1);
        tiles.push_back(tile);
    }
    const Image sheet = contactSheet(tiles, 2);
    EXPECT_EQ(sheet.width, 2 * 6 + 3 * 4);
    EXPECT_EQ(sheet.height, 3 * 3 + 4 * 4);
    EXPECT_FLOAT_EQ(sheet.at(4, 4, 1), 0.1f);                   // tile 0, top left
    EXPECT_FLOAT_EQ(sheet.at(4 + 6 + 4 + 5, 4 + 2, 2), 0.2f);    // tile 1, right of it
    EXPECT_FLOAT_EQ(sheet.at(4, 4 + 2 * (3 + 4), 0), 0.5f);      // tile 4, third row
    EXPECT_FLOAT_EQ(sheet.at(4 + 6 + 4, 4 + 2 * (3 + 4), 0), 0.0f);  // no tile 5: black
    EXPECT_FLOAT_EQ(sheet.at(2, 2, 0), 0.0f);                     // the gap
    EXPECT_THROW(contactSheet({}, 2), Error);
    EXPECT_THROW(contactSheet(tiles, 0), Error);
}

}  // namespace
}  // namespace conus::codec
