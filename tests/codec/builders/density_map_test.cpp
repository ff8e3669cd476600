// buildMapFromDensity: valid maps whose det J follows the target, for smooth and extreme densities.
#include "conus/codec/builders/density_map.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <thread>

#include "conus/core/map_rules.h"
#include "conus/format/container.h"
#include "conus/core/error.h"
#include "codec/builders/valid_map.h"

namespace conus::codec {
namespace {

DensityField makeField(int w, int h, const std::function<double(double, double)>& f) {
    DensityField field;
    field.width = w;
    field.height = h;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) field.values.push_back(float(f((x + 0.5) / w, (y + 0.5) / h)));
    return field;
}

double gaussian(double u, double v, double cu, double cv, double sigma) {
    return std::exp(-((u - cu) * (u - cu) + (v - cv) * (v - cv)) / (2 * sigma * sigma));
}

double mean(const DensityField& field) {
    double sum = 0;
    for (float v : field.values) sum += v;
    return sum / double(field.values.size());
}

// Pearson correlation of the map's det J and the normalized target, sampled at cell centres of a
// 128x128 grid of undistorted points.
double correlation(const SamplingMap& map, const std::function<double(double, double)>& target) {
    double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
    const int s = 128;
    for (int y = 0; y < s; ++y)
        for (int x = 0; x < s; ++x) {
            const double u = (x + 0.5) / s, v = (y + 0.5) / s;
            const double a = map.density({u, v}), b = target(u, v);
            sa += a, sb += b, saa += a * a, sbb += b * b, sab += a * b;
        }
    const double n = double(s) * s;
    return (sab - sa * sb / n) / std::sqrt((saa - sa * sa / n) * (sbb - sb * sb / n));
}

// Valid, and its corners on the frame's corners.
void expectValid(const SamplingMap& map) {
    test::expectValid(map);
    const int n = map.columns(), m = map.rows();
    EXPECT_EQ(map.node(0, 0), glm::vec2(0, 0));
    EXPECT_EQ(map.node(n - 1, 0), glm::vec2(1, 0));
    EXPECT_EQ(map.node(0, m - 1), glm::vec2(0, 1));
    EXPECT_EQ(map.node(n - 1, m - 1), glm::vec2(1, 1));
}

TEST(DensityMap, UniformDensityGivesIdentity) {
    const SamplingMap map = buildMapFromDensity(makeField(64, 48, [](double, double) { return 3.0; }));
    const SamplingMap identity = SamplingMap::identity(map_rules::kDefaultSide, map_rules::kDefaultSide);
    for (std::size_t k = 0; k < map.nodes().size(); ++k) {
        EXPECT_NEAR(map.nodes()[k].x, identity.nodes()[k].x, 1e-6);
        EXPECT_NEAR(map.nodes()[k].y, identity.nodes()[k].y, 1e-6);
    }
}

TEST(DensityMap, HotSpotDensityFollowsTarget) {
    auto target = [](double u, double v) { return 1.0 + 8.0 * gaussian(u, v, 0.35, 0.6, 0.08); };
    const DensityField field = makeField(256, 256, target);
    const SamplingMap map = buildMapFromDensity(field);
    expectValid(map);
    const double mu = mean(field);
    EXPECT_GT(correlation(map, target), 0.95);
    // Ratio of hot spot to a far region, against the target's ratio 9.
    const double hot = map.density({0.35, 0.6}), far = map.density({0.9, 0.1});
    EXPECT_NEAR(hot / far, 9.0, 9.0 * 0.12);
    EXPECT_NEAR(hot, 9.0 / mu, 9.0 / mu * 0.12);
}

TEST(DensityMap, RandomSmoothDensitiesAreValidAndFollowed) {
    for (unsigned seed = 1; seed <= 5; ++seed) {
        std::mt19937 rng(seed);
        std::uniform_real_distribution<double> unit(0.0, 1.0);
        double cx[3], cy[3], w[3], sg[3];
        for (int g = 0; g < 3; ++g) cx[g] = unit(rng), cy[g] = unit(rng), w[g] = 10 * unit(rng), sg[g] = 0.06 + 0.2 * unit(rng);
        auto target = [&](double u, double v) {
            double d = 1.0;
            for (int g = 0; g < 3; ++g) d += w[g] * gaussian(u, v, cx[g], cy[g], sg[g]);
            return d;
        };
        DensityMapOptions options;
        options.columns = 33 + int(rng() % 40);
        options.rows = 33 + int(rng() % 40);
        const SamplingMap map = buildMapFromDensity(makeField(200, 150, target), options);
        expectValid(map);
        EXPECT_EQ(map.columns(), options.columns);
        EXPECT_EQ(map.rows(), options.rows);
        EXPECT_GT(correlation(map, target), 0.95) << "seed " << seed;
    }
}

TEST(DensityMap, SingleHotPixelIsValid) {
    DensityField field = makeField(256, 256, [](double, double) { return 1.0; });
    field.values[std::size_t(100) * 256 + 37] = 1e6f;
    expectValid(buildMapFromDensity(field));
    field.values[0] = 1e6f;  // in a corner
    expectValid(buildMapFromDensity(field));
}

TEST(DensityMap, SteepDensitiesAreValid) {
    // 1:1000 as a sharp step and as a narrow peak.
    expectValid(buildMapFromDensity(makeField(256, 256, [](double u, double) { return u < 0.5 ? 1.0 : 1000.0; })));
    expectValid(buildMapFromDensity(
        makeField(256, 256, [](double u, double v) { return 1.0 + 999.0 * gaussian(u, v, 0.5, 0.5, 0.02); })));
    // Extreme but finite: still a valid map (tempered if need be), never a crash.
    expectValid(buildMapFromDensity(makeField(64, 64, [](double u, double) { return u < 0.3 ? 1e-30 : 1e30; })));
}

TEST(DensityMap, RejectsBadInput) {
    auto expectInvalid = [](const DensityField& field, DensityMapOptions options = {}) {
        try {
            buildMapFromDensity(field, options);
            ADD_FAILURE() << "accepted";
        } catch (const Error& e) {
            EXPECT_EQ(e.code(), ErrorCode::InvalidArgument) << e.what();
        }
    };
    DensityField field = makeField(16, 16, [](double, double) { return 1.0; });
    expectInvalid(DensityField{});
    DensityField bad = field;
    bad.values[5] = std::numeric_limits<float>::quiet_NaN();
    expectInvalid(bad);
    bad = field;
    bad.values[5] = std::numeric_limits<float>::infinity();
    expectInvalid(bad);
    bad = field;
    bad.values[5] = -1.0f;
    expectInvalid(bad);
    bad = field;
    bad.values[5] = 0.0f;
    expectInvalid(bad);
    bad = field;
    bad.values.pop_back();
    expectInvalid(bad);
    DensityMapOptions options;
    options.columns = 1;
    expectInvalid(field, options);
    options = {};
    options.steps = 0;
    expectInvalid(field, options);
}

TEST(DensityMap, DeterministicBitForBit) {
    auto target = [](double u, double v) { return 1.0 + 5.0 * gaussian(u, v, 0.7, 0.3, 0.1); };
    const DensityField field = makeField(180, 120, target);
    const SamplingMap a = buildMapFromDensity(field);
    const SamplingMap b = buildMapFromDensity(field);
    ASSERT_EQ(a.nodes().size(), b.nodes().size());
    for (std::size_t k = 0; k < a.nodes().size(); ++k) {
        EXPECT_EQ(a.nodes()[k].x, b.nodes()[k].x);
        EXPECT_EQ(a.nodes()[k].y, b.nodes()[k].y);
    }
}

TEST(DensityMap, ConcurrentBuildsAgree) {
    // FFTW planning is serialized inside; concurrent callers get the same map as a lone one.
    const DensityField field = makeField(128, 96, [](double u, double v) { return 1.0 + 6.0 * gaussian(u, v, 0.3, 0.4, 0.1); });
    const std::vector<glm::vec2> expected = buildMapFromDensity(field).nodes();
    std::vector<std::vector<glm::vec2>> results(4);
    std::vector<std::thread> threads;
    for (auto& r : results) threads.emplace_back([&field, &r] { r = buildMapFromDensity(field).nodes(); });
    for (auto& t : threads) t.join();
    for (const auto& r : results) EXPECT_EQ(r, expected);
}

TEST(DensityMap, TinyFields) {
    expectValid(buildMapFromDensity(makeField(1, 1, [](double, double) { return 2.0; })));
    expectValid(buildMapFromDensity(makeField(2, 1, [](double u, double) { return u < 0.5 ? 1.0 : 4.0; })));
}

}  // namespace
}  // namespace conus::codec
