// The Embree mesh reference, CoNUS against conventional, read off one run:
//   BM_MeshReferenceConus / BM_MeshReferenceUniform: the procedural city (16 blocks, 6 cars) at
//   480x320, one ray a pixel, through a two-focus FPC (foci on two cars) vs the identity FPC. The
//   difference is the exact inverse of Eq. 1 per pixel (and where the rays go).
//   BM_SubdivideCity: the city split until no projected edge spans more than half a cell of a
//   65x65 map (what the GPU encoder's offline step costs), with the triangle count as a counter.
// Counters: rays/s for the renders.
#include <benchmark/benchmark.h>

#include <memory>
#include <vector>

#include "conus/codec/builders/foci.h"
#include "conus/codec/mesh/city.h"
#include "conus/codec/mesh/raycast.h"
#include "conus/codec/mesh/subdivide.h"

namespace {

using namespace conus;
using namespace conus::codec;

constexpr int kWidth = 480, kHeight = 320;
constexpr double kTime = 2.0;

const CityScene& city() {
    static const CityScene scene;
    return scene;
}
const MeshScene& cityScene() {
    static const MeshScene scene(city().meshAt(kTime));
    return scene;
}
const Camera& camera() {
    static const Camera c = Camera::perspective({-160, 120, 190}, {0, 0, 0}, {0, 1, 0}, 45, double(kWidth) / kHeight, 1, 1000);
    return c;
}
std::shared_ptr<const SamplingMap> carFoci() {
    static const std::shared_ptr<const SamplingMap> map = [] {
        std::vector<Focus> foci;
        for (int car = 0; car < 2; ++car) {
            const glm::dvec3 p = camera().project(city().carCentre(car, kTime));
            foci.push_back({std::clamp(p.x, 0.05, 0.95), std::clamp(p.y, 0.05, 0.95), 0.06, 4});
        }
        FociOptions options;
        options.aspect = double(kWidth) / kHeight;
        return std::make_shared<SamplingMap>(buildFociMap(foci, options));
    }();
    return map;
}

void render(benchmark::State& state, const Fpc& fpc) {
    ReferenceOptions options;
    options.threads = 1;  // one core: the machine is shared, and ratios want the same setting
    for (auto _ : state) benchmark::DoNotOptimize(renderMeshReference(cityScene(), fpc, kWidth, kHeight, options));
    state.counters["rays/s"] = benchmark::Counter(double(kWidth) * kHeight, benchmark::Counter::kIsIterationInvariantRate);
}

void BM_MeshReferenceUniform(benchmark::State& state) { render(state, Fpc(camera(), nullptr)); }
void BM_MeshReferenceConus(benchmark::State& state) {
    const Fpc fpc(camera(), carFoci());
    fpc.distortion()->undistort({0.5, 0.5});  // the inverse's index is built once, outside the timing
    render(state, fpc);
}
BENCHMARK(BM_MeshReferenceUniform)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MeshReferenceConus)->Unit(benchmark::kMillisecond);

void BM_SubdivideCity(benchmark::State& state) {
    const Mesh mesh = city().meshAt(kTime);
    const SamplingMap& map = *carFoci();
    std::size_t triangles = 0;
    for (auto _ : state) triangles = subdivideForMap(mesh, camera(), map, 0.5).triangleCount();
    state.counters["triangles"] = double(triangles);
    state.counters["input"] = double(mesh.triangleCount());
}
BENCHMARK(BM_SubdivideCity)->Unit(benchmark::kMillisecond);

}  // namespace
