// The GPU mesh encoder on the procedural city (paper section 6) at 1024 x 576, on the GL backend of
// CONUS_BACKEND (default auto): the CoNUS render (two tracked foci) next to the conventional render
// of the same mesh at the same size (the identity map: the paper measured no cost for the vertex
// distortion; both drawn as built), the mesh split where the map bends (the tessellation stages,
// --max-bend, the default) and everywhere on the CPU (--max-edge 0.5), their cost and PSNR against
// the Embree reference, that reference (rays
// a second), and per-frame map construction from 1..8 foci on a 65 x 65 grid, both compositions
// (the animation builds one every frame). GPU and Embree times are wall-clock (the work runs on
// other threads). Read ratios within one run (bench/README.md).
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "bench_context.h"
#include "conus/codec/builders/mesh_sequence.h"
#include "conus/codec/image/metrics.h"
#include "conus/codec/mesh/city.h"
#include "conus/codec/mesh/raycast.h"
#include "conus/codec/mesh/subdivide.h"
#include "conus/renderers/mesh_render.h"
#include "paired.h"

namespace {

using namespace conus;

constexpr int kWidth = 1024, kHeight = 576;
constexpr double kAspect = double(kWidth) / kHeight;

struct Data {
    codec::CityScene city;
    Mesh mesh, fine;  // as built; --max-edge 0.5
    Camera camera = Camera::perspective({30, 110, 160}, {0, 0, -10}, {0, 1, 0}, 50.0, kAspect, 1.0, 600.0);
    std::unique_ptr<codec::SamplingMap> map, identity;
    std::unique_ptr<renderers::Context> context;
    std::unique_ptr<renderers::MeshRenderer> renderer, fineRenderer;
    std::int64_t bendTriangles = 0;  // what the tessellation stages draw at the default --max-bend
};

// The mesh drawn as it is (no tessellation), as the paper drew it.
renderers::MeshRenderOptions asBuilt() {
    renderers::MeshRenderOptions options;
    options.maxBend = 0;
    return options;
}

Data& data() {
    static Data* d = [] {
        auto* d = new Data;
        d->mesh = d->city.meshAt(0.0);
        const std::vector<glm::dvec3> cars{d->city.carCentre(0, 0.0), d->city.carCentre(2, 0.0)};
        codec::FociOptions fo;
        fo.aspect = kAspect;
        d->map = std::make_unique<codec::SamplingMap>(codec::frameMap(codec::trackedFoci(d->camera, cars, kAspect), fo));
        d->identity = std::make_unique<codec::SamplingMap>(codec::SamplingMap::identity(2, 2));
        d->fine = codec::subdivideForMap(d->mesh, d->camera, *d->map, 0.5);
        d->context = bench::createBenchContext();
        d->renderer = std::make_unique<renderers::MeshRenderer>(*d->context, d->mesh);
        d->fineRenderer = std::make_unique<renderers::MeshRenderer>(*d->context, d->fine);
        // Warm up: shader compilation and the framebuffers belong to no frame.
        d->renderer->render(d->camera, *d->map, kWidth, kHeight, asBuilt());
        d->renderer->render(d->camera, *d->map, kWidth, kHeight, {}, nullptr, &d->bendTriangles);
        return d;
    }();
    return *d;
}

void setCounters(benchmark::State& state, double triangles) {
    state.counters["triangles"] = triangles;
    state.counters["pixels/s"] =
        benchmark::Counter(double(kWidth) * kHeight, benchmark::Counter::kIsIterationInvariantRate);
}

// Draw + resolve + readback of `renderer`, which holds its mesh already uploaded: the frame loop's cost.
void renderFrames(benchmark::State& state, renderers::MeshRenderer& renderer, const codec::SamplingMap& map,
                  const renderers::MeshRenderOptions& options, double triangles) {
    const Data& d = data();
    for (auto _ : state) benchmark::DoNotOptimize(renderer.render(d.camera, map, kWidth, kHeight, options));
    setCounters(state, triangles);
}
void BM_GpuConventional(benchmark::State& state) {
    renderFrames(state, *data().renderer, *data().identity, asBuilt(), double(data().mesh.triangleCount()));
}
void BM_GpuConus(benchmark::State& state) {
    renderFrames(state, *data().renderer, *data().map, asBuilt(), double(data().mesh.triangleCount()));
}
void BM_GpuConusSubdivided(benchmark::State& state) {
    renderFrames(state, *data().fineRenderer, *data().map, asBuilt(), double(data().fine.triangleCount()));
}
void BM_GpuConusBend(benchmark::State& state) {
    renderFrames(state, *data().renderer, *data().map, {}, double(data().bendTriangles));
}
// Only the draw (no readback): where the vertex distortion's cost would show.
void BM_GpuDrawOnly(benchmark::State& state) {
    Data& d = data();
    const codec::SamplingMap& map = state.range(0) ? *d.map : *d.identity;
    double ms = 0;
    for (auto _ : state) {
        renderers::GpuTimings timings;
        benchmark::DoNotOptimize(d.renderer->render(d.camera, map, kWidth, kHeight, asBuilt(), &timings));
        ms += timings.drawMs;
    }
    state.counters["drawMs"] = ms / static_cast<double>(state.iterations());
    state.SetLabel(state.range(0) ? "conus" : "conventional");
}
// CoNUS over conventional, timed in interleaved pairs (paired.h). Arg 1: the draw time only
// (GpuTimings, after glFinish) instead of the whole render (which returns after the readback).
void BM_GpuConusOverConventionalPaired(benchmark::State& state) {
    Data& d = data();
    const bool drawOnly = state.range(0) != 0;
    const auto timeOne = [&](const codec::SamplingMap& map) {
        renderers::GpuTimings timings;
        const auto start = std::chrono::steady_clock::now();
        benchmark::DoNotOptimize(d.renderer->render(d.camera, map, kWidth, kHeight, asBuilt(), &timings));
        const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        return drawOnly ? timings.drawMs : ms;
    };
    bench::pairedRatio(state, [&] { return timeOne(*d.identity); }, [&] { return timeOne(*d.map); });
    state.SetLabel(drawOnly ? "draw only" : "draw + resolve + readback");
}
// The default (split where the map bends, tessellation) over the mesh as built, both through the
// CoNUS map, timed in interleaved pairs: what following the map costs a frame.
void BM_GpuBendOverAsBuiltPaired(benchmark::State& state) {
    Data& d = data();
    const auto timeOne = [&](const renderers::MeshRenderOptions& options) {
        const auto start = std::chrono::steady_clock::now();
        benchmark::DoNotOptimize(d.renderer->render(d.camera, *d.map, kWidth, kHeight, options));
        return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    };
    bench::pairedRatio(state, [&] { return timeOne(asBuilt()); }, [&] { return timeOne({}); });
    state.counters["triangles"] = static_cast<double>(d.bendTriangles);
}
void BM_Subdivide(benchmark::State& state) {
    Data& d = data();
    for (auto _ : state) benchmark::DoNotOptimize(codec::subdivideForMap(d.mesh, d.camera, *d.map, 0.5));
    state.counters["triangles out"] = static_cast<double>(d.fine.triangleCount());
}
// Deterministic, run once: each CoNUS render's triangles and PSNR (RGB) against the Embree
// reference (4 rays a pixel against 4x MSAA): as built, where the map bends, everywhere.
void BM_SubdivisionQuality(benchmark::State& state) {
    Data& d = data();
    const codec::MeshScene scene(d.mesh);
    codec::ReferenceOptions options;
    options.samplesPerPixel = 4;
    const Image reference =
        codec::renderMeshReference(scene, Fpc(d.camera, std::make_shared<codec::SamplingMap>(*d.map)), kWidth, kHeight, options);
    const struct {
        const char* name;
        renderers::MeshRenderer& renderer;
        renderers::MeshRenderOptions options;
    } renders[] = {{"none", *d.renderer, asBuilt()}, {"bend", *d.renderer, {}}, {"edge", *d.fineRenderer, asBuilt()}};
    for (auto _ : state)
        for (const auto& r : renders) {
            std::int64_t triangles = 0;
            state.counters[std::string("psnr_") + r.name] =
                codec::psnr(r.renderer.render(d.camera, *d.map, kWidth, kHeight, r.options, nullptr, &triangles), reference);
            state.counters[std::string("triangles_") + r.name] = static_cast<double>(triangles);
        }
    state.SetLabel(d.context->renderer());  // the GL the frame times of this run are read on
}
void BM_EmbreeReference(benchmark::State& state) {
    Data& d = data();
    static const codec::MeshScene scene(d.mesh);
    const Fpc fpc(d.camera, std::make_shared<codec::SamplingMap>(*d.map));
    codec::ReferenceOptions options;
    options.samplesPerPixel = 4;
    for (auto _ : state) benchmark::DoNotOptimize(codec::renderMeshReference(scene, fpc, kWidth, kHeight, options));
    state.counters["rays/s"] =
        benchmark::Counter(4.0 * kWidth * kHeight, benchmark::Counter::kIsIterationInvariantRate);
}

// Per-frame map from N foci spread over the frame, 65 x 65 nodes, on one core.
void fociFrame(benchmark::State& state, codec::FociComposition composition) {
    std::vector<codec::Focus> foci;
    for (int i = 0; i < state.range(0); ++i)
        foci.push_back({0.1 + 0.8 * ((i * 37) % 8) / 7.0, 0.15 + 0.7 * ((i * 5) % 8) / 7.0, 0.06, 4.0});
    codec::FociOptions options;
    options.aspect = kAspect;
    options.composition = composition;
    for (auto _ : state) benchmark::DoNotOptimize(codec::frameMap(foci, options));
}
void BM_FociFrameDensity(benchmark::State& state) { fociFrame(state, codec::FociComposition::Density); }
void BM_FociFrameAdd(benchmark::State& state) { fociFrame(state, codec::FociComposition::Add); }

BENCHMARK(BM_GpuConventional)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_GpuConus)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_GpuConusSubdivided)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_GpuConusBend)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_GpuDrawOnly)->Arg(0)->Arg(1)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_GpuConusOverConventionalPaired)->Arg(0)->Arg(1)->Iterations(41)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_GpuBendOverAsBuiltPaired)->Iterations(41)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Subdivide)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SubdivisionQuality)->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_EmbreeReference)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FociFrameDensity)->Arg(1)->Arg(2)->Arg(8)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FociFrameAdd)->Arg(1)->Arg(2)->Arg(8)->Unit(benchmark::kMillisecond);

}  // namespace
