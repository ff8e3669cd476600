#include "conus/codec/depth/relief.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>

#include "conus/codec/builders/foci.h"
#include "conus/codec/depth/intersect.h"
#include "conus/core/error.h"
#include "test_dir.h"

namespace conus::codec {
namespace {

// Ink of two strokes: a bar and an L, off centre (no text rasterizer in codec's tests).
Image strokesInk(int w, int h) {
    Image ink = makeImage(w, h, {"Y"});
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const double u = (x + 0.5) / w, v = (y + 0.5) / h;
            const bool bar = u > 0.25 && u < 0.6 && v > 0.3 && v < 0.36;
            const bool ell = (u > 0.7 && u < 0.74 && v > 0.4 && v < 0.7) || (u > 0.7 && u < 0.82 && v > 0.66 && v < 0.7);
            ink.at(x, y) = bar || ell ? 1.0f : 0.0f;
        }
    return ink;
}

TEST(Tablet, FrameFieldBevelsAndEngraving) {
    TabletOptions o;
    const Tablet tablet = makeTablet(strokesInk(400, 300), o);
    EXPECT_DOUBLE_EQ(tablet.extent.x, 1.0);
    EXPECT_DOUBLE_EQ(tablet.extent.y, 0.75);
    const auto at = [&](double u, double v) {
        return tablet.heights.at(int(u * 400), int(v * 300));
    };
    // The field, the frame above it, the chamfered outer edge below it, the strokes cut into it.
    EXPECT_NEAR(at(0.45, 0.5), o.slab, 1e-6);
    EXPECT_NEAR(at(0.5, 0.02), o.slab + o.frame, 1e-6);
    EXPECT_LT(at(0.0, 0.5), o.slab + o.frame - 0.5 * o.bevel);
    EXPECT_NEAR(at(0.4, 0.33), o.slab - o.engraving, 1e-6);
    EXPECT_NEAR(at(0.72, 0.55), o.slab - o.engraving, 1e-6);
    // Stroke walls slope over a pixel (the 3x3 softening): a wall pixel is part way down.
    const float wall = tablet.heights.at(int(0.25 * 400), int(0.33 * 300));
    EXPECT_GT(wall, o.slab - o.engraving);
    EXPECT_LT(wall, o.slab);
    // Painted strokes are darker than the stone around them.
    EXPECT_LT(tablet.colour.at(int(0.4 * 400), int(0.33 * 300), 0), 0.5f * tablet.colour.at(int(0.45 * 400), int(0.5 * 300), 0));
    TabletOptions bad;
    bad.engraving = 1.0;
    EXPECT_THROW(makeTablet(strokesInk(8, 8), bad), Error);
}

TEST(ReliefBake, AssetsValidateRoundTripAndIntersectLikeTheSource) {
    const Tablet tablet = makeTablet(strokesInk(512, 384));
    const Focus focus{0.5, 0.33, 0.12, 3.0};
    FociOptions fo;
    fo.aspect = 512.0 / 384.0;
    const SamplingMap map = buildFociMap(std::span<const Focus>(&focus, 1), fo);
    ReliefBakeOptions options;
    options.width = 128;
    options.height = 96;
    options.extent = tablet.extent;
    const test::TestDir dir("relief-bake");
    for (const bool conus : {false, true}) {
        const format::ConusFile baked = bakeRelief(tablet.heights, tablet.colour, conus ? &map : nullptr, options);
        EXPECT_EQ(baked.dataKind, format::DataKind::HeightField);
        EXPECT_EQ(baked.depth.kind, format::DepthKind::Height);
        ASSERT_TRUE(baked.camera);
        EXPECT_EQ(baked.camera->projection, "orthographic");
        const std::string path = (dir.path() / (conus ? "conus.exr" : "uniform.exr")).string();
        format::writeConusFile(path, baked);
        EXPECT_TRUE(format::validateConusFile(path).ok()) << format::validateConusFile(path).summary();
        const format::ConusFile read = format::readConusFile(path);
        EXPECT_EQ(read.image.width, 128);
        EXPECT_EQ(read.map.columns, conus ? map.columns() : 2);
        // Straight-down rays land on the source's height at the point below them (the field and
        // the engraving's floor, away from walls and the narrow frame).
        const DepthImage asset = DepthImage::fromFile(read);
        for (const glm::dvec2 uv : {glm::dvec2(0.45, 0.55), glm::dvec2(0.4, 0.33), glm::dvec2(0.3, 0.8), glm::dvec2(0.8, 0.2)}) {
            const glm::dvec3 above(uv.x * tablet.extent.x, 1.0, uv.y * tablet.extent.y);
            const auto hit = intersect(asset, {above, {0, -1, 0}});
            ASSERT_TRUE(hit);
            const float truth = tablet.heights.at(int(uv.x * 512), int(uv.y * 384));
            EXPECT_NEAR(hit->position.y, truth, 2e-3) << uv.x << "," << uv.y << (conus ? " CoNUS" : " uniform");
            EXPECT_NEAR(hit->point.x, uv.x, 1e-6);
            EXPECT_NEAR(hit->point.y, uv.y, 1e-6);
        }
    }
    options.extent = {0.0, 1.0};
    EXPECT_THROW(bakeRelief(tablet.heights, tablet.colour, &map, options), Error);
}

}  // namespace
}  // namespace conus::codec
