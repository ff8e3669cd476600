// CoNUS volume ray casting against the conventional render of the same volume at the same size,
// in one binary so ratios come from one run (the bound: CoNUS <= 1.05x conventional; the
// paper measured +7%). CONUS_BACKEND picks the GL backend as in gpu_bench.cpp.
//
//   volume: the MRI scan brainsmall.den (128 x 128 x 84) when the shared data is there, else the
//           Shepp-Logan phantom at 128^3; transfer function "bone"; the default camera
//   GPU rows: 512 x 512; CPU rows (the reference): 256 x 256
//   CoNUS: two foci on the head (k = 3 and 2.5); conventional: the identity FPC
//   framed (the default camera) and filled (closer, the volume covering the frame): see fpc()
// Counters: hit_fraction (pixels whose ray reaches an opacity above zero), entering_fraction (rays
// that enter the volume's box) and mean_steps (samples a pixel, counted on the CPU reference)
// explain the ratio: a focus on the volume spends more of the frame's rays inside it, each of them
// longer than a ray through the empty border. ns_per_pixel, ns_per_entering_ray and ns_per_sample
// (wall time of a frame divided by those) separate that from what the FPC machinery costs.
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "conus/codec/builders/foci.h"
#include "conus/codec/volume/procedural.h"
#include "conus/codec/volume/raycast.h"
#include "bench_context.h"
#include "conus/renderers/context.h"
#include "conus/renderers/volume_renderer.h"
#include "conus/sceneio/volume_file.h"
#include "paired.h"

namespace {

using namespace conus;

const Volume& volume() {
    static const Volume v = [] {
        const std::string brain = std::string(CONUS_SHARED_DATA) + "/volumes/brainsmall.den";
        if (std::filesystem::exists(brain)) return sceneio::readVolume(brain);
        return codec::sheppLogan3d(128);
    }();
    return v;
}

const codec::TransferFunction& transfer() {
    static const codec::TransferFunction tf = codec::TransferFunction::preset("bone");
    return tf;
}

// framed: the default camera, the whole volume in view (much of the frame is empty air around it);
// filled: the eye moved to half the distance, the volume covering the frame, so conventional and
// CoNUS rays alike cross it and the ratio shows the per-ray overhead of CoNUS alone.
Fpc fpc(bool conus, int width, int height, bool filled = false) {
    Camera camera = codec::defaultVolumeCamera(volume(), double(width) / height);
    if (filled) {
        const glm::dvec3 centre = 0.5 * volume().extent();
        const double distance = glm::distance(camera.eye(), centre);
        camera = Camera::perspective(centre - camera.forward() * (0.5 * distance), centre, {0.0, -1.0, 0.0},
                                     camera.verticalFovDegrees(), double(width) / height, 0.01 * distance, 2.0 * distance);
    }
    if (!conus) return Fpc(camera, nullptr);
    return Fpc(camera, std::make_shared<codec::SamplingMap>(codec::buildFociMap(
                           std::vector<codec::Focus>{{0.45, 0.45, 0.1, 3.0}, {0.6, 0.6, 0.08, 2.5}},
                           {.aspect = double(width) / height})));
}

// Null when no GL backend works (the GPU rows then skip).
renderers::Context* context() { return bench::sharedBenchContext(); }

double hitFraction(const Image& image) {
    double hits = 0;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) hits += image.at(x, y, 3) > 0.0f;
    return hits / (double(image.width) * image.height);
}

// What the frame's rays cost, counted on the CPU reference with the same sampling (every
// `stride`-th pixel each way, outside the timing): rays that enter the volume's box (take a step)
// and samples taken, both per pixel.
struct RayCounts {
    double entering = 0;  // fraction of the pixels
    double steps = 0;     // mean samples a pixel
};

RayCounts countRays(const Fpc& f, int width, int height, int stride) {
    const Volume& v = volume();
    const glm::vec2 range = codec::renderRange(v, {});
    double entering = 0, steps = 0, count = 0;
    for (int y = 0; y < height; y += stride)
        for (int x = 0; x < width; x += stride) {
            const glm::dvec2 pd((x + 0.5) / width, (y + 0.5) / height);
            int n = 0;
            codec::castVolumeRay(v, transfer(), f.camera(), f.distortion() ? f.distortion()->undistort(pd) : pd,
                                 codec::pixelJitter(x, y), range, {}, &n);
            steps += n;
            entering += n > 0;
            ++count;
        }
    return {entering / count, steps / count};
}

// The counters that take the frame's work out of the ratio: time a pixel, a ray that enters the
// volume, and a sample. CoNUS and conventional frames of the same size differ in how many rays
// enter and how long they are; what a sample costs is what the FPC machinery could add.
void setCostCounters(benchmark::State& state, double frameMs, const RayCounts& rays, int width, int height) {
    const double pixels = double(width) * height;
    state.counters["entering_fraction"] = rays.entering;
    state.counters["mean_steps"] = rays.steps;
    state.counters["ns_per_pixel"] = frameMs * 1e6 / pixels;
    state.counters["ns_per_entering_ray"] = frameMs * 1e6 / (rays.entering * pixels);
    state.counters["ns_per_sample"] = frameMs * 1e6 / (rays.steps * pixels);
}

double millisecondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

void runGpu(benchmark::State& state, bool conus, bool filled = false) {
    if (!context()) return state.SkipWithError("no GL backend");
    const int w = 512, h = 512;
    renderers::VolumeRendererGpu renderer(*context(), volume(), transfer());
    const Fpc f = fpc(conus, w, h, filled);
    Image last = renderer.render(f, w, h, {});  // compile the shader outside the timing
    renderers::GpuTimings sum, t;
    const auto start = std::chrono::steady_clock::now();
    for (auto _ : state) {
        last = renderer.render(f, w, h, {}, &t);
        sum.uploadMs += t.uploadMs;
        sum.drawMs += t.drawMs;
        sum.readbackMs += t.readbackMs;
    }
    const double frameMs = millisecondsSince(start) / static_cast<double>(state.iterations());
    const auto avg = benchmark::Counter::kAvgIterations;
    state.counters["upload_ms"] = benchmark::Counter(sum.uploadMs, avg);
    state.counters["draw_ms"] = benchmark::Counter(sum.drawMs, avg);
    state.counters["readback_ms"] = benchmark::Counter(sum.readbackMs, avg);
    state.counters["hit_fraction"] = hitFraction(last);
    setCostCounters(state, frameMs, countRays(f, w, h, 4), w, h);
    state.SetLabel(context()->renderer());
}

void runCpu(benchmark::State& state, bool conus, bool filled = false) {
    const int w = 256, h = 256;
    const Fpc f = fpc(conus, w, h, filled);
    Image last;
    const auto start = std::chrono::steady_clock::now();
    for (auto _ : state) last = codec::renderVolumeReference(volume(), transfer(), f, w, h);
    const double frameMs = millisecondsSince(start) / static_cast<double>(state.iterations());
    state.counters["hit_fraction"] = hitFraction(last);
    setCostCounters(state, frameMs, countRays(f, w, h, 1), w, h);
}

// CoNUS over conventional on the GPU, timed in interleaved pairs (paired.h); Arg 1: filled.
// samples_ratio is what the frames' work alone predicts (mean steps, CoNUS over conventional), so
// ratio_median / samples_ratio is the per-sample cost of the FPC machinery.
void BM_VolumeGpuConusOverConventionalPaired(benchmark::State& state) {
    if (!context()) return state.SkipWithError("no GL backend");
    const bool filled = state.range(0) != 0;
    const int w = 512, h = 512;
    renderers::VolumeRendererGpu renderer(*context(), volume(), transfer());
    const Fpc conventional = fpc(false, w, h, filled), conus = fpc(true, w, h, filled);
    renderer.render(conus, w, h, {});  // compile the shader outside the timing
    const auto timeOne = [&](const Fpc& f) {
        const auto start = std::chrono::steady_clock::now();
        benchmark::DoNotOptimize(renderer.render(f, w, h, {}));
        return millisecondsSince(start);
    };
    bench::pairedRatio(state, [&] { return timeOne(conventional); }, [&] { return timeOne(conus); });
    const double samplesRatio = countRays(conus, w, h, 4).steps / countRays(conventional, w, h, 4).steps;
    state.counters["samples_ratio"] = samplesRatio;
    if (state.counters.count("ratio_median"))
        state.counters["per_sample_ratio"] = state.counters["ratio_median"] / samplesRatio;
    state.SetLabel(filled ? "filled" : "framed");
}

}  // namespace

BENCHMARK(BM_VolumeGpuConusOverConventionalPaired)->Arg(0)->Arg(1)->Iterations(21)->UseRealTime()->Unit(benchmark::kMillisecond);
// The frames, each way: BM_Volume{Gpu,Cpu}{Conventional,Conus}, then the same with Filled; in
// milliseconds of wall clock.
static const bool kFrameBenches = [] {
    for (const bool filled : {false, true})
        for (const bool gpu : {true, false})
            for (const bool conus : {false, true}) {
                const std::string name =
                    std::string("BM_Volume") + (gpu ? "Gpu" : "Cpu") + (conus ? "Conus" : "Conventional") + (filled ? "Filled" : "");
                benchmark::RegisterBenchmark(name.c_str(), gpu ? runGpu : runCpu, conus, filled)
                    ->Unit(benchmark::kMillisecond)
                    ->UseRealTime();
            }
    return true;
}();
