// CPU encode and decode against their uniform baselines, read off one run:
//   BM_EncodeConus / BM_EncodeBaselineAreaDownsample: 4096^2 RGB -> 1024^2 (2-focus map vs plain area average);
//   BM_EncodeConusEwa: the same encode through the EWA filter (EncodeFilter::Ewa), the GL encoder's twin;
//   BM_FitLocal / BM_FitLeastSquares: the fit to the decoder of that encode (fit.h's two methods,
//   the least squares with the encode's default iterations), each on a copy of the encoded image.
//   BM_DecodeConusView / BM_DecodeBaselineBilinear: a 1920x1080 view of a 2048^2 image (CoNUS
//   through the map vs a uniform image), for the whole frame and for a zoom on the first focus.
//   BM_DecodeConusPyramid: the same views through the CoNUS image's mip chain (one trilinear tap
//   where zoomed out), built once like a viewer's; BM_BuildPyramid: building it.
//   OpenImageIO's resize, the outside baseline, is timed in oiio_baseline_bench (bench/oiio_baseline):
//   linking OIIO here would stop this binary under valgrind (libhwy's start-up executes rdtscp).
#include <benchmark/benchmark.h>

#include "conus/codec/image/decode.h"
#include "conus/codec/image/encode.h"
#include "conus/codec/image/fit.h"
#include "decode_views.h"

namespace {

using namespace conus;
using namespace conus::codec;
using namespace conus::bench;

const Image& source4096() {
    static const Image im = hashImage(4096, 1);
    return im;
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

void BM_EncodeConusEwa(benchmark::State& state) {
    const Image& src = source4096();
    const SamplingMap& map = fociMap();
    EncodeOptions options{1024, 1024, 0, {}};
    options.filter = EncodeFilter::Ewa;
    for (auto _ : state) {
        Image out = encodeImage(src, map, options);
        benchmark::DoNotOptimize(out.pixels.data());
    }
    state.SetItemsProcessed(state.iterations() * 1024 * 1024);
}

void fitEncoded(benchmark::State& state, FitMethod method) {
    const Image& src = source4096();
    const SamplingMap& map = fociMap();
    // The encode's low-pass share goes to the fit, as `conus encode` hands it on.
    static std::vector<float> share;
    static const Image encoded = encodeImage(src, map, {1024, 1024, 0, {}, EncodeFilter::Anisotropic, nullptr, &share});
    FitOptions options;
    options.method = method;
    options.lowPassShare = &share;
    options.iterations = kDefaultEncodeFitIterations;
    for (auto _ : state) {
        state.PauseTiming();
        Image image = encoded;
        state.ResumeTiming();
        fitToDecoder(src, map, image, options);
        benchmark::DoNotOptimize(image.pixels.data());
    }
}

void BM_FitLocal(benchmark::State& state) { fitEncoded(state, FitMethod::Local); }
void BM_FitLeastSquares(benchmark::State& state) { fitEncoded(state, FitMethod::LeastSquares); }

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

void BM_DecodeBaselineBilinear(benchmark::State& state) { decodeBaselineBilinear(state); }

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

// The encodes' CPU column is the whole process's (every thread's) CPU time: on a shared machine the
// wall time follows the load, the CPU time much less.
BENCHMARK(BM_EncodeConus)->UseRealTime()->MeasureProcessCPUTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_EncodeConusEwa)->UseRealTime()->MeasureProcessCPUTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_EncodeBaselineAreaDownsample)->UseRealTime()->MeasureProcessCPUTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FitLocal)->UseRealTime()->MeasureProcessCPUTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FitLeastSquares)->UseRealTime()->MeasureProcessCPUTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DecodeConusView)->ArgName("zoom")->Arg(0)->Arg(1)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DecodeBaselineBilinear)->ArgName("zoom")->Arg(0)->Arg(1)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DecodeConusPyramid)->ArgName("zoom")->Arg(0)->Arg(1)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BuildPyramid)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
