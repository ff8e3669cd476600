// The outside baseline of the CPU decode: OpenImageIO's ImageBufAlgo::resize of the uniform 2048^2
// image to the same 1920x1080 views as codec_bench's decode benchmarks (the view rounded to whole
// pixels), beside our own bilinear baseline so that the ratio is read off one run.
// A binary of its own: OIIO pulls in libhwy, whose start-up executes an instruction (rdtscp) that
// valgrind 3.19 cannot decode, and codec_bench has to run under callgrind (bench/README.md).
#include <benchmark/benchmark.h>

#include <cmath>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include "../codec/image/decode_views.h"

namespace {

using namespace conus;
using namespace conus::bench;

void BM_DecodeBaselineBilinear(benchmark::State& state) { decodeBaselineBilinear(state); }

// arg 1: bilinear ("triangle", the default filter for a magnification); the whole frame shrinks
// 2048 -> 1080 rows, where OIIO widens its filter (antialiased, unlike our single tap).
void BM_DecodeBaselineOiio(benchmark::State& state) {
    namespace OIIO = OIIO_NAMESPACE;
    const Image& image = image2048();
    const codec::View view = viewFor(static_cast<int>(state.range(0)));
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

BENCHMARK(BM_DecodeBaselineBilinear)->ArgName("zoom")->Arg(0)->Arg(1)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DecodeBaselineOiio)->ArgName("zoom")->Arg(0)->Arg(1)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
