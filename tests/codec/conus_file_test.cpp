#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "conus/codec/builders/foci.h"
#include "conus/codec/conus_file.h"
#include "conus/core/error.h"

using namespace conus;

TEST(MapFile, HoldsTheMapAndItsDensityAndIsValid) {
    const std::vector<codec::Focus> foci{{0.3, 0.4, 0.1, 3}};
    const codec::SamplingMap map = codec::buildFociMap(foci, {});
    format::AnalyticMap analytic{"foci", {{0.3, 0.4, 0.1, 3}}, "density", {}};
    const format::ConusFile file = codec::makeMapFile(map, analytic);
    EXPECT_TRUE(format::validateConusFile(file).ok()) << format::validateConusFile(file).str();
    EXPECT_EQ(file.image.width, map.columns());
    EXPECT_EQ(file.image.height, map.rows());
    const auto back = codec::SamplingMap::fromGrid(file.map);
    EXPECT_EQ(back.nodes(), map.nodes());
    // The picture is the density at the nodes: high at the focus, below 1 far from it.
    const int fi = static_cast<int>(0.3 * (map.columns() - 1) + 0.5), fj = static_cast<int>(0.4 * (map.rows() - 1) + 0.5);
    EXPECT_GT(file.image.at(fi, fj), 4.0f);
    EXPECT_LT(file.image.at(map.columns() - 1, map.rows() - 1), 1.0f);
    ASSERT_TRUE(file.analytic.has_value());
    EXPECT_EQ(file.analytic->foci.size(), 1u);
}

// V12 is one rule (map_rules::isValidFocus): the builders refuse exactly the foci that the file
// validator refuses, at and past each end of every range.
TEST(MapFile, BuildersAndValidatorAgreeOnWhichFociAreValid) {
    const double nan = std::nan(""), inf = std::numeric_limits<double>::infinity();
    const std::vector<codec::Focus> cases{
        {0.3, 0.4, 0.1, 3},   {0.0, 1.0, 1.0, 1.0},  {1.0, 0.0, 0.001, 64}, {0.5, 0.5, 1.5, 2},  {0.5, 0.5, 1.0001, 2},
        {0.5, 0.5, 0.0, 2},   {0.5, 0.5, -0.1, 2},   {0.5, 0.5, inf, 2},    {0.5, 0.5, nan, 2},  {1.01, 0.5, 0.1, 2},
        {0.5, -0.01, 0.1, 2}, {nan, 0.5, 0.1, 2},    {0.5, 0.5, 0.1, 0.99}, {0.5, 0.5, 0.1, 65}, {0.5, 0.5, 0.1, nan}};
    int accepted = 0;
    for (const codec::Focus& f : cases) {
        bool builds = true;
        try {
            codec::checkFocus(f);
        } catch (const Error&) {
            builds = false;
        }
        const format::AnalyticMap analytic{"foci", {{f.u, f.v, f.r, f.k}}, "density", {}};
        const format::ValidationReport report = format::validateConusFile(codec::makeMapFile(codec::SamplingMap::identity(5, 5), analytic));
        EXPECT_EQ(builds, report.ok()) << f.u << "," << f.v << "," << f.r << "," << f.k << ": " << report.str();
        if (!report.ok()) {
            EXPECT_TRUE(report.violates(format::Rule::V12)) << report.str();
        }
        accepted += builds;
    }
    EXPECT_EQ(accepted, 3);
}

TEST(ConusFile, ImageFilesWithDepthAreValidDepthImages) {
    // The editor used to build its file by hand and forgot the depth kind a Z channel needs (V14).
    const auto map = conus::codec::SamplingMap::identity(3, 3);
    conus::Image image = conus::makeImage(4, 4, {"R", "G", "B", "Z"});
    for (std::size_t i = 0; i < image.pixels.size(); ++i) image.pixels[i] = float(i % 7) / 7.0f;
    conus::SourceEncoding encoding;
    encoding.transfer = conus::Transfer::Srgb;
    const conus::format::ConusFile file = conus::codec::makeImageFile(image, map, 16, 16, encoding);
    EXPECT_TRUE(conus::format::validateConusFile(file).ok()) << conus::format::validateConusFile(file).str();
    EXPECT_EQ(file.depth.kind, conus::format::DepthKind::CameraDepth);
    EXPECT_EQ(file.sourceEncoding.transfer, conus::Transfer::Srgb);
    EXPECT_EQ(file.sourceWidth, 16);
}

// The encode's defaults and checks that every caller (the CLI's encode, bake and demo, Python)
// shares: a quarter of each side to the nearest pixel, aspects 1% apart, the grid an image can show.
TEST(ConusFile, DefaultSizeAspectAndGridRules) {
    EXPECT_EQ(codec::defaultConusSize(4096, 3072), std::make_pair(1024, 768));
    EXPECT_EQ(codec::defaultConusSize(1001, 999), std::make_pair(250, 250));
    EXPECT_EQ(codec::defaultConusSize(1002, 3), std::make_pair(251, 1));
    EXPECT_EQ(codec::defaultConusSize(1, 1), std::make_pair(1, 1));
    EXPECT_FALSE(codec::aspectsDiffer(1.5, 1.505));
    EXPECT_TRUE(codec::aspectsDiffer(1.5, 1.52));
    EXPECT_TRUE(codec::aspectsDiffer(1.0, 1.5));
    EXPECT_NO_THROW(codec::checkGridForImage(129, 16, 11, "--grid"));  // 129 always
    EXPECT_NO_THROW(codec::checkGridForImage(257, 64, 43, "--grid"));  // 4 a pixel of 64, plus one
    try {
        codec::checkGridForImage(258, 64, 43, "--grid");
        ADD_FAILURE() << "accepted";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::InvalidArgument);
        EXPECT_STREQ(e.what(), "--grid 258 is finer than a 64x43 image can show; at most 257 nodes a side");
    }
    EXPECT_NO_THROW(codec::checkGridForImage(513, 16, 11, "--grid", 513));  // the command's own default
}
