// CoNUS height fields at 1k x 1k (paper section 4: "rendered at over 400 and used at over 100
// frames per second" on 2010 hardware): the server's encode, the client's undistort-to-mesh and its
// frames per second on the GL backend of CONUS_BACKEND (default auto), each next to the uniform
// height field of the same size as the baseline. The DEM is the 2k x 2k procedural terrain.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <memory>

#include "bench_context.h"
#include "conus/codec/depth/heightfield.h"
#include "conus/renderers/terrain.h"

namespace {

using namespace conus;

constexpr int kDem = 2048, kSamples = 1024, kFrameWidth = 1280, kFrameHeight = 720;
const codec::GroundParams kGround{150.0, 200.0, 6000.0, 60.0};

struct Data {
    Image dem, colour;
    format::ConusFile conus, uniform;
    Mesh conusMesh, uniformMesh;
    std::unique_ptr<renderers::Context> context;
};

Data& data() {
    static Data* d = [] {
        auto* d = new Data;
        codec::TerrainOptions options;
        options.width = options.height = kDem;
        d->dem = codec::generateTerrain(options);
        const glm::dvec2 extent = codec::fieldExtent(kGround);
        d->colour = codec::terrainColours(d->dem, extent);
        codec::HeightFieldOptions encode;
        encode.ground = kGround;
        encode.width = encode.height = kSamples;
        d->conus = codec::encodeHeightField(d->dem, d->colour, encode);
        d->uniform = codec::uniformHeightField(d->dem, d->colour, kSamples, kSamples);
        d->conusMesh = codec::undistortHeightField(d->conus);
        d->uniformMesh = codec::undistortHeightField(d->uniform, extent);
        d->context = bench::createBenchContext();
        return d;
    }();
    return *d;
}

void BM_EncodeConus(benchmark::State& state) {
    Data& d = data();
    codec::HeightFieldOptions encode;
    encode.ground = kGround;
    encode.width = encode.height = kSamples;
    for (auto _ : state) benchmark::DoNotOptimize(codec::encodeHeightField(d.dem, d.colour, encode));
}
void BM_EncodeUniform(benchmark::State& state) {
    Data& d = data();
    for (auto _ : state) benchmark::DoNotOptimize(codec::uniformHeightField(d.dem, d.colour, kSamples, kSamples));
}
void BM_UndistortConus(benchmark::State& state) {
    Data& d = data();
    for (auto _ : state) benchmark::DoNotOptimize(codec::undistortHeightField(d.conus));
}
void BM_UndistortUniform(benchmark::State& state) {
    Data& d = data();
    const glm::dvec2 extent = codec::fieldExtent(kGround);
    for (auto _ : state) benchmark::DoNotOptimize(codec::undistortHeightField(d.uniform, extent));
}
void renderFrames(benchmark::State& state, const Mesh& mesh) {
    Data& d = data();
    renderers::TerrainRenderer renderer(*d.context, mesh);
    const Camera camera = renderers::viewerCamera(kGround, d.dem.at(kDem / 2, kDem - 1), double(kFrameWidth) / kFrameHeight);
    for (auto _ : state) benchmark::DoNotOptimize(renderer.render(camera, kFrameWidth, kFrameHeight));
    state.counters["frames/s"] = benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
    state.SetLabel(d.context->renderer());
}
void BM_RenderConus(benchmark::State& state) { renderFrames(state, data().conusMesh); }
void BM_RenderUniform(benchmark::State& state) { renderFrames(state, data().uniformMesh); }

BENCHMARK(BM_EncodeConus)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_EncodeUniform)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_UndistortConus)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_UndistortUniform)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_RenderConus)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_RenderUniform)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
