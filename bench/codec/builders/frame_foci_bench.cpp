// Per-frame focus maps on a 65x65 grid from 1, 2 and 8 foci, CPU time of the building thread: the
// closed-form lens builder (frame_foci.h) against the density-grid builder's add composition, the
// path it replaces, and its density composition, in the same run. The target: < 1 ms a frame.
#include <benchmark/benchmark.h>

#include <vector>

#include "conus/codec/builders/foci.h"
#include "conus/codec/builders/frame_foci.h"
#include "conus/core/map_rules.h"

namespace {

using namespace conus;

// N foci spread over a 16:9 frame, overlapping in pairs for N = 8 (as mesh_bench's BM_FociFrame).
std::vector<codec::Focus> spreadFoci(int count) {
    std::vector<codec::Focus> foci;
    for (int i = 0; i < count; ++i)
        foci.push_back({0.1 + 0.8 * ((i * 37) % 8) / 7.0, 0.15 + 0.7 * ((i * 5) % 8) / 7.0, 0.06, 4.0});
    return foci;
}

codec::FociOptions frameOptions(codec::FociComposition composition) {
    codec::FociOptions options;
    options.aspect = 16.0 / 9.0;
    options.composition = composition;
    return options;
}

void BM_FrameFociClosedForm(benchmark::State& state) {
    const auto foci = spreadFoci(static_cast<int>(state.range(0)));
    const auto options = frameOptions(codec::FociComposition::Add);
    for (auto _ : state) benchmark::DoNotOptimize(codec::buildFrameFociMap(foci, options));
}

// What any builder pays to hand back a map: the identity's nodes, validated by SamplingMap.
void BM_FrameFociIdentity(benchmark::State& state) {
    for (auto _ : state) benchmark::DoNotOptimize(codec::SamplingMap::identity(map_rules::kDefaultSide, map_rules::kDefaultSide));
}

void BM_FrameFociDensityGridAdd(benchmark::State& state) {
    const auto foci = spreadFoci(static_cast<int>(state.range(0)));
    const auto options = frameOptions(codec::FociComposition::Add);
    for (auto _ : state) benchmark::DoNotOptimize(codec::buildFociMap(foci, options));
}

void BM_FrameFociDensityGridDensity(benchmark::State& state) {
    const auto foci = spreadFoci(static_cast<int>(state.range(0)));
    const auto options = frameOptions(codec::FociComposition::Density);
    for (auto _ : state) benchmark::DoNotOptimize(codec::buildFociMap(foci, options));
}

BENCHMARK(BM_FrameFociClosedForm)->Arg(1)->Arg(2)->Arg(8)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FrameFociIdentity)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FrameFociDensityGridAdd)->Arg(1)->Arg(2)->Arg(8)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FrameFociDensityGridDensity)->Arg(1)->Arg(2)->Arg(8)->Unit(benchmark::kMicrosecond);

}  // namespace
