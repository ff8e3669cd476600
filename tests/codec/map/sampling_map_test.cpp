// SamplingMap: Equation 1, its inverse, validation (V7..V11), Jacobian, density and resampling.
#include "conus/codec/map/sampling_map.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <random>
#include <string>
#include <thread>

#include "conus/codec/builders/density_map.h"
#include "conus/codec/builders/foci.h"
#include "conus/core/error.h"
#include "conus/core/map_rules.h"
#include "conus/format/container.h"
#include "sanitizers.h"

namespace conus::codec {
namespace {

std::vector<glm::vec2> identityNodes(int n, int m) {
    std::vector<glm::vec2> nodes(std::size_t(n) * m);
    for (int j = 0; j < m; ++j)
        for (int i = 0; i < n; ++i) nodes[std::size_t(j) * n + i] = {float(double(i) / (n - 1)), float(double(j) / (m - 1))};
    return nodes;
}

// Identity nodes moved at random by up to `amount` cells (boundary nodes along their edge only);
// kept only if valid, so the result is a valid, fairly irregular map.
SamplingMap jitteredMap(std::mt19937& rng, int n, int m, double amount) {
    std::uniform_real_distribution<double> jitter(-amount, amount);
    for (int attempt = 0; attempt < 100; ++attempt) {
        std::vector<glm::vec2> nodes = identityNodes(n, m);
        for (int j = 0; j < m; ++j)
            for (int i = 0; i < n; ++i) {
                glm::vec2& p = nodes[std::size_t(j) * n + i];
                if (i != 0 && i != n - 1) p.x = float(std::clamp(p.x + jitter(rng) / (n - 1), 0.0, 1.0));
                if (j != 0 && j != m - 1) p.y = float(std::clamp(p.y + jitter(rng) / (m - 1), 0.0, 1.0));
            }
        try {
            return SamplingMap(n, m, std::move(nodes));
        } catch (const Error&) {
        }
    }
    return SamplingMap::identity(n, m);
}

SamplingMap randomFociMap(std::mt19937& rng, int n, int m, FociComposition composition) {
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::vector<Focus> foci(1 + rng() % 3);
    for (Focus& f : foci) f = {unit(rng), unit(rng), 0.03 + 0.12 * unit(rng), 1.0 + 5.0 * unit(rng)};
    FociOptions options;
    options.columns = n;
    options.rows = m;
    options.aspect = 0.6 + unit(rng);
    options.composition = composition;
    return buildFociMap(foci, options);
}

SamplingMap randomDensityMap(std::mt19937& rng, int n, int m) {
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    DensityField field;
    field.width = 96;
    field.height = 80;
    double cx[4], cy[4], w[4], sigma[4];
    for (int g = 0; g < 4; ++g) cx[g] = unit(rng), cy[g] = unit(rng), w[g] = 8.0 * unit(rng), sigma[g] = 0.05 + 0.2 * unit(rng);
    for (int y = 0; y < field.height; ++y)
        for (int x = 0; x < field.width; ++x) {
            const double u = (x + 0.5) / field.width, v = (y + 0.5) / field.height;
            double d = 1.0;
            for (int g = 0; g < 4; ++g)
                d += w[g] * std::exp(-((u - cx[g]) * (u - cx[g]) + (v - cy[g]) * (v - cy[g])) / (2 * sigma[g] * sigma[g]));
            field.values.push_back(float(d));
        }
    DensityMapOptions options;
    options.columns = n;
    options.rows = m;
    return buildMapFromDensity(field, options);
}

// Random points that stress the inverse: uniform, exact node positions, cell edges, the border.
std::vector<glm::dvec2> testPoints(std::mt19937& rng, const SamplingMap& map, int count) {
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const int n = map.columns(), m = map.rows();
    std::vector<glm::dvec2> points;
    points.reserve(count);
    for (int k = 0; k < count; ++k) {
        glm::dvec2 p{unit(rng), unit(rng)};
        switch (k % 6) {
            case 1: p = {double(rng() % n) / (n - 1), double(rng() % m) / (m - 1)}; break;
            case 2: p.x = double(rng() % n) / (n - 1); break;
            case 3: p.y = double(rng() % m) / (m - 1); break;
            case 4: (rng() % 2 ? p.x : p.y) = double(rng() % 2); break;
            default: break;
        }
        points.push_back(p);
    }
    return points;
}

struct RoundTrip {
    double forward = 0;  // max |undistort(distort(p)) - p|
    double backward = 0; // max |distort(undistort(q)) - q|
};

RoundTrip roundTrip(const SamplingMap& map, std::mt19937& rng, int count) {
    RoundTrip result;
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (const glm::dvec2& p : testPoints(rng, map, count)) {
        const glm::dvec2 back = map.undistort(map.distort(p));
        result.forward = std::max(result.forward, glm::length(back - p));
        const glm::dvec2 q{unit(rng), unit(rng)};
        result.backward = std::max(result.backward, glm::length(map.distort(map.undistort(q)) - q));
    }
    return result;
}

std::string invalidMessage(int n, int m, std::vector<glm::vec2> nodes) {
    try {
        SamplingMap map(n, m, std::move(nodes));
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::InvalidMap);
        return e.what();
    }
    return "accepted";
}

TEST(SamplingMap, IdentityDistortIsIdentity) {
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (auto [n, m] : {std::pair{map_rules::kDefaultSide, map_rules::kDefaultSide}, std::pair{10, 7}, std::pair{2, 2}}) {
        const SamplingMap map = SamplingMap::identity(n, m);
        for (int k = 0; k < 1000; ++k) {
            const glm::dvec2 p{unit(rng), unit(rng)};
            EXPECT_NEAR(map.distort(p).x, p.x, 1e-7);
            EXPECT_NEAR(map.distort(p).y, p.y, 1e-7);
            EXPECT_NEAR(map.undistort(p).x, p.x, 1e-7);
            EXPECT_NEAR(map.undistort(p).y, p.y, 1e-7);
            EXPECT_NEAR(map.density(p), 1.0, 1e-6);
        }
    }
    // Powers of two are exact in float: Eq. 1 of the identity on 2^6 x 2^6 cells is exact.
    const SamplingMap map = SamplingMap::identity((1 << 6) + 1, (1 << 6) + 1);
    EXPECT_EQ(map.distort({0.3, 0.7}), glm::dvec2(0.3, 0.7));
    EXPECT_EQ(map.distort({1.0, 1.0}), glm::dvec2(1.0, 1.0));
}

TEST(SamplingMap, PointsOutsideAreClamped) {
    const SamplingMap map = SamplingMap::identity(5, 5);
    EXPECT_EQ(map.distort({-0.5, 1.5}), glm::dvec2(0.0, 1.0));
    EXPECT_EQ(map.undistort({2.0, -1.0}), glm::dvec2(1.0, 0.0));
    const glm::dvec2 nan = map.undistort({std::nan(""), 0.5});  // no crash, no index from NaN
    EXPECT_TRUE(nan.x >= 0.0 && nan.x <= 1.0);
}

TEST(SamplingMap, RoundTripJitteredMaps) {
    for (unsigned seed = 1; seed <= 4; ++seed) {
        std::mt19937 rng(seed);
        const int n = 5 + int(rng() % 60), m = 5 + int(rng() % 60);
        const SamplingMap map = jitteredMap(rng, n, m, 0.45);
        const RoundTrip r = roundTrip(map, rng, 100000);
        EXPECT_LT(r.forward, 1e-9) << "seed " << seed << " grid " << n << "x" << m;
        EXPECT_LT(r.backward, 1e-9) << "seed " << seed;
    }
}

TEST(SamplingMap, RoundTripFociMaps) {
    for (unsigned seed = 11; seed <= 14; ++seed) {
        std::mt19937 rng(seed);
        const SamplingMap map = randomFociMap(rng, map_rules::kDefaultSide, 49, seed % 2 ? FociComposition::Add : FociComposition::Density);
        const RoundTrip r = roundTrip(map, rng, 100000);
        EXPECT_LT(r.forward, 1e-9) << "seed " << seed;
        EXPECT_LT(r.backward, 1e-9) << "seed " << seed;
    }
}

TEST(SamplingMap, RoundTripStrongFociMaps) {
    // Strong magnifications (up to 64) and both compositions give very thin cells whose inverse
    // quadratic has both roots' t in [0,1] (once a bug: the wrong root was taken).
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int trial = 0; trial < 12; ++trial) {
        std::vector<Focus> foci(1 + rng() % 3);
        for (Focus& f : foci) f = {unit(rng), unit(rng), 0.02 + 0.15 * unit(rng), 1 + (trial % 3 == 0 ? 63 : 7) * unit(rng)};
        FociOptions options;
        options.composition = trial % 2 ? FociComposition::Add : FociComposition::Density;
        options.aspect = 0.5 + unit(rng);
        const SamplingMap map = buildFociMap(foci, options);
        const RoundTrip r = roundTrip(map, rng, 50000);
        EXPECT_LT(r.forward, 1e-9) << "trial " << trial;
        EXPECT_LT(r.backward, 1e-9) << "trial " << trial;
    }
}

TEST(SamplingMap, InverseTakesTheRootInsideTheCell) {
    // A map with very thin cells near the right border, where both roots of the inverse quadratic
    // have t in [0,1] and only one has s in [0,1] (found by a fuzz run: undistort was 8e-3 off).
    const std::vector<Focus> foci{{0.53663304650412202, 0.61976420582643388, 0.16173230672871919, 6.5259908650238518}};
    FociOptions options;
    options.composition = FociComposition::Add;
    options.aspect = 0.78879380834272306;
    const SamplingMap map = buildFociMap(foci, options);
    std::mt19937 rng(2);
    std::uniform_real_distribution<double> near(-0.03, 0.03);
    double worst = 0;
    for (int k = 0; k < 100000; ++k) {
        const glm::dvec2 p = glm::clamp(glm::dvec2(0.8284421954400023 + near(rng), 0.71089834761131943 + near(rng)), 0.0, 1.0);
        worst = std::max(worst, glm::length(map.undistort(map.distort(p)) - p));
    }
    EXPECT_LT(worst, 1e-9);
}

TEST(SamplingMap, RoundTripDensityMaps) {
    for (unsigned seed = 21; seed <= 23; ++seed) {
        std::mt19937 rng(seed);
        const SamplingMap map = randomDensityMap(rng, 33, 41);
        const RoundTrip r = roundTrip(map, rng, 100000);
        EXPECT_LT(r.forward, 1e-9) << "seed " << seed;
        EXPECT_LT(r.backward, 1e-9) << "seed " << seed;
    }
}

TEST(SamplingMap, RoundTripNearlyParallelogramCells) {
    // A shear (every cell an exact parallelogram) and a tiny perturbation of it: the quadratic of
    // the inverse degenerates to a linear equation.
    const int n = 9, m = 9;
    std::vector<glm::vec2> nodes = identityNodes(n, m);
    for (int j = 1; j < m - 1; ++j)
        for (int i = 1; i < n - 1; ++i) nodes[std::size_t(j) * n + i].x += 0.02f * std::sin(3.0f * j / (m - 1));
    std::mt19937 rng(5);
    const SamplingMap shear(n, m, nodes);
    RoundTrip r = roundTrip(shear, rng, 20000);
    EXPECT_LT(r.forward, 1e-9);
    EXPECT_LT(r.backward, 1e-9);
    nodes[std::size_t(4) * n + 4].y += 1e-6f;
    const SamplingMap almost(n, m, nodes);
    r = roundTrip(almost, rng, 20000);
    EXPECT_LT(r.forward, 1e-9);
    EXPECT_LT(r.backward, 1e-9);
}

TEST(SamplingMap, UndistortOfNodesGivesGridPositions) {
    std::mt19937 rng(3);
    const SamplingMap map = randomFociMap(rng, 17, 13, FociComposition::Density);
    for (int j = 0; j < map.rows(); ++j)
        for (int i = 0; i < map.columns(); ++i) {
            const glm::dvec2 p = map.undistort(glm::dvec2(map.node(i, j)));
            EXPECT_NEAR(p.x, double(i) / (map.columns() - 1), 1e-12);
            EXPECT_NEAR(p.y, double(j) / (map.rows() - 1), 1e-12);
        }
}

TEST(SamplingMap, RejectsWrongSize) {
    EXPECT_NE(invalidMessage(3, 3, identityNodes(3, 2)).find("V7"), std::string::npos);
    EXPECT_NE(invalidMessage(1, 3, identityNodes(1, 3)).find("V7"), std::string::npos);
    EXPECT_THROW(SamplingMap::identity(1, 5), Error);
}

TEST(SamplingMap, RejectsNonFinite) {
    std::vector<glm::vec2> nodes = identityNodes(5, 5);
    nodes[12].x = std::numeric_limits<float>::quiet_NaN();
    EXPECT_NE(invalidMessage(5, 5, nodes).find("V8"), std::string::npos);
    nodes = identityNodes(5, 5);
    nodes[12].y = std::numeric_limits<float>::infinity();
    EXPECT_NE(invalidMessage(5, 5, nodes).find("V8"), std::string::npos);
}

TEST(SamplingMap, RejectsOutsideUnitSquare) {
    std::vector<glm::vec2> nodes = identityNodes(5, 5);
    nodes[6].y = -0.01f;
    EXPECT_NE(invalidMessage(5, 5, nodes).find("V9"), std::string::npos);
}

TEST(SamplingMap, RejectsOffBoundary) {
    std::vector<glm::vec2> nodes = identityNodes(5, 5);
    nodes[5].x = 0.01f;  // left column, row 1
    EXPECT_NE(invalidMessage(5, 5, nodes).find("V10"), std::string::npos);
    nodes = identityNodes(5, 5);
    nodes[24] = {0.99f, 1.0f};  // bottom-right corner moved
    EXPECT_NE(invalidMessage(5, 5, nodes).find("V10"), std::string::npos);
}

TEST(SamplingMap, RejectsFoldedAndDegenerate) {
    std::vector<glm::vec2> nodes = identityNodes(5, 5);
    std::swap(nodes[6], nodes[7]);  // two interior nodes swapped: folded cells
    EXPECT_NE(invalidMessage(5, 5, nodes).find("V11"), std::string::npos);
    nodes = identityNodes(5, 5);
    nodes[6] = {0.375f, 0.375f};  // crosses the diagonal of its cell: non-convex
    EXPECT_NE(invalidMessage(5, 5, nodes).find("V11"), std::string::npos);
    nodes = identityNodes(5, 5);
    nodes[6] = {0.125f, 0.125f};  // collinear with nodes (1,0) and (0,1): cell (0,0) is degenerate
    EXPECT_NE(invalidMessage(5, 5, nodes).find("V11"), std::string::npos);
}

TEST(SamplingMap, JacobianMatchesFiniteDifferences) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> unit(0.02, 0.98);
    const SamplingMap map = randomFociMap(rng, 33, 33, FociComposition::Density);
    const double h = 1e-7;
    for (int k = 0; k < 2000; ++k) {
        const glm::dvec2 p{unit(rng), unit(rng)};
        // Stay inside one cell so the piecewise map is differentiable at p.
        if (std::abs(std::remainder(p.x * 32, 1.0)) < 1e-5 || std::abs(std::remainder(p.y * 32, 1.0)) < 1e-5) continue;
        const glm::dmat2 j = map.jacobian(p);
        const glm::dvec2 du = (map.distort(p + glm::dvec2(h, 0)) - map.distort(p - glm::dvec2(h, 0))) / (2 * h);
        const glm::dvec2 dv = (map.distort(p + glm::dvec2(0, h)) - map.distort(p - glm::dvec2(0, h))) / (2 * h);
        EXPECT_NEAR(j[0].x, du.x, 1e-6 * (1 + std::abs(du.x)));
        EXPECT_NEAR(j[0].y, du.y, 1e-6 * (1 + std::abs(du.y)));
        EXPECT_NEAR(j[1].x, dv.x, 1e-6 * (1 + std::abs(dv.x)));
        EXPECT_NEAR(j[1].y, dv.y, 1e-6 * (1 + std::abs(dv.y)));
        EXPECT_NEAR(map.density(p), glm::determinant(j), 1e-12);
        EXPECT_GT(map.density(p), 0.0);
    }
}

TEST(SamplingMap, DensityIntegratesToOne) {
    // det J is an area ratio and the map is onto [0,1]^2: its mean over the square is 1.
    std::mt19937 rng(8);
    const SamplingMap map = randomFociMap(rng, map_rules::kDefaultSide, map_rules::kDefaultSide, FociComposition::Density);
    double sum = 0;
    const int s = 512;
    for (int y = 0; y < s; ++y)
        for (int x = 0; x < s; ++x) sum += map.density({(x + 0.5) / s, (y + 0.5) / s});
    EXPECT_NEAR(sum / (double(s) * s), 1.0, 1e-3);
}

TEST(SamplingMap, ResampledAgreesWithOriginal) {
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const SamplingMap map = randomFociMap(rng, 33, 33, FociComposition::Density);
    // A grid whose cells subdivide the original ones reproduces it up to float rounding.
    const SamplingMap finer = map.resampled(map_rules::kDefaultSide, 129);
    EXPECT_EQ(finer.columns(), map_rules::kDefaultSide);
    EXPECT_EQ(finer.rows(), 129);
    // Any other grid approximates it.
    const SamplingMap other = map.resampled(50, 41);
    for (int k = 0; k < 10000; ++k) {
        const glm::dvec2 p{unit(rng), unit(rng)};
        EXPECT_LT(glm::length(finer.distort(p) - map.distort(p)), 2e-7);
        EXPECT_LT(glm::length(other.distort(p) - map.distort(p)), 1e-2);
    }
    // Boundary nodes exactly on their edge (V10), whatever the rounding.
    for (int j = 0; j < other.rows(); ++j) {
        EXPECT_EQ(other.node(0, j).x, 0.0f);
        EXPECT_EQ(other.node(other.columns() - 1, j).x, 1.0f);
    }
}

TEST(SamplingMap, GridRoundTripCopyAndMove) {
    std::mt19937 rng(10);
    const SamplingMap map = randomFociMap(rng, 21, 17, FociComposition::Add);
    const SamplingMap fromGrid = SamplingMap::fromGrid(map.toGrid());
    EXPECT_EQ(fromGrid.nodes(), map.nodes());
    SamplingMap copy = map;
    SamplingMap assigned = SamplingMap::identity(3, 3);
    assigned = copy;
    SamplingMap moved = std::move(copy);
    const glm::dvec2 q{0.3, 0.6};
    EXPECT_EQ(moved.undistort(q), map.undistort(q));
    EXPECT_EQ(assigned.undistort(q), map.undistort(q));
    EXPECT_EQ(assigned.distort(q), map.distort(q));
    format::GridNodes bad = map.toGrid();
    bad.xy.pop_back();
    EXPECT_THROW(SamplingMap::fromGrid(bad), Error);
}


// ---- the inverse's index: bounded memory whatever the map's shape ------------------------------

std::int64_t indexBudget(const SamplingMap& map) {
    const std::int64_t cells = std::int64_t{map.columns() - 1} * (map.rows() - 1);
    return std::min(kMaxIndexBytes, kIndexBytesPerCell * cells + kIndexBytesBase);
}

// The shape of the hostile maps in ../shared/data/hostile, at any size: even rows crowd into the
// left strip [0, (n-2) eps], odd rows into the right strip, so every cell is a sliver across the
// whole width (bounding boxes cover the plane n times over) and the cells next to the right edge
// taper to a point (a root of the inverse's quadratic where the patch folds).
SamplingMap zigzagMap(int n, int m) {
    const double eps = 0.01 / (n - 2);
    std::vector<glm::vec2> nodes(std::size_t(n) * m);
    for (int j = 0; j < m; ++j)
        for (int i = 0; i < n; ++i) {
            double x = j % 2 == 0 ? i * eps : (i == 0 ? 0.0 : 1.0 - (n - 1 - i) * eps);
            if (i == n - 1) x = 1.0;
            if (j == m - 1) x = double(i) / (n - 1);
            nodes[std::size_t(j) * n + i] = {float(x), float(double(j) / (m - 1))};
        }
    return SamplingMap(n, m, std::move(nodes));
}

TEST(SamplingMapIndex, OrdinaryMapsKeepTwoBucketsPerCell) {
    // About 9 cells listed and 4 bucket starts per cell at 2x2 buckets per cell: 52 bytes a cell.
    for (int side : {17, map_rules::kDefaultSide, 257}) {
        const SamplingMap map = SamplingMap::identity(side, side);
        const double perCell = double(map.indexBytes()) / ((side - 1) * (side - 1));
        EXPECT_GT(perCell, 45.0) << side;
        EXPECT_LE(std::int64_t(map.indexBytes()), indexBudget(map)) << side;
    }
    std::vector<Focus> foci{{0.42, 0.31, 0.08, 4}, {0.7, 0.65, 0.1, 3}};
    FociOptions options;
    options.columns = options.rows = 257;
    const SamplingMap map = buildFociMap(foci, options);
    EXPECT_GT(double(map.indexBytes()) / (256 * 256), 45.0);
}

TEST(SamplingMapIndex, SliverCellsStayWithinBudgetAndInvertExactly) {
    std::mt19937 rng(15);
    for (int n : {5, 17, map_rules::kDefaultSide, 257}) {
        const SamplingMap map = zigzagMap(n, n);
        EXPECT_LE(std::int64_t(map.indexBytes()), indexBudget(map)) << n;
        const RoundTrip r = roundTrip(map, rng, 2000);
        EXPECT_LT(r.backward, 1e-9) << n;
    }
}

TEST(SamplingMapIndex, TaperedCellInvertsToTheRootThatSolvesIt) {
    // Regression: on the edge shared by two tapered cells the closed form picked the root on the
    // fold line (b + d t = 0), where s is undetermined, and returned s = 0.5.
    const SamplingMap map = zigzagMap(257, 257);
    for (const glm::dvec2 q : {glm::dvec2(0.5, 0.5), glm::dvec2(0.1, 0.9), glm::dvec2(0.3, 0.3)}) {
        const glm::dvec2 back = map.distort(map.undistort(q));
        EXPECT_NEAR(back.x, q.x, 1e-12);
        EXPECT_NEAR(back.y, q.y, 1e-12);
    }
}

TEST(SamplingMapIndex, BuiltOnFirstUseOnceAcrossThreads) {
    const SamplingMap map = zigzagMap(map_rules::kDefaultSide, map_rules::kDefaultSide);
    const SamplingMap copy = map;  // not built yet: the copy builds its own
    std::vector<glm::dvec2> results(8);
    std::vector<std::thread> threads;
    for (int t = 0; t < 8; ++t)
        threads.emplace_back([&, t] { results[t] = map.undistort({0.125 * t + 0.01, 0.5}); });
    for (std::thread& t : threads) t.join();
    for (int t = 0; t < 8; ++t) {
        EXPECT_NEAR(map.distort(results[t]).x, 0.125 * t + 0.01, 1e-12);
        EXPECT_EQ(copy.undistort({0.125 * t + 0.01, 0.5}), results[t]);
    }
    const SamplingMap built = map;  // built: shared
    EXPECT_EQ(built.indexBytes(), map.indexBytes());
}

// The sizes of two hostile files (900x900 nodes: the index's 32-bit counts overflowed, a heap
// overflow; 257x257: 575 MB), as zigzag grids of the longest cells a valid map can have. (The
// files themselves, each over a 24x16 image, are now refused by readers from their headers.)
TEST(SamplingMapIndex, HostileMapSizesStayWithinTheBudget) {
    std::mt19937 rng(15);
    for (const int side : {900, 257}) {
        const auto start = std::chrono::steady_clock::now();
        const SamplingMap map = zigzagMap(side, side);
        EXPECT_LE(std::int64_t(map.indexBytes()), indexBudget(map)) << side;
        EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0 * conus::testing::kTimeScale)
            << side;
        EXPECT_LT(roundTrip(map, rng, 200).backward, 1e-9) << side;
    }
}

}  // namespace
}  // namespace conus::codec
