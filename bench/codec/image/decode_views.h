// The decode benchmarks' inputs, shared by codec_bench and oiio_baseline_bench: a 2048^2 RGB
// image of hash noise, the two-focus map it is read through, and the 1920x1080 views (the whole
// frame, and a zoom on the first focus); and the bilinear baseline both binaries time.
#pragma once

#include <benchmark/benchmark.h>

#include <cstdint>
#include <vector>

#include "conus/codec/builders/foci.h"
#include "conus/codec/image/decode.h"

namespace conus::bench {

// Hash noise: content does not change the cost of these kernels, and this is quick to build.
inline Image hashImage(int side, unsigned seed) {
    // makeImage, as the EXR reader does: huge pages for a large image.
    Image im = makeImage(side, side, {"R", "G", "B"});
    std::uint32_t h = seed * 2654435761u + 1;
    for (float& v : im.pixels) {
        h ^= h << 13;
        h ^= h >> 17;
        h ^= h << 5;
        v = static_cast<float>(h >> 8) * (1.0f / 16777216.0f);
    }
    return im;
}

inline const std::vector<codec::Focus>& foci() {
    static const std::vector<codec::Focus> f = {{0.3, 0.35, 0.08, 4}, {0.7, 0.6, 0.06, 3}};
    return f;
}
inline const codec::SamplingMap& fociMap() {
    static const codec::SamplingMap map = codec::buildFociMap(foci());
    return map;
}
inline const Image& image2048() {
    static const Image im = hashImage(2048, 2);
    return im;
}

constexpr int kViewWidth = 1920, kViewHeight = 1080;
// 0: the whole frame (zoomed out inside the foci); 1: a 16:9 zoom centred on the first focus.
inline codec::View viewFor(int which) {
    if (which == 0) return {};
    const codec::Focus& f = foci()[0];
    return {f.u - 0.12, f.v - 0.0675, f.u + 0.12, f.v + 0.0675};
}

// The uniform image resized bilinearly to the view of state.range(0): our own baseline.
inline void decodeBaselineBilinear(benchmark::State& state) {
    const Image& image = image2048();
    const codec::View view = viewFor(static_cast<int>(state.range(0)));
    for (auto _ : state) {
        Image out = codec::resizeBilinear(image, view, kViewWidth, kViewHeight);
        benchmark::DoNotOptimize(out.pixels.data());
    }
    state.SetItemsProcessed(state.iterations() * kViewWidth * kViewHeight);
}

}  // namespace conus::bench
