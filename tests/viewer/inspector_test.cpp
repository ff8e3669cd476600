#include "inspector.h"

#include <gtest/gtest.h>

#include "document.h"
#include "editor.h"
#include "viewer_test_util.h"

namespace conus::viewer {
namespace {

TEST(Inspector, IdentityMapReadsThePixel) {
    format::ConusFile file;
    file.image = makeImage(4, 2, {"R", "G", "B", "Z"});
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 4; ++x)
            for (int c = 0; c < 4; ++c) file.image.at(x, y, c) = float(x + 10 * y + 100 * c);
    file.sourceWidth = 4;
    file.sourceHeight = 2;
    const codec::SamplingMap map = codec::SamplingMap::identity(2, 2);
    const Probe p = probe(file, map, {(2 + 0.5) / 4, (1 + 0.5) / 2});  // centre of pixel (2,1)
    EXPECT_TRUE(p.inside);
    EXPECT_EQ(p.conusPixel, glm::ivec2(2, 1));
    EXPECT_EQ(p.sourcePixel, glm::ivec2(2, 1));
    EXPECT_NEAR(p.density, 1.0, 1e-9);
    ASSERT_EQ(p.values.size(), 4u);
    EXPECT_FLOAT_EQ(p.values[0], 12.0f);
    EXPECT_FLOAT_EQ(p.values[3], 312.0f);  // Z too
    const std::string text = formatProbe(p);
    EXPECT_NE(text.find("Z=312"), std::string::npos) << text;
    EXPECT_FALSE(probe(file, map, {1.5, 0.5}).inside);
}

TEST(Inspector, FocusIsDenseAndDistorted) {
    const format::ConusFile file = test::conusFile();
    const codec::SamplingMap map = codec::SamplingMap::fromGrid(file.map);
    const Probe focus = probe(file, map, {test::kFocusU, test::kFocusV});
    const Probe far = probe(file, map, {0.05, 0.05});
    EXPECT_GT(focus.density, 4.0);
    EXPECT_LT(far.density, 1.0);
    EXPECT_NEAR(glm::length(focus.distorted - map.distort({test::kFocusU, test::kFocusV})), 0.0, 1e-12);
}

TEST(Document, InvalidFilesBecomeErrorsNotExceptions) {
    const auto dir = test::tempDir();
    test::writeText(dir / "garbage.exr", "this is not an EXR file");
    const Document garbage = loadDocument((dir / "garbage.exr").string());
    EXPECT_FALSE(garbage.ok());
    EXPECT_FALSE(garbage.error.empty());
    const Document missing = loadDocument((dir / "missing.exr").string());
    EXPECT_FALSE(missing.ok());
    const Document good = loadDocument(test::conusPath());
    ASSERT_TRUE(good.ok()) << good.error;
    EXPECT_EQ(good.sourceWidth(), test::kSourceWidth);
}

TEST(MapEditor, StrokesMagnifyTheBrushCentreAndSaveAValidMap) {
    MapEditor editor(test::sourceImage(), {}, 33, 33);
    editor.brush().radius = 0.15;
    editor.brush().strength = 1.0;
    editor.press({0.5, 0.5});
    editor.moveTo({0.51, 0.5});  // too close for a new stroke
    EXPECT_EQ(editor.strokes(), 1);
    editor.moveTo({0.6, 0.5});
    EXPECT_EQ(editor.strokes(), 2);
    editor.release();
    editor.moveTo({0.9, 0.9});
    EXPECT_EQ(editor.strokes(), 2);
    for (int k = 0; k < 100 && !editor.stable(); ++k) editor.step(20);
    const codec::SamplingMap map = editor.map();
    EXPECT_GT(map.density({0.55, 0.5}), 1.5);
    EXPECT_LT(map.density({0.05, 0.95}), 1.0);
    const format::ConusFile mapFile = editor.mapFile();
    EXPECT_TRUE(format::validateConusFile(mapFile).ok());
    EXPECT_EQ(mapFile.image.channels, std::vector<std::string>{"Y"});
    const format::ConusFile encoded = editor.encode(160, 120);
    EXPECT_EQ(encoded.image.width, 160);
    EXPECT_EQ(encoded.sourceWidth, test::kSourceWidth);
    EXPECT_TRUE(format::validateConusFile(encoded).ok());
    editor.scaleRadius(1e9);
    EXPECT_LE(editor.brush().radius, 1.0);
    editor.reset();
    EXPECT_NEAR(editor.map().density({0.5, 0.5}), 1.0, 1e-6);
}

}  // namespace
}  // namespace conus::viewer
