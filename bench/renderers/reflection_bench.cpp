// Reflections (paper section 5, Figure 6): a sphere mirror reflecting a box above a floor, the
// reflected rays intersecting six cube faces baked from the sphere's centre, CoNUS (a focus on the
// box) against conventional faces of the same texel count. BM_ReflectionQuality reports the PSNR
// of both against the ground truth (the reflected rays traced against the mesh with Embree) in the
// region of interest (reflector pixels showing the box) and over the rest of the reflector, and
// writes bench/img/reflection.png (CoNUS | conventional | truth) when CONUS_BENCH_PICTURE names a
// path. BM_ReflectionFrame times the CPU frame with either set of faces (the ratio is the cost);
// BM_ReflectionFrameGl the GLSL frame (renderers::ReflectionRenderer::draw: the scene behind, its upload
// and the reflection pass) on the context CONUS_BACKEND names (default auto).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>

#include "conus/codec/depth/reflection.h"
#include "conus/imageio/image_file.h"
#include "conus/renderers/reflection.h"
#include "bench_context.h"
#include "box_mesh.h"
#include "reflection_scoring.h"

namespace conus {
namespace {

constexpr int kFace = 48;      // texels a face side: 6 x 48^2 texels for either set
constexpr int kFrame = 192;    // frame side
constexpr std::uint32_t kBoxTriangles = 12;

Mesh boxAndFloor() {
    Mesh m;
    const glm::vec3 lo(0.4f, -0.3f, 1.5f), hi(1.0f, 0.5f, 2.2f);
    bench::addBox(m, lo, hi, bench::rampAcross(lo, hi));
    const glm::vec3 floor(0.6f, 0.6f, 0.55f);
    bench::addQuad(m, {glm::vec3(-4, -1, -4), glm::vec3(-4, -1, 4), glm::vec3(4, -1, 4), glm::vec3(4, -1, -4)},
                   {floor, floor, floor, floor});
    return m;
}

struct Setup {
    codec::MeshScene scene{boxAndFloor()};
    codec::ReflectionFrameOptions options;
    Camera camera = Camera::perspective({-0.8, 0.5, 3.0}, {0.0, 0.0, 0.0}, {0, 1, 0}, 22.0, 1.0, 0.1, 20.0);
    std::vector<codec::ReflectionFace> faces[2];  // 0 conventional, 1 CoNUS
    explicit Setup(double magnification) {
        options.reflector.radius = 0.5;
        codec::ReflectionBakeOptions bake;
        bake.size = kFace;
        bake.magnification = magnification;
        bake.roi = codec::AxisBox{{0.4, -0.3, 1.5}, {1.0, 0.5, 2.2}};
        faces[1] = codec::bakeReflection(scene, bake);
        bake.uniform = true;
        faces[0] = codec::bakeReflection(scene, bake);
    }
};

// The focus's magnification k (bake reflection's default: 4).
Setup& setup(int k) {
    static std::map<int, std::unique_ptr<Setup>> setups;
    auto& s = setups[k];
    if (!s) s = std::make_unique<Setup>(k);
    return *s;
}

void BM_ReflectionFrame(benchmark::State& state) {
    Setup& s = setup(static_cast<int>(codec::ReflectionBakeOptions{}.magnification));
    for (auto _ : state)
        benchmark::DoNotOptimize(codec::renderReflectionFrame(s.scene, &s.faces[state.range(0)], s.options.reflector.centre,
                                                              s.camera, kFrame, kFrame, s.options));
    state.SetLabel(state.range(0) ? "CoNUS" : "conventional");
}

void BM_ReflectionFrameGl(benchmark::State& state) {
    Setup& s = setup(static_cast<int>(codec::ReflectionBakeOptions{}.magnification));
    static std::unique_ptr<renderers::Context> context = bench::createBenchContext();
    renderers::ReflectionRenderer renderer(*context, s.scene.mesh(), s.faces[state.range(0)], s.options);
    renderer.draw(s.camera, kFrame, kFrame);  // compiles the program
    const auto start = std::chrono::steady_clock::now();
    for (auto _ : state) renderer.draw(s.camera, kFrame, kFrame);
    const std::chrono::duration<double> seconds = std::chrono::steady_clock::now() - start;
    state.counters["fps"] = double(state.iterations()) / seconds.count();  // wall clock, not this thread's CPU
    state.SetLabel(std::string(state.range(0) ? "CoNUS, " : "conventional, ") + context->renderer());
}

// Args: the focus's magnification k and the linear-search step in tenths of a CoNUS pixel.
void BM_ReflectionQuality(benchmark::State& state) {
    Setup& s = setup(static_cast<int>(state.range(0)));
    codec::ReflectionFrameOptions options = s.options;
    options.intersect.stepTexels = state.range(1) / 10.0;
    Image frames[2], truth;
    for (auto _ : state) {
        truth = codec::renderReflectionFrame(s.scene, nullptr, options.reflector.centre, s.camera, kFrame, kFrame, options);
        for (int k = 0; k < 2; ++k)
            frames[k] = codec::renderReflectionFrame(s.scene, &s.faces[k], options.reflector.centre, s.camera, kFrame,
                                                     kFrame, options);
    }
    // ROI: reflector pixels whose traced reflected ray meets the box.
    const bench::MirrorScore score = bench::scoreMirror(frames, truth, s.scene, options.reflector, s.camera, kFrame, kBoxTriangles);
    state.counters["roi_conus_dB"] = score.psnr(1, {0});
    state.counters["roi_conventional_dB"] = score.psnr(0, {0});
    state.counters["rest_conus_dB"] = score.psnr(1, {1});
    state.counters["rest_conventional_dB"] = score.psnr(0, {1});
    state.counters["roi_pixels"] = score.count[0];
    state.counters["roi_wrong_conus"] = score.wrong[1][0];
    state.counters["roi_wrong_conventional"] = score.wrong[0][0];
    // What the focus achieves: the +z face's linear sampling rate at the box's centre, against the
    // conventional face's (the map's Jacobian determinant, square-rooted).
    const codec::DepthImage& front = s.faces[1][4].depth;
    const glm::dvec2 centre(front.camera().project(glm::dvec3(0.7, 0.1, 1.85)));
    state.counters["box_rate"] = std::sqrt(std::abs(glm::determinant(front.map().jacobian(centre))));
    const char* picture = std::getenv("CONUS_BENCH_PICTURE");
    if (picture && state.range(0) == static_cast<int>(codec::ReflectionBakeOptions{}.magnification) &&
        state.range(1) == 10) {
        bench::writeMirrorStrip(picture, frames, truth, score, kFrame, 4);
    }
}

BENCHMARK(BM_ReflectionFrame)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ReflectionFrameGl)->Arg(0)->Arg(1)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ReflectionQuality)
    ->Args({3, 10})
    ->Args({4, 10})
    ->Args({5, 10})
    ->Args({4, 5})
    ->Args({4, 20})
    ->Iterations(1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace conus
