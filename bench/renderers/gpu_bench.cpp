// GPU encode and decode against the CPU reference, in one binary so ratios come from one run.
// CONUS_BACKEND picks the GL backend (auto, egl, osmesa; default auto: the EGL hardware device on a
// GPU machine, llvmpipe elsewhere). GPU rows report upload, draw and readback per call.
//
//   encode: a 4096^2 RGB source -> 1024^2 CoNUS image through a two-focus map, from memory, with
//           the default (anisotropic) filter: a float source (BM_EncodeCpu, BM_EncodeGpu: the
//           mipmapped GL encoder uploads half floats) and the same picture rounded to 8-bit sRGB
//           codes, as a PNG or JPEG reads (BM_EncodeCpu8Bit, BM_EncodeGpu8Bit/<anisotropy>: 8-bit
//           sRGB textures; /1 a trilinear sample per tap, /4 the sampler's anisotropic filter for
//           up to 4 taps); BM_EncodeGpuEwa is the EWA GL encoder on the float source
//   decode: a 1920x1080 view of a 2048^2 RGB CoNUS image
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "conus/codec/image/decode.h"
#include "conus/codec/image/encode.h"
#include "conus/codec/builders/foci.h"
#include "bench_context.h"
#include "conus/renderers/context.h"
#include "conus/renderers/gpu_image.h"

namespace {

using namespace conus;

Image smoothSource(int size) {
    Image im = makeImage(size, size, {"R", "G", "B"});
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const double u = (x + 0.5) / size, v = (y + 0.5) / size;
            for (int c = 0; c < 3; ++c)
                im.at(x, y, c) = static_cast<float>(0.5 + 0.3 * std::sin(40.0 * u + c) * std::cos(31.0 * v - c) +
                                                    0.1 * std::sin(400.0 * u * v));
        }
    return im;
}

const codec::SamplingMap& focusMap() {
    static const codec::SamplingMap map =
        codec::buildFociMap(std::vector<codec::Focus>{{0.35, 0.4, 0.08, 4}, {0.7, 0.65, 0.06, 3}});
    return map;
}

const Image& encodeSource() {
    static const Image image = smoothSource(4096);
    return image;
}

// The source rounded to 8-bit sRGB codes and linearised again, as reading an 8-bit file gives.
Image rounded8Bit(Image image) {
    for (float& v : image.pixels) {
        const double s = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(std::max(0.0f, v), 1 / 2.4) - 0.055;
        const double code = std::round(std::clamp(s, 0.0, 1.0) * 255.0) / 255.0;
        v = static_cast<float>(code <= 0.04045 ? code / 12.92 : std::pow((code + 0.055) / 1.055, 2.4));
    }
    return image;
}

const Image& encodeSource8Bit() {
    static const Image image = rounded8Bit(encodeSource());
    return image;
}

const Image& decodeSource() {
    static const Image image = smoothSource(2048);
    return image;
}

// Null when no GL backend works (the GPU rows then skip).
renderers::Context* context() { return bench::sharedBenchContext(); }

void reportTimings(benchmark::State& state, const renderers::GpuTimings& sum) {
    const auto avg = benchmark::Counter::kAvgIterations;
    state.counters["upload_ms"] = benchmark::Counter(sum.uploadMs, avg);
    state.counters["draw_ms"] = benchmark::Counter(sum.drawMs, avg);
    state.counters["readback_ms"] = benchmark::Counter(sum.readbackMs, avg);
    state.SetLabel(context()->renderer() + ": " + sum.path);
}

codec::EncodeOptions encodeOptions() {
    codec::EncodeOptions o;
    o.width = 1024;
    o.height = 1024;
    return o;
}

codec::DecodeOptions decodeOptions() {
    codec::DecodeOptions o;
    o.view = {0.2, 0.25, 0.2 + 0.6, 0.25 + 0.6 * 1080.0 / 1920.0};
    o.width = 1920;
    o.height = 1080;
    return o;
}

void BM_EncodeCpu(benchmark::State& state) {
    const Image& source = encodeSource();
    for (auto _ : state) benchmark::DoNotOptimize(codec::encodeImage(source, focusMap(), encodeOptions()));
}

// Times run(&timings) on the GL context, once untimed first (shaders compile on the first call),
// and reports the average upload, draw and readback times beside the wall clock.
template <class Run>
void timeGpu(benchmark::State& state, Run run) {
    if (!context()) return state.SkipWithError("no GL backend");
    run(nullptr);
    renderers::GpuTimings sum, t;
    for (auto _ : state) {
        benchmark::DoNotOptimize(run(&t));
        sum.uploadMs += t.uploadMs;
        sum.drawMs += t.drawMs;
        sum.readbackMs += t.readbackMs;
        sum.path = t.path;
    }
    reportTimings(state, sum);
}

void BM_EncodeGpu(benchmark::State& state) {
    const Image& source = encodeSource();
    timeGpu(state, [&](renderers::GpuTimings* t) { return renderers::encodeImageGpu(*context(), source, focusMap(), encodeOptions(), t); });
}

void BM_EncodeCpu8Bit(benchmark::State& state) {
    const Image& source = encodeSource8Bit();
    for (auto _ : state) benchmark::DoNotOptimize(codec::encodeImage(source, focusMap(), encodeOptions()));
}

void BM_EncodeGpu8Bit(benchmark::State& state) {
    const Image& source = encodeSource8Bit();
    renderers::GpuEncodeOptions gpu;
    gpu.anisotropy = static_cast<int>(state.range(0));
    timeGpu(state, [&](renderers::GpuTimings* t) {
        return renderers::encodeImageGpu(*context(), source, focusMap(), encodeOptions(), t, gpu);
    });
}

void BM_EncodeGpuEwa(benchmark::State& state) {
    const Image& source = encodeSource();
    renderers::GpuEncodeOptions gpu;
    gpu.kernel = renderers::GpuEncodeKernel::Ewa;
    timeGpu(state, [&](renderers::GpuTimings* t) {
        return renderers::encodeImageGpu(*context(), source, focusMap(), encodeOptions(), t, gpu);
    });
}

Image decodeInput() {
    codec::EncodeOptions o;
    o.width = 2048;
    o.height = 2048;
    return codec::encodeImage(decodeSource(), focusMap(), o);
}

const Image& conusImage() {
    static const Image image = decodeInput();
    return image;
}

void BM_DecodeCpu(benchmark::State& state) {
    const Image& conus = conusImage();
    for (auto _ : state) benchmark::DoNotOptimize(codec::decodeImage(conus, focusMap(), decodeOptions()));
}

void BM_DecodeGpu(benchmark::State& state) {
    const Image& conus = conusImage();
    timeGpu(state, [&](renderers::GpuTimings* t) { return renderers::decodeImageGpu(*context(), conus, focusMap(), decodeOptions(), t); });
}

BENCHMARK(BM_EncodeCpu)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_EncodeGpu)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_EncodeCpu8Bit)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_EncodeGpu8Bit)->Arg(1)->Arg(4)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_EncodeGpuEwa)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DecodeCpu)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DecodeGpu)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
