// The foci builders on the default 65x65 grid, in the same run: the bounded-distortion builder (the
// default) against Moser's flow, on the foci of the reported photos. Counters: the map's largest
// cell anisotropy and the smallest share of its k a focus reached (reached / k). Ratios of the two
// builders' times are the figure to quote (bench/notes/2026-11-27-map-builders.md).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <vector>

#include "conus/codec/builders/foci.h"
#include "conus/codec/builders/map_measures.h"

namespace {

using namespace conus;

struct FociCase {
    double aspect;
    std::vector<codec::Focus> foci;
};

// 0: the fig (1.48:1, one focus near the bottom); 1: astronaut (two small foci); 2: two dog faces
// (0.75:1, large foci); 3: one small k = 8 focus.
const FociCase kCases[] = {{1.48, {{0.58, 0.55, 0.12, 4}}},
                           {1.0, {{0.44, 0.24, 0.07, 4}, {0.30, 0.75, 0.06, 3}}},
                           {0.75, {{0.35, 0.4, 0.16, 4}, {0.65, 0.45, 0.17, 4}}},
                           {1.0, {{0.5, 0.5, 0.05, 8}}}};

void run(benchmark::State& state, codec::DensityBuilder builder) {
    const FociCase& c = kCases[state.range(0)];
    codec::FociOptions options;
    options.aspect = c.aspect;
    options.builder = builder;
    const codec::SamplingMap* last = nullptr;
    std::vector<codec::SamplingMap> keep;
    for (auto _ : state) {
        codec::SamplingMap map = codec::buildFociMap(c.foci, options);
        benchmark::DoNotOptimize(map.nodes().data());
        state.PauseTiming();
        keep.clear();
        keep.push_back(std::move(map));
        last = &keep.back();
        state.ResumeTiming();
    }
    if (!last) return;
    state.counters["anisotropy"] = codec::measureMap(*last, c.aspect).maxAnisotropy;
    const std::vector<double> reached = codec::reachedMagnification(*last, c.foci);
    double share = 1.0;
    for (std::size_t i = 0; i < reached.size(); ++i) share = std::min(share, reached[i] / c.foci[i].k);
    state.counters["reached_share"] = share;
}

void BM_FociBounded(benchmark::State& state) { run(state, codec::DensityBuilder::Bounded); }
void BM_FociFlow(benchmark::State& state) { run(state, codec::DensityBuilder::Flow); }

}  // namespace

BENCHMARK(BM_FociFlow)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FociBounded)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->UseRealTime();
