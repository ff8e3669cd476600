// Sampling-map lookups and builders. Baseline in the same binary: a plain bilinear lookup in a flat
// float grid of the identity (Eq. 1's arithmetic with nothing else), so that distort/undistort
// are read as ratios to it.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "conus/codec/builders/density_map.h"
#include "conus/codec/builders/foci.h"
#include "conus/codec/map/sampling_map.h"
#include "conus/core/map_rules.h"

namespace {

using namespace conus::codec;

constexpr int kSide = conus::map_rules::kDefaultSide;
constexpr int kPoints = 4096;

const std::vector<Focus>& twoFoci() {
    static const std::vector<Focus> foci{{0.42, 0.31, 0.08, 4}, {0.7, 0.65, 0.1, 3}};
    return foci;
}

const SamplingMap& twoFocusMap() {
    static const SamplingMap map = buildFociMap(twoFoci());
    return map;
}

const std::vector<glm::dvec2>& points() {
    static const std::vector<glm::dvec2> p = [] {
        std::mt19937 rng(42);
        std::uniform_real_distribution<double> unit(0.0, 1.0);
        std::vector<glm::dvec2> v(kPoints);
        for (glm::dvec2& q : v) q = {unit(rng), unit(rng)};
        return v;
    }();
    return p;
}

// The baseline: Eq. 1 on the identity's float nodes, written inline.
void BM_BaselineBilinear(benchmark::State& state) {
    std::vector<float> xy(2 * kSide * kSide);
    for (int j = 0; j < kSide; ++j)
        for (int i = 0; i < kSide; ++i) {
            xy[2 * (j * kSide + i)] = float(i) / (kSide - 1);
            xy[2 * (j * kSide + i) + 1] = float(j) / (kSide - 1);
        }
    const auto& ps = points();
    for (auto _ : state) {
        for (const glm::dvec2& p : ps) {
            const double fx = std::clamp(p.x, 0.0, 1.0) * (kSide - 1), fy = std::clamp(p.y, 0.0, 1.0) * (kSide - 1);
            const int i = std::min(int(fx), kSide - 2), j = std::min(int(fy), kSide - 2);
            const double s = fx - i, t = fy - j;
            const float* a = &xy[2 * (j * kSide + i)];
            const float* b = a + 2 * kSide;
            const double x = (a[0] * (1 - s) + a[2] * s) * (1 - t) + (b[0] * (1 - s) + b[2] * s) * t;
            const double y = (a[1] * (1 - s) + a[3] * s) * (1 - t) + (b[1] * (1 - s) + b[3] * s) * t;
            benchmark::DoNotOptimize(x);
            benchmark::DoNotOptimize(y);
        }
    }
    state.SetItemsProcessed(state.iterations() * kPoints);
}
BENCHMARK(BM_BaselineBilinear);

void lookups(benchmark::State& state, const SamplingMap& map, bool inverse) {
    const auto& ps = points();
    for (auto _ : state) {
        for (const glm::dvec2& p : ps) {
            const glm::dvec2 r = inverse ? map.undistort(p) : map.distort(p);
            benchmark::DoNotOptimize(r);
        }
    }
    state.SetItemsProcessed(state.iterations() * kPoints);
}

// BM_Distort, BM_DistortIdentity, BM_Undistort, BM_UndistortIdentity: each lookup on the two-focus
// map and on the identity.
const bool kLookupsRegistered = [] {
    static const SamplingMap identity = SamplingMap::identity(kSide, kSide);
    for (const bool inverse : {false, true}) {
        const std::string name = inverse ? "BM_Undistort" : "BM_Distort";
        benchmark::RegisterBenchmark((name + "Identity").c_str(), [inverse](benchmark::State& s) { lookups(s, identity, inverse); });
        benchmark::RegisterBenchmark(name.c_str(), [inverse](benchmark::State& s) { lookups(s, twoFocusMap(), inverse); });
    }
    return true;
}();

void BM_BuildMapFromDensity(benchmark::State& state) {
    const int side = int(state.range(0));
    DensityField field;
    field.width = field.height = side;
    for (int y = 0; y < side; ++y)
        for (int x = 0; x < side; ++x) {
            const double u = (x + 0.5) / side - 0.4, v = (y + 0.5) / side - 0.6;
            field.values.push_back(float(1.0 + 15.0 * std::exp(-(u * u + v * v) / (2 * 0.05 * 0.05))));
        }
    for (auto _ : state) benchmark::DoNotOptimize(buildMapFromDensity(field));
}
// The builders use every core: wall-clock time is what a caller waits.
BENCHMARK(BM_BuildMapFromDensity)->Arg(256)->Arg(512)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_BuildFociMap(benchmark::State& state) {
    FociOptions options;
    options.composition = state.range(0) == 0 ? FociComposition::Density : FociComposition::Add;
    state.SetLabel(state.range(0) == 0 ? "2 foci, density" : "2 foci, add");
    for (auto _ : state) benchmark::DoNotOptimize(buildFociMap(twoFoci(), options));
}
BENCHMARK(BM_BuildFociMap)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
