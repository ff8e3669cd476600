// Mass-spring brush system: steps per second of a 256x256 particle grid, next to a baseline in the
// same binary (one plain streaming pass over arrays of the same size: the memory traffic floor of
// any step), and the time to the stable state for a typical stroke set. The paper updates 256x256
// particles at 30 steps/s and reaches the stable state in under 2 s.
#include <benchmark/benchmark.h>

#include <vector>

#include "conus/codec/builders/springs.h"

namespace {

constexpr int kSide = 256;

const std::vector<conus::codec::Stroke>& typicalStrokes() {
    static const std::vector<conus::codec::Stroke> strokes{
        {0.35, 0.4, 0.15, 1.5, 0.3}, {0.65, 0.6, 0.1, 1.0, 0.3}, {0.5, 0.8, 0.08, 2.0, 0.2}};
    return strokes;
}

// Steps of a system that is still moving (strokes being painted in and settling).
void BM_SpringStep256(benchmark::State& state) {
    conus::codec::SpringSystem system(kSide, kSide);
    for (const auto& s : typicalStrokes()) system.addStroke({s.u, s.v, s.radius, s.strength, 1e3});
    system.step(20);
    for (auto _ : state) system.step();
    state.SetItemsProcessed(state.iterations());
    state.counters["particles"] = double(kSide) * kSide;
}
BENCHMARK(BM_SpringStep256)->Unit(benchmark::kMillisecond);

// Baseline: x += dt * v over 256x256 float pairs, the cheapest conceivable particle update.
void BM_SpringBaselinePass256(benchmark::State& state) {
    const std::size_t n = std::size_t(kSide) * kSide;
    std::vector<float> x(n, 0.5f), y(n, 0.5f), vx(n, 1e-3f), vy(n, -1e-3f);
    for (auto _ : state) {
        for (std::size_t k = 0; k < n; ++k) {
            x[k] += 0.01f * vx[k];
            y[k] += 0.01f * vy[k];
        }
        benchmark::DoNotOptimize(x.data());
        benchmark::DoNotOptimize(y.data());
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_SpringBaselinePass256)->Unit(benchmark::kMillisecond);

// From the identity to stable() with runUntilStable: three strokes, painted in over 0.3 s of
// simulated time. steps: 256x256 steps; warm_steps: the coarse-grid warm start's work in 256x256
// steps. Arg 1: multilevel (the default), 0: plain stepping (the old path).
void BM_SpringTimeToStable256(benchmark::State& state) {
    int steps = 0;
    double warm = 0.0;
    conus::codec::SpringOptions options;
    options.multilevel = state.range(0) != 0;
    for (auto _ : state) {
        conus::codec::SpringSystem system(kSide, kSide, options);
        for (const auto& s : typicalStrokes()) system.addStroke(s);
        steps = system.runUntilStable(100000);
        warm = system.warmStartWork();
        benchmark::DoNotOptimize(system.time());
    }
    state.counters["steps"] = steps;
    state.counters["warm_steps"] = warm;
}
BENCHMARK(BM_SpringTimeToStable256)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);

// The same for strong strokes (strength 3-4: a brush pressed hard, the case people wait for; what
// bench/end_to_end.sh runs through `conus map springs`). Target: under 0.5 s.
void BM_SpringTimeToStableStrong256(benchmark::State& state) {
    const std::vector<conus::codec::Stroke> strokes{
        {0.35, 0.4, 0.15, 4.0, 0.3}, {0.65, 0.6, 0.1, 3.0, 0.3}, {0.5, 0.8, 0.08, 4.0, 0.2}};
    int steps = 0;
    for (auto _ : state) {
        conus::codec::SpringSystem system(kSide, kSide);
        for (const auto& s : strokes) system.addStroke(s);
        steps = system.runUntilStable(100000);
        benchmark::DoNotOptimize(system.time());
    }
    state.counters["steps"] = steps;
}
BENCHMARK(BM_SpringTimeToStableStrong256)->Unit(benchmark::kMillisecond);

}  // namespace
