// CPU encode and decode against their uniform baselines, read off one run:
//   BM_EncodeConus / BM_EncodeBaselineAreaDownsample: 4096^2 RGB -> 1024^2 (2-focus map vs plain area average)
//   BM_DecodeConusView / BM_DecodeBaselineBilinear: a 1920x1080 view of a 2048^2 image (CoNUS
//   through the map vs a uniform image), for the whole frame and for a zoom on the first focus.
//   BM_DecodeConusPyramid: the same views through the CoNUS image's mip chain (one trilinear tap
//   where zoomed out), built once like a viewer's; BM_BuildPyramid: building it.
//   BM_DecodeBaselineOiio: OpenImageIO's ImageBufAlgo::resize of the uniform image to the same
//   output (the view rounded to whole pixels), the outside baseline beside our own bilinear.
#include <benchmark/benchmark.h>

#include <cmath>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <cstdint>
#include <vector>

#include "conus/codec/image/decode.h"
#include "conus/codec/image/encode.h"
#include "conus/codec/build/foci.h"

namespace {

using namespace conus;
using namespace conus::codec;

// Hash noise: content does not change the cost of these kernels, and this is quick to build.
Image hashImage(int side, unsigned seed) {
    Image im;
    im.width = im.height = side;
    im.channels = {"R", "G", "B"};
    im.pixels.resize(static_cast<std::size_t>(side) * side * 3);
    std::uint32_t h = seed * 2654435761u + 1;
    for (float& v : im.pixels) {
        h ^= h << 13;
        h ^= h >> 17;
        h ^= h << 5;
        v = static_cast<float>(h >> 8) * (1.0f / 16777216.0f);
    }
    return im;
}

const std::vector<Focus>& foci() {
    static const std::vector<Focus> f = {{0.3, 0.35, 0.08, 4}, {0.7, 0.6, 0.06, 3}};
    return f;
}
const SamplingMap& fociMap() {
    static const SamplingMap map = buildFociMap(foci());
    return map;
}
const Image& source4096() {
    static const Image im = hashImage(4096, 1);
    return im;
}
const Image& image2048() {
    static const Image im = hashImage(2048, 2);
    return im;
}

constexpr int kViewWidth = 1920, kViewHeight = 1080;
// 0: the whole frame (zoomed out inside the foci); 1: a 16:9 zoom centred on the first focus.
View viewFor(int which) {
    if (which == 0) return {};
    const Focus& f = foci()[0];
    return {f.u - 0.12, f.v - 0.0675, f.u + 0.12, f.v + 0.0675};
}

void BM_EncodeConus(benchmark::State& state) {
    const Image& src = source4096();
    const SamplingMap& map = fociMap();
    for (auto _ : state) {
        Image out = encodeImage(src, map, {1024, 1024, 0, {}});
        benchmark::DoNotOptimize(out.pixels.data());
    }
    state.SetItemsProcessed(state.iterations() * 1024 * 1024);
}

void BM_EncodeBaselineAreaDownsample(benchmark::State& state) {
    const Image& src = source4096();
    for (auto _ : state) {
        Image out = areaDownsample(src, 1024, 1024);
        benchmark::DoNotOptimize(out.pixels.data());
    }
    state.SetItemsProcessed(state.iterations() * 1024 * 1024);
}

// The 2048^2 CoNUS image decoded to the view of state.range(0), through `pyramid` when given.
void decodeViews(benchmark::State& state, const ImagePyramid* pyramid) {
    const Image& conus = image2048();
    const SamplingMap& map = fociMap();
    DecodeOptions options;
    options.view = viewFor(static_cast<int>(state.range(0)));
    options.width = kViewWidth;
    options.height = kViewHeight;
    options.pyramid = pyramid;
    for (auto _ : state) {
        Image out = decodeImage(conus, map, options);
        benchmark::DoNotOptimize(out.pixels.data());
    }
    state.SetItemsProcessed(state.iterations() * kViewWidth * kViewHeight);
}

void BM_DecodeConusView(benchmark::State& state) { decodeViews(state, nullptr); }

void BM_DecodeBaselineBilinear(benchmark::State& state) {
    const Image& image = image2048();
    const View view = viewFor(static_cast<int>(state.range(0)));
    for (auto _ : state) {
        Image out = resizeBilinear(image, view, kViewWidth, kViewHeight);
        benchmark::DoNotOptimize(out.pixels.data());
    }
    state.SetItemsProcessed(state.iterations() * kViewWidth * kViewHeight);
}

const ImagePyramid& pyramid2048() {
    static const ImagePyramid p = buildPyramid(image2048());
    return p;
}

void BM_DecodeConusPyramid(benchmark::State& state) { decodeViews(state, &pyramid2048()); }

void BM_BuildPyramid(benchmark::State& state) {
    const Image& image = image2048();
    for (auto _ : state) {
        ImagePyramid p = buildPyramid(image);
        benchmark::DoNotOptimize(p.levels.data());
    }
}

// arg 1: bilinear ("triangle", the default filter for a magnification); the whole frame shrinks
// 2048 -> 1080 rows, where OIIO widens its filter (antialiased, unlike our single tap).
void BM_DecodeBaselineOiio(benchmark::State& state) {
    namespace OIIO = OIIO_NAMESPACE;
    const Image& image = image2048();
    const View view = viewFor(static_cast<int>(state.range(0)));
    OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::FLOAT);
    OIIO::ImageBuf src(spec, const_cast<float*>(image.pixels.data()));
    const int x0 = static_cast<int>(std::lround(view.u0 * image.width));
    const int x1 = static_cast<int>(std::lround(view.u1 * image.width));
    const int y0 = static_cast<int>(std::lround(view.v0 * image.height));
    const int y1 = static_cast<int>(std::lround(view.v1 * image.height));
    src.set_roi_full(OIIO::ROI(x0, x1, y0, y1, 0, 1, 0, 3));
    const OIIO::ROI roi(0, kViewWidth, 0, kViewHeight, 0, 1, 0, 3);
    for (auto _ : state) {
        OIIO::ImageBuf out = OIIO::ImageBufAlgo::resize(src, "triangle", 0.0f, roi);
        if (out.has_error()) state.SkipWithError(out.geterror().c_str());
        benchmark::DoNotOptimize(out.localpixels());
    }
    state.SetItemsProcessed(state.iterations() * kViewWidth * kViewHeight);
}

BENCHMARK(BM_EncodeConus)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_EncodeBaselineAreaDownsample)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DecodeConusView)->ArgName("zoom")->Arg(0)->Arg(1)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DecodeBaselineBilinear)->ArgName("zoom")->Arg(0)->Arg(1)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DecodeConusPyramid)->ArgName("zoom")->Arg(0)->Arg(1)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DecodeBaselineOiio)->ArgName("zoom")->Arg(0)->Arg(1)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BuildPyramid)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
