// Documents: a picture opened with foci is what `conus encode --focus` writes of it on the CPU (the
// viewer encodes there; a GL encode of the same map differs in its pixels' rounding), through the
// one call from foci to a map (codec::budgetedFociMap), read back from the real binary's file.
#include "document.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "conus/format/container.h"
#include "conus/imageio/image_file.h"
#include "viewer_test_util.h"

namespace conus::viewer {
namespace {

TEST(Document, APictureWithFociIsWhatEncodeWrites) {
    const std::string picture = (test::tempDir() / "document-picture.png").string();
    imageio::WriteOptions write;
    write.sampleType = SampleType::Uint16;
    imageio::writeImageFile(picture, test::sourceImage(), write);
    const std::string encoded = (test::tempDir() / "document-picture.exr").string();
    std::string log;
    ASSERT_EQ(test::run(std::string(CONUS_BIN_DIR) + "/conus encode " + picture +
                            " --focus 0.65,0.55,0.1,3 --focus 0.25,0.3,0.06,6 --backend cpu -q -o " + encoded, &log),
              0)
        << log;
    const format::ConusFile written = format::readConusFile(encoded);

    const codec::Focus foci[] = {{0.65, 0.55, 0.1, 3}, {0.25, 0.3, 0.06, 6}};
    const Document doc = loadDocument(picture, foci);
    ASSERT_TRUE(doc.ok()) << doc.error;
    const format::ConusFile& shown = *doc.file;
    EXPECT_EQ(shown.map.columns, written.map.columns);
    EXPECT_EQ(shown.map.rows, written.map.rows);
    EXPECT_EQ(shown.map.xy, written.map.xy) << "the map encode wrote, node for node";
    ASSERT_TRUE(shown.analytic && written.analytic);
    ASSERT_EQ(shown.analytic->foci.size(), 2u);
    for (std::size_t i = 0; i < 2; ++i) EXPECT_EQ(shown.analytic->foci[i].k, written.analytic->foci[i].k) << "the k the budget gave";
    EXPECT_EQ(shown.analytic->scalars, written.analytic->scalars);
    EXPECT_EQ(shown.sourceWidth, test::kSourceWidth);
    ASSERT_EQ(shown.image.width, written.image.width);
    ASSERT_EQ(shown.image.height, written.image.height);
    ASSERT_EQ(shown.image.channelCount(), written.image.channelCount());
    double worst = 0;  // encode writes half floats, its channels in the file's (sorted) order
    for (int c = 0; c < shown.image.channelCount(); ++c) {
        const int w = written.image.channelIndex(shown.image.channels[c]);
        ASSERT_GE(w, 0) << shown.image.channels[c];
        for (int y = 0; y < shown.image.height; ++y)
            for (int x = 0; x < shown.image.width; ++x) {
                const double a = shown.image.at(x, y, c), b = written.image.at(x, y, w);
                worst = std::max(worst, std::abs(a - b) / std::max(1e-3, std::abs(b)));
            }
    }
    EXPECT_LT(worst, 1.0 / 1024) << "the same pixels to half rounding";
    EXPECT_EQ(doc.map->columns(), written.map.columns);
}

TEST(Document, APictureThatCannotBeReadIsAnErrorNamingIt) {
    const codec::Focus focus{0.5, 0.5, 0.1, 3};
    const std::string missing = (test::tempDir() / "no-such-picture.png").string();
    const Document doc = loadDocument(missing, std::span<const codec::Focus>(&focus, 1));
    EXPECT_FALSE(doc.ok());
    EXPECT_NE(doc.error.find(missing), std::string::npos) << doc.error;
    EXPECT_EQ(doc.error.find('\n'), std::string::npos) << doc.error;
}

}  // namespace
}  // namespace conus::viewer
