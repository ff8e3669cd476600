#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "../../../codec/src/builders/density_cells_pvt.h"
#include "conus/codec/builders/auto_map.h"
#include "conus/codec/builders/map_measures.h"
#include "conus/core/map_rules.h"
#include "conus/core/error.h"

using namespace conus;
using namespace conus::codec;

namespace {

// Importance with Gaussian blobs at the given centres (u,v,sigma) on a w x h image.
Image blobs(int w, int h, std::initializer_list<std::array<double, 3>> centres, double base = 0.0) {
    Image img = makeImage(w, h, {"Y"});
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double v = base;
            for (const auto& c : centres) {
                const double dx = (x + 0.5) / w - c[0], dy = (y + 0.5) / h - c[1];
                v += std::exp(-(dx * dx + dy * dy) / (2 * c[2] * c[2]));
            }
            img.at(x, y) = static_cast<float>(v);
        }
    return img;
}


// Importance with a bump near the top right, a noisy ramp along x and, at zeroShare, cells of none.
Image importance(int w, int h, std::mt19937& rng, double zeroShare) {
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    Image img = makeImage(w, h, {"Y"});
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const double dx = (x + 0.5) / w - 0.7, dy = (y + 0.5) / h - 0.25;
            const double v = std::exp(-(dx * dx + dy * dy) / 0.003) + 0.3 * std::pow(unit(rng), 4.0) * x / w;
            img.at(x, y) = unit(rng) < zeroShare ? 0.0f : float(v);
        }
    return img;
}
}  // namespace

TEST(AutoMap, TargetHasMeanOneAndRespectsFloorAndCap) {
    AutoMapOptions options;
    options.minDensity = 0.3;
    options.maxDensity = 9;
    const DensityField field = importanceToDensity(blobs(300, 200, {{0.3, 0.4, 0.05}}), options);
    double sum = 0, lo = 1e9, hi = 0;
    for (float v : field.values) {
        sum += v;
        lo = std::min<double>(lo, v);
        hi = std::max<double>(hi, v);
    }
    EXPECT_NEAR(sum / field.values.size(), 1.0, 1e-4);
    EXPECT_NEAR(lo, 0.3, 1e-5);
    EXPECT_LE(hi, 9.0 + 1e-5);
    EXPECT_GT(hi, 3.0);
    EXPECT_EQ(field.width, 256);  // the long side
    EXPECT_NEAR(double(field.width) / field.height, 1.5, 0.02);
}

TEST(AutoMap, FlowFollowsTheTargetBetterThanSeparable) {
    // Two blobs on a diagonal: a separable map also magnifies the off-diagonal crossings.
    const Image importance = blobs(256, 256, {{0.3, 0.3, 0.06}, {0.7, 0.7, 0.06}});
    AutoMapOptions options;
    const DensityField target = importanceToDensity(importance, options);
    const SamplingMap flow = buildAutoMap(importance, options);
    // (buildAutoMap refuses the separable map here: its bands leave cells at 1/4 of the floor.)
    const SamplingMap separable = buildSeparableMap(target, options.columns, options.rows);
    const double cFlow = densityCorrelation(flow, target), cSep = densityCorrelation(separable, target);
    EXPECT_GT(cFlow, 0.9);
    EXPECT_GT(cFlow, cSep + 0.1) << "flow " << cFlow << " separable " << cSep;
    // The off-diagonal crossing (0.3,0.7) gets context density from the flow map, but is
    // magnified by the separable one.
    EXPECT_LT(flow.density({0.3, 0.7}), 0.6);
    EXPECT_GT(separable.density({0.3, 0.7}), 1.0);
    // The default builder keeps the anisotropy bound: the blobs' steep rims cost them some of the
    // cap (the density gives way, not the bound), and still far more than the context.
    const MapMeasures m = measureMap(flow);
    EXPECT_LE(m.maxAnisotropy, map_rules::kMaxAnisotropy);
    EXPECT_GT(flow.density({0.3, 0.3}) / flow.density({0.05, 0.95}), 12.0);
    // Context keeps the floor.
    // On a fine grid Moser's flow reproduces the target: the floor in the context, the cap in the
    // blobs (a 65-node grid cannot hold the blobs' steep plateaus and gives context ~0.37 instead),
    // at the price of the shear that the bound forbids.
    options.method = AutoMethod::Flow;
    options.builder = DensityBuilder::Flow;
    options.columns = options.rows = 257;
    const SamplingMap fine = buildAutoMap(importance, options);
    EXPECT_GT(densityCorrelation(fine, target), 0.999);
    for (glm::dvec2 p : {glm::dvec2{0.05, 0.95}, {0.5, 0.1}, {0.9, 0.2}})
        EXPECT_NEAR(fine.density(p), options.minDensity, 0.02) << p.x << "," << p.y;
    EXPECT_NEAR(fine.density({0.3, 0.3}), options.maxDensity, 0.5);
}

TEST(AutoMap, AdversarialImportanceGivesValidMaps) {
    Image hot = makeImage(128, 96, {"Y"});
    hot.at(17, 80) = 1000.0f;  // a single hot pixel
    const SamplingMap a = buildAutoMap(hot);
    EXPECT_GT(a.density({17.5 / 128, 80.5 / 96}), 1.5);

    const Image zero = makeImage(64, 64, {"Y"});
    const SamplingMap b = buildAutoMap(zero);
    EXPECT_NEAR(b.density({0.37, 0.61}), 1.0, 1e-6);

    std::mt19937 random(7);
    std::uniform_real_distribution<float> noise(0, 1);
    Image rough = makeImage(200, 150, {"R", "G", "B"});
    for (float& v : rough.pixels) v = noise(random) * noise(random) * noise(random);
    for (AutoMethod method : {AutoMethod::Flow, AutoMethod::Separable}) {
        AutoMapOptions options;
        options.method = method;
        options.smoothing = 0;
        options.minDensity = 0.05;
        options.maxDensity = 400;
        EXPECT_NO_THROW(buildAutoMap(rough, options));
    }
}

TEST(AutoMap, BadInputIsAClearError) {
    Image img = blobs(32, 32, {{0.5, 0.5, 0.1}});
    img.at(3, 4) = std::numeric_limits<float>::quiet_NaN();
    try {
        buildAutoMap(img);
        FAIL() << "NaN accepted";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::InvalidArgument);
        EXPECT_NE(std::string(e.what()).find("NaN"), std::string::npos);
    }
    img.at(3, 4) = -1;
    EXPECT_THROW(buildAutoMap(img), Error);
    AutoMapOptions options;
    options.minDensity = 1.5;
    EXPECT_THROW(buildAutoMap(blobs(8, 8, {{0.5, 0.5, 0.1}}), options), Error);
    EXPECT_THROW(buildAutoMap(Image{}), Error);
}

TEST(AutoMap, DetailIsHighAtEdgesAndZeroInFlatRegions) {
    Image img = makeImage(100, 80, {"R", "G", "B"});
    for (int y = 0; y < 80; ++y)
        for (int x = 50; x < 100; ++x)
            for (int c = 0; c < 3; ++c) img.at(x, y, c) = 1.0f;
    const Image detail = detailImportance(img);
    EXPECT_GT(detail.at(49, 40), 1.0f);
    EXPECT_EQ(detail.at(10, 40), 0.0f);
    EXPECT_EQ(detail.at(90, 40), 0.0f);
}

// The scale of the importance puts the density's mean at 1 with the floor and cap exact: with and
// without a context, with cells at the cap, with a cap no cell reaches.
TEST(AutoMap, TargetMeanFloorAndCapHoldWithContextsAndCaps) {
    std::mt19937 rng(11);
    DensityField context;
    context.width = 40;
    context.height = 23;
    for (int y = 0; y < context.height; ++y)
        for (int x = 0; x < context.width; ++x) context.values.push_back(float(0.4 + 1.3 * x / 40.0 + 0.2 * (y % 3)));
    struct Case {
        int w, h;
        double minDensity, maxDensity, zeroShare;
        bool withContext;
    };
    const Case cases[] = {{300, 200, 0.25, 16, 0.0, false}, {180, 420, 0.1, 4, 0.0, false}, {256, 256, 0.5, 64, 0.0, true},
                          {1024, 640, 0.3, 9, 0.0, true},   {200, 130, 0.2, 1.5, 0.0, false}, {120, 90, 0.4, 2000, 0.0, false}};
    for (const Case& c : cases) {
        AutoMapOptions options;
        options.minDensity = c.minDensity;
        options.maxDensity = c.maxDensity;
        options.context = c.withContext ? &context : nullptr;
        const DensityField field = importanceToDensity(importance(c.w, c.h, rng, c.zeroShare), options);
        double sum = 0.0, lowestFactor = HUGE_VAL, highestFactor = 0.0;
        // The factor over the context: the context's own mean over the field's cells is 1.
        std::vector<double> ctx(field.values.size(), 1.0);
        if (c.withContext) {
            double ctxSum = 0.0;
            for (int y = 0; y < field.height; ++y)
                for (int x = 0; x < field.width; ++x)
                    ctxSum += ctx[std::size_t(y) * field.width + x] = densityAt(context, (x + 0.5) / field.width, (y + 0.5) / field.height);
            for (double& v : ctx) v *= double(ctx.size()) / ctxSum;
        }
        for (std::size_t k = 0; k < field.values.size(); ++k) {
            sum += field.values[k];
            lowestFactor = std::min(lowestFactor, field.values[k] / ctx[k]);
            highestFactor = std::max(highestFactor, field.values[k] / ctx[k]);
        }
        const std::string what = std::to_string(c.w) + "x" + std::to_string(c.h) + " max " + std::to_string(c.maxDensity);
        EXPECT_NEAR(sum / double(field.values.size()), 1.0, 1e-6) << what;
        EXPECT_NEAR(lowestFactor, c.minDensity, 1e-5 * c.minDensity) << what;
        EXPECT_LE(highestFactor, c.maxDensity * (1 + 1e-6)) << what;
        // The cap binds where the importance is concentrated enough.
        if (c.maxDensity <= 9) {
            EXPECT_NEAR(highestFactor, c.maxDensity, 1e-5 * c.maxDensity) << what;
        }
    }
}

// The scale is the very double that bisecting [0, sMax] 200 times finds (the answer the maps were
// built from before), on fields with and without contexts, floors and caps that bind or not.
TEST(AutoMap, ScaleIsTheBisectionsDouble) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    int compared = 0;
    for (int trial = 0; trial < 60; ++trial) {
        const std::size_t n = 500 + std::size_t(unit(rng) * 4000);
        std::vector<double> field(n), context(n, 1.0);
        const double spread = 1.0 + 8.0 * unit(rng);
        for (double& v : field) v = unit(rng) < 0.2 ? 0.0 : std::pow(unit(rng), spread);
        if (trial % 2) {
            double sum = 0;
            for (double& c : context) sum += c = 0.3 + 2.0 * unit(rng);
            for (double& c : context) c *= double(n) / sum;
        }
        const double floor = 0.05 + 0.6 * unit(rng), cap = 1.2 + 40.0 * unit(rng) * unit(rng);
        double smallest = HUGE_VAL;
        for (double v : field)
            if (v > 0) smallest = std::min(smallest, v);
        const double sMax = cap / smallest;
        const auto meanFor = [&](double s) {
            double sum = 0;
            for (std::size_t i = 0; i < n; ++i) sum += context[i] * std::clamp(s * field[i], floor, cap);
            return sum / double(n);
        };
        if (meanFor(sMax) < 1.0) continue;  // importanceToDensity raises the floor instead
        double lo = 0, hi = sMax;
        for (int i = 0; i < 200; ++i) {
            const double mid = 0.5 * (lo + hi);
            (meanFor(mid) < 1.0 ? lo : hi) = mid;
        }
        EXPECT_EQ(leastScaleForMeanOne(field, context, floor, cap, sMax), hi) << "trial " << trial;
        ++compared;
    }
    EXPECT_GT(compared, 40);
}

