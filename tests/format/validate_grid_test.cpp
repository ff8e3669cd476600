// The sampling-map rules V7..V11 on in-memory grids.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "conus/core/map_rules.h"
#include "conus/format/container.h"
#include "test_files.h"

namespace conus::format {
namespace {

using testing::identityGrid;

float& u(GridNodes& g, int i, int j) { return g.xy[2 * (std::size_t(j) * g.columns + i)]; }
float& v(GridNodes& g, int i, int j) { return g.xy[2 * (std::size_t(j) * g.columns + i) + 1]; }

// The report breaks exactly `rule` and nothing else.
void expectOnly(const ValidationReport& r, int rule) {
    ASSERT_FALSE(r.ok());
    for (const Issue& issue : r.issues) EXPECT_EQ(number(issue.rule), rule) << r.str();
}

// core/map_rules.h decides and the validator words: both give the same answer on grids broken in
// every way (random moves of growing size, NaN, nodes off their edge, a wrong count, sides outside V7).
TEST(ValidateGrid, AgreesWithTheCoreRule) {
    std::mt19937 rng(20261127);
    int valid = 0, invalid = 0;
    for (int trial = 0; trial < 400; ++trial) {
        const int n = 2 + trial % 7, m = 2 + (trial * 5) % 9;
        GridNodes g = identityGrid(n, m);
        const float size = 0.02f * float(trial % 20) / float(n);
        std::uniform_real_distribution<float> move(-size, size);
        for (int j = 1; j + 1 < m; ++j)
            for (int i = 1; i + 1 < n; ++i) u(g, i, j) += move(rng), v(g, i, j) += move(rng);
        std::uniform_int_distribution<int> node(0, n * m - 1);
        switch (trial % 10) {
            case 7: g.xy[2 * std::size_t(node(rng)) + 1] = std::numeric_limits<float>::quiet_NaN(); break;
            case 8: u(g, 0, m - 1) = 1e-4f; break;
            case 9: g.xy.pop_back(); break;
            default: break;
        }
        const bool rule = map_rules::isValidGrid(g.columns, g.rows, g.xy);
        EXPECT_EQ(rule, validateGrid(g).ok()) << "trial " << trial << ": " << validateGrid(g).str();
        (rule ? valid : invalid) += 1;
    }
    EXPECT_GT(valid, 50);
    EXPECT_GT(invalid, 50);
    GridNodes wide = identityGrid(2, 2);
    wide.columns = kMaxMapSide + 1;
    EXPECT_FALSE(map_rules::isValidGrid(wide.columns, wide.rows, wide.xy));
    EXPECT_FALSE(validateGrid(wide).ok());
}

TEST(ValidateGrid, IdentityIsValid) {
    EXPECT_TRUE(validateGrid(identityGrid(2, 2)).ok());
    EXPECT_TRUE(validateGrid(identityGrid(17, 9)).ok()) << validateGrid(identityGrid(17, 9)).str();
}

TEST(ValidateGrid, SmoothDistortionIsValid) {
    GridNodes g = identityGrid(33, 33);
    for (int j = 1; j < 32; ++j) {
        for (int i = 1; i < 32; ++i) {
            const float x = u(g, i, j), y = v(g, i, j);
            u(g, i, j) = x + 0.05f * std::sin(3.14159265f * x) * std::sin(3.14159265f * y);
        }
    }
    EXPECT_TRUE(validateGrid(g).ok()) << validateGrid(g).str();
}

TEST(ValidateGrid, V7Shape) {
    expectOnly(validateGrid(identityGrid(1, 5)), 7);
    GridNodes big;
    big.columns = 4098;
    big.rows = 2;
    expectOnly(validateGrid(big), 7);
    GridNodes g = identityGrid(4, 4);
    g.xy.pop_back();
    expectOnly(validateGrid(g), 7);
    EXPECT_NE(validateGrid(g).str().find("V7: "), std::string::npos);
}

TEST(ValidateGrid, V8NotFinite) {
    GridNodes g = identityGrid(5, 5);
    u(g, 2, 2) = std::numeric_limits<float>::quiet_NaN();
    expectOnly(validateGrid(g), 8);
    g = identityGrid(5, 5);
    v(g, 1, 3) = std::numeric_limits<float>::infinity();
    expectOnly(validateGrid(g), 8);
}

TEST(ValidateGrid, V9OutsideUnitSquare) {
    // An interior node out of [0,1]^2 can only get there by folding too, so accept V11 alongside.
    GridNodes g = identityGrid(3, 3);
    u(g, 1, 1) = 1.5f;
    const ValidationReport r = validateGrid(g);
    EXPECT_TRUE(r.violates(Rule::V9)) << r.str();
    EXPECT_FALSE(r.violates(Rule::V10));
    EXPECT_NE(r.str().find("(1,1)"), std::string::npos) << r.str();
}

TEST(ValidateGrid, V10BoundaryOffEdge) {
    GridNodes g = identityGrid(5, 5);
    u(g, 0, 2) = 0.01f;  // left column slides inward: still convex, still inside
    expectOnly(validateGrid(g), 10);
    g = identityGrid(5, 5);
    v(g, 4, 4) = 0.999f;  // a corner
    expectOnly(validateGrid(g), 10);
}

TEST(ValidateGrid, V11FoldedCell) {
    GridNodes g = identityGrid(5, 5);
    u(g, 2, 2) = 0.8f;  // past its right neighbour at 0.75: cells fold
    const ValidationReport r = validateGrid(g);
    expectOnly(r, 11);
    EXPECT_NE(r.str().find("is not strictly convex"), std::string::npos) << r.str();
}

TEST(ValidateGrid, V11DegenerateCell) {
    GridNodes g = identityGrid(5, 5);
    u(g, 2, 2) = 0.75f;  // onto its right neighbour: zero-area corner
    expectOnly(validateGrid(g), 11);
}

TEST(ValidateGrid, V11MirroredGridHasWrongOrientation) {
    // A grid mirrored in u has every cell convex but clockwise; the boundary rule breaks too.
    GridNodes g = identityGrid(4, 4);
    for (int j = 0; j < 4; ++j) {
        for (int i = 0; i < 4; ++i) u(g, i, j) = 1.0f - u(g, i, j);
    }
    const ValidationReport r = validateGrid(g);
    EXPECT_TRUE(r.violates(Rule::V11));
    EXPECT_TRUE(r.violates(Rule::V10));
}

TEST(ValidateGrid, MessagesAreCapped) {
    GridNodes g = identityGrid(200, 200);
    for (float& x : g.xy) x = std::numeric_limits<float>::quiet_NaN();
    const ValidationReport r = validateGrid(g);
    EXPECT_EQ(r.issues.size(), 21u);
    EXPECT_NE(r.issues.back().message.find("... and 39980 more"), std::string::npos) << r.issues.back().message;

    GridNodes flat = identityGrid(100, 100);
    for (int j = 1; j < 99; ++j) {
        for (int i = 1; i < 99; ++i) v(flat, i, j) = 0.5f;  // interior rows collapse
    }
    const ValidationReport rf = validateGrid(flat);
    EXPECT_EQ(rf.issues.size(), 21u) << rf.str();
    EXPECT_NE(rf.issues.back().message.find("more cells"), std::string::npos);
}

TEST(ValidationReport, StrAndViolates) {
    ValidationReport r;
    EXPECT_TRUE(r.ok());
    r.add(Rule::V3, "bad channel");
    r.add(Rule::Unreadable, "unreadable\nfrom a library");
    EXPECT_TRUE(r.violates(Rule::V3));
    EXPECT_FALSE(r.violates(Rule::V4));
    // One line, whatever the messages held: errors built from a report never span lines.
    EXPECT_EQ(r.str(), "V3: bad channel; error: unreadable from a library");
}

TEST(Image, MakeImageAndChannelIndex) {
    Image im = makeImage(3, 2, {"R", "G", "B"});
    EXPECT_EQ(im.pixels.size(), 18u);
    EXPECT_EQ(im.channelIndex("G"), 1);
    EXPECT_EQ(im.channelIndex("Z"), -1);
    im.at(2, 1, 2) = 5.0f;
    EXPECT_EQ(im.pixels.back(), 5.0f);
    EXPECT_THROW(makeImage(0, 2, {"R"}), Error);
    EXPECT_THROW(makeImage(2, 2, {}), Error);
    try {
        makeImage(65536, 65536, {"R"});
        FAIL();
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::LimitExceeded);
    }
}

TEST(ToString, Names) {
    EXPECT_STREQ(enumName(PixelType::Half), "half");
    EXPECT_STREQ(enumName(Compression::Dwaa), "dwaa");
    EXPECT_STREQ(enumName(DataKind::HeightField), "heightfield");
    EXPECT_STREQ(enumName(DepthKind::CameraDepth), "cameraDepth");
}

}  // namespace
}  // namespace conus::format

TEST(ValidateGrid, CappedRulesStillCountEveryProblem) {
    // 11x11 nodes with the interior columns in reverse order: most of the 100 cells fold, 20 are
    // listed, and the count still says how many there are.
    conus::format::GridNodes grid;
    grid.columns = grid.rows = 11;
    for (int j = 0; j < 11; ++j)
        for (int i = 0; i < 11; ++i) {
            const float u = i == 0 || i == 10 ? i / 10.0f : (10 - i) / 10.0f;
            grid.xy.push_back(u);
            grid.xy.push_back(j / 10.0f);
        }
    const conus::format::ValidationReport report = conus::format::validateGrid(grid);
    ASSERT_FALSE(report.ok());
    EXPECT_LE(report.issues.size(), 22u) << "listed up to the cap";
    long long listed = 0;
    for (const auto& issue : report.issues) listed += issue.count == 1;
    EXPECT_GT(report.problemCount(), listed) << "past the cap, the summary line carries the rest";
    EXPECT_GE(report.problemCount(), 70);
    const std::string summary = report.summary();
    EXPECT_EQ(summary.find('\n'), std::string::npos) << summary;
    EXPECT_NE(summary.find("more problems"), std::string::npos) << summary;
}
