// Relief texture mapping on the engraved tablet (paper section 5: "an average frame rate penalty
// of only 5%"): ray / depth-image intersection on the CPU reference and in GLSL, and frames of the
// relief renderer, each for the CoNUS asset (detail importance map) and the conventional asset of
// the same texel count (identity map, the same code path): the ratio of the two is the cost of
// CoNUS. BM_Quality reports the ROI PSNRs (the engraved text vs the rest) against the frame of the
// full-resolution height field, as counters. GL backend: CONUS_BACKEND (default auto).
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdlib>
#include <memory>
#include <optional>

#include "bench_context.h"
#include "paired.h"
#include "conus/codec/builders/auto_map.h"
#include "conus/codec/depth/intersect.h"
#include "conus/codec/depth/relief.h"
#include "conus/imageio/text.h"
#include "conus/renderers/relief.h"

namespace {

using namespace conus;

constexpr int kTabletWidth = 1024, kTabletHeight = 768;  // the full-resolution height field
constexpr int kAssetWidth = 256, kAssetHeight = 192;     // both assets: 1/16 of its texels
constexpr int kFrameWidth = 640, kFrameHeight = 480;
constexpr int kRayWidth = 320, kRayHeight = 240;  // eye rays for the intersection benchmarks
constexpr int kManyRays = 4;                       // the paired GLSL walk: 4 x 4 rays a pixel of those
constexpr double kContextDensity = 0.7;            // `bake relief`'s default --min-density

struct Asset {
    format::ConusFile file;
    std::optional<codec::DepthImage> image;
    std::unique_ptr<renderers::ReliefRenderer> renderer;
};

struct Data {
    codec::Tablet tablet;
    Image ink;
    Asset conus, conventional, full;
    std::vector<Ray> rays, manyRays;
    std::unique_ptr<renderers::Context> context;
};

void load(Data& d, Asset& asset, const codec::SamplingMap* map, int width, int height) {
    codec::ReliefBakeOptions options;
    options.width = width;
    options.height = height;
    options.extent = d.tablet.extent;
    asset.file = codec::bakeRelief(d.tablet.heights, d.tablet.colour, map, options);
    asset.image.emplace(codec::DepthImage::fromFile(asset.file));
    asset.renderer = std::make_unique<renderers::ReliefRenderer>(*d.context, *asset.image, asset.file.image);
}

Data& data() {
    static Data* d = [] {
        auto* d = new Data;
        d->ink = imageio::inscription("CoNUS|FLEXIBLE PINHOLE|CAMERA", kTabletWidth, kTabletHeight);
        d->tablet = codec::makeTablet(d->ink);
        d->context = bench::createBenchContext();
        // What `conus bake relief tablet` does by default: the colour's detail decides, the rest
        // keeping 70% of its density.
        codec::AutoMapOptions options;
        options.minDensity = kContextDensity;
        const codec::SamplingMap map = codec::buildAutoMap(codec::detailImportance(d->tablet.colour), options);
        load(*d, d->conus, &map, kAssetWidth, kAssetHeight);
        load(*d, d->conventional, nullptr, kAssetWidth, kAssetHeight);
        load(*d, d->full, nullptr, kTabletWidth, kTabletHeight);
        const Camera camera = codec::defaultReliefView(*d->conus.image, double(kRayWidth) / kRayHeight);
        for (int y = 0; y < kRayHeight; ++y)
            for (int x = 0; x < kRayWidth; ++x) d->rays.push_back(camera.ray({(x + 0.5) / kRayWidth, (y + 0.5) / kRayHeight}));
        const int wide = kManyRays * kRayWidth, high = kManyRays * kRayHeight;
        for (int y = 0; y < high; ++y)
            for (int x = 0; x < wide; ++x) d->manyRays.push_back(camera.ray({(x + 0.5) / wide, (y + 0.5) / high}));
        return d;
    }();
    return *d;
}

Asset& assetOf(const benchmark::State& state) { return state.range(0) ? data().conus : data().conventional; }

void BM_IntersectCpu(benchmark::State& state) {
    const Asset& asset = assetOf(state);
    const std::vector<Ray>& rays = data().rays;
    long steps = 0;
    for (auto _ : state)
        for (const Ray& ray : rays)
            if (const auto hit = codec::intersect(*asset.image, ray)) steps += hit->steps;
    state.SetItemsProcessed(state.iterations() * static_cast<long>(rays.size()));
    state.counters["steps/ray"] = double(steps) / double(state.iterations() * rays.size());
    state.SetLabel(state.range(0) ? "CoNUS" : "conventional");
}

void BM_IntersectGlsl(benchmark::State& state) {
    Data& d = data();
    const Asset& asset = assetOf(state);
    for (auto _ : state) benchmark::DoNotOptimize(renderers::intersectRays(*d.context, *asset.image, d.rays));
    state.SetItemsProcessed(state.iterations() * static_cast<long>(d.rays.size()));
    state.SetLabel(state.range(0) ? "CoNUS" : "conventional");
}

// CoNUS over conventional in interleaved pairs (paired.h), where a fast GPU's clocks and a loaded
// machine would otherwise swap the sides of separate runs. Arg 0: the GLSL walk of the 320 x 240
// rays (with their upload and readback); 1: of 1280 x 960 rays, where the walk outweighs the
// transfers; 2: the relief frame's draw (640 x 480, waited for); 3: codec::intersect of the
// 320 x 240 rays on the CPU (one thread).
void BM_ReliefPaired(benchmark::State& state) {
    Data& d = data();
    const auto milliseconds = [](auto&& work) {
        const auto start = std::chrono::steady_clock::now();
        work();
        return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    };
    const auto timeOne = [&](Asset& asset) {
        if (state.range(0) == 2) {
            const Camera camera = codec::defaultReliefView(*asset.image, double(kFrameWidth) / kFrameHeight);
            return milliseconds([&] { asset.renderer->draw(camera, kFrameWidth, kFrameHeight); });
        }
        if (state.range(0) == 3)
            return milliseconds([&] {
                for (const Ray& ray : d.rays) benchmark::DoNotOptimize(codec::intersect(*asset.image, ray));
            });
        const std::vector<Ray>& rays = state.range(0) ? d.manyRays : d.rays;
        return milliseconds([&] { benchmark::DoNotOptimize(renderers::intersectRays(*d.context, *asset.image, rays)); });
    };
    bench::pairedRatio(state, [&] { return timeOne(d.conventional); }, [&] { return timeOne(d.conus); });
    const char* labels[] = {"GLSL walk, 320x240 rays", "GLSL walk, 1280x960 rays", "relief frame", "CPU walk, 320x240 rays"};
    state.SetLabel(labels[state.range(0)]);
}

void BM_ReliefFrame(benchmark::State& state) {
    Asset& asset = assetOf(state);
    const Camera camera = codec::defaultReliefView(*asset.image, double(kFrameWidth) / kFrameHeight);
    const auto start = std::chrono::steady_clock::now();
    for (auto _ : state) asset.renderer->draw(camera, kFrameWidth, kFrameHeight);
    const std::chrono::duration<double> seconds = std::chrono::steady_clock::now() - start;
    state.counters["fps"] = double(state.iterations()) / seconds.count();  // wall clock, not this thread's CPU
    state.SetLabel(state.range(0) ? "CoNUS" : "conventional");
}

// Arg: the map's context density (AutoMapOptions::minDensity) in percent: how much of the texel
// budget the text may take from the rest.
void BM_Quality(benchmark::State& state) {
    Data& d = data();
    codec::AutoMapOptions options;
    options.minDensity = state.range(0) / 100.0;
    const codec::SamplingMap map = codec::buildAutoMap(codec::detailImportance(d.tablet.colour), options);
    Asset conus;
    load(d, conus, &map, kAssetWidth, kAssetHeight);
    const Camera camera = codec::defaultReliefView(*d.full.image, double(kFrameWidth) / kFrameHeight);
    Image frames[3];
    for (auto _ : state) {
        frames[0] = d.full.renderer->render(camera, kFrameWidth, kFrameHeight);
        frames[1] = conus.renderer->render(camera, kFrameWidth, kFrameHeight);
        frames[2] = d.conventional.renderer->render(camera, kFrameWidth, kFrameHeight);
    }
    // The ROI: where the frame shows the engraved strokes (the full-resolution tablet drawn with
    // its ink as colour, unlit).
    renderers::ReliefLook unlit;
    unlit.ambient = 1.0f;
    renderers::ReliefRenderer maskRenderer(*d.context, *d.full.image, d.ink, unlit);
    const Image mask = maskRenderer.render(camera, kFrameWidth, kFrameHeight);
    state.counters["roi_conus_dB"] = codec::maskedPsnr(frames[1], frames[0], mask, true);
    state.counters["roi_conventional_dB"] = codec::maskedPsnr(frames[2], frames[0], mask, true);
    state.counters["rest_conus_dB"] = codec::maskedPsnr(frames[1], frames[0], mask, false);
    state.counters["rest_conventional_dB"] = codec::maskedPsnr(frames[2], frames[0], mask, false);
}

BENCHMARK(BM_IntersectCpu)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
// GL work runs on llvmpipe's own threads (or the GPU): wall-clock time is what counts there.
BENCHMARK(BM_IntersectGlsl)->Arg(0)->Arg(1)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ReliefFrame)->Arg(0)->Arg(1)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ReliefPaired)->DenseRange(0, 3)->Iterations(61)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Quality)->Arg(25)->Arg(50)->Arg(70)->Iterations(1)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
