// Automatic maps from a 4096^2 importance image: construction time for the 2-D method (the default
// bounded builder) and the separable baseline, with how well each achieves the target density
// (counter "correlation"). Three sharp blobs on a 65x65 grid ask for more than either can hold
// within the density bounds, so both return the closest map instead of refusing (refuseBounds).
#include <benchmark/benchmark.h>

#include <cmath>

#include "conus/codec/builders/auto_map.h"

namespace {

using namespace conus;

const Image& importance4096() {
    static const Image image = [] {
        Image img = makeImage(4096, 4096, {"Y"});
        const double blobs[][3] = {{0.3, 0.3, 0.05}, {0.7, 0.65, 0.04}, {0.25, 0.8, 0.03}};
        for (int y = 0; y < 4096; ++y)
            for (int x = 0; x < 4096; ++x) {
                double v = 0;
                for (const auto& b : blobs) {
                    const double dx = (x + 0.5) / 4096 - b[0], dy = (y + 0.5) / 4096 - b[1];
                    v += std::exp(-(dx * dx + dy * dy) / (2 * b[2] * b[2]));
                }
                img.at(x, y) = static_cast<float>(v);
            }
        return img;
    }();
    return image;
}

void run(benchmark::State& state, codec::AutoMethod method) {
    const Image& importance = importance4096();
    codec::AutoMapOptions options;
    options.method = method;
    options.refuseBounds = false;
    double correlation = 0;
    for (auto _ : state) {
        const codec::SamplingMap map = codec::buildAutoMap(importance, options);
        benchmark::DoNotOptimize(map.nodes().data());
        state.PauseTiming();
        correlation = codec::densityCorrelation(map, codec::importanceToDensity(importance, options));
        state.ResumeTiming();
    }
    state.counters["correlation"] = correlation;
}

void BM_AutoMapFlow4096(benchmark::State& state) { run(state, codec::AutoMethod::Flow); }
void BM_AutoMapSeparable4096(benchmark::State& state) { run(state, codec::AutoMethod::Separable); }

}  // namespace

BENCHMARK(BM_AutoMapSeparable4096)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_AutoMapFlow4096)->Unit(benchmark::kMillisecond)->UseRealTime();
