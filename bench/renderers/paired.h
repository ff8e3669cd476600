// Two renders timed in interleaved pairs (A B, B A, A B, ...), each on its own: the median of the
// per-pair ratios is what a loaded machine disturbs least, since both renders of a pair see the
// same load, and the alternating order cancels a drift within a pair.
#pragma once

#include <algorithm>
#include <vector>

#include <benchmark/benchmark.h>

namespace conus::bench {

// Runs the benchmark loop; timeA and timeB do one render each and return its milliseconds.
// Counters: ratio_median (B over A) and its quartiles, and the number of pairs.
template <class TimeA, class TimeB>
void pairedRatio(benchmark::State& state, TimeA&& timeA, TimeB&& timeB) {
    std::vector<double> ratios;
    bool bFirst = false;
    for (auto _ : state) {
        double a, b;
        if (bFirst) {
            b = timeB();
            a = timeA();
        } else {
            a = timeA();
            b = timeB();
        }
        bFirst = !bFirst;
        if (a > 0) ratios.push_back(b / a);
    }
    std::sort(ratios.begin(), ratios.end());
    if (ratios.empty()) return;
    state.counters["ratio_median"] = ratios[ratios.size() / 2];
    state.counters["ratio_q1"] = ratios[ratios.size() / 4];
    state.counters["ratio_q3"] = ratios[ratios.size() * 3 / 4];
    state.counters["pairs"] = static_cast<double>(ratios.size());
}

}  // namespace conus::bench
