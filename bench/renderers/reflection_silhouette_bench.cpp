// Reflections across silhouettes at the defaults a user gets (`bake reflection`: 128-texel faces,
// a focus of k = 4 on the region of interest): a sphere mirror and a square plane mirror, each
// reflecting a colour-ramped box, a thin pole and a wall behind them over a floor, where reflected
// rays pass beside silhouettes with far surfaces behind (the case a single-layer depth image must
// not bridge). BM_ReflectionSilhouettes reports the PSNR over the whole mirror against the traced
// reference (the reflected rays against the mesh, Embree), and inside and outside the region of
// interest (mirror pixels whose traced ray meets the box), for CoNUS faces and uniform faces of the
// same texel count; with CONUS_BENCH_PICTURES set to a prefix it writes <prefix>-sphere.png and
// <prefix>-plane.png (CoNUS | uniform | reference, the box enlarged below).
// BM_ReflectionSilhouetteVariants: the CoNUS - uniform gains over ten variants of the scene.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <string>

#include "conus/codec/depth/reflection.h"
#include "conus/imageio/image_file.h"
#include "box_mesh.h"
#include "reflection_scoring.h"

namespace conus {
namespace {

constexpr int kFrame = 256;
constexpr std::uint32_t kBoxTriangles = 12;
const codec::AxisBox kBox{{0.4, -0.3, 1.5}, {1.0, 0.5, 2.2}};

// The room's wall (its top at y = `top`, its face at z = `wallZ`, its foot on the floor) and floor
// (y = `floorY`, out to z = 4) move in BM_ReflectionSilhouetteVariants; the defaults: the bench's scene.
struct Room {
    float top = 3, floorY = -1, wallZ = 4;
};

Mesh room(const Room& r = {}) {
    Mesh m;
    const glm::vec3 lo(kBox.lo), hi(kBox.hi);
    bench::addBox(m, lo, hi, bench::rampAcross(lo, hi));
    // A pole beside the mirror, 0.08 wide: thin against the wall and the floor behind it.
    bench::addBox(m, {0.9f, -1.0f, 0.5f}, {0.98f, 0.9f, 0.58f}, [](glm::vec3 p) { return glm::vec3(0.85f, 0.3f + 0.3f * p.y, 0.2f); });
    const float f = r.floorY, z = r.wallZ;
    bench::addQuad(m, {glm::vec3(-4, f, -4), glm::vec3(-4, f, 4), glm::vec3(4, f, 4), glm::vec3(4, f, -4)},
            {glm::vec3(0.3f, 0.5f, 0.3f), glm::vec3(0.6f, 0.6f, 0.4f), glm::vec3(0.7f, 0.5f, 0.5f), glm::vec3(0.4f, 0.4f, 0.6f)});
    bench::addQuad(m, {glm::vec3(-4, f, z), glm::vec3(-4, r.top, z), glm::vec3(4, r.top, z), glm::vec3(4, f, z)},
            {glm::vec3(0.2f, 0.3f, 0.7f), glm::vec3(0.8f, 0.8f, 0.9f), glm::vec3(0.9f, 0.7f, 0.3f), glm::vec3(0.3f, 0.6f, 0.3f)});
    return m;
}

struct Scene {
    codec::MeshScene scene;
    Camera camera = Camera::perspective({-0.8, 0.5, 3.0}, {0.0, 0.0, 0.0}, {0, 1, 0}, 22.0, 1.0, 0.1, 20.0);
    std::vector<codec::ReflectionFace> faces[2];  // 0 uniform, 1 CoNUS, both at the defaults
    explicit Scene(const Room& r = {}, int size = codec::ReflectionBakeOptions{}.size) : scene(room(r)) {
        codec::ReflectionBakeOptions bake;
        bake.roi = kBox;
        bake.size = size;
        faces[1] = codec::bakeReflection(scene, bake);
        bake.uniform = true;
        faces[0] = codec::bakeReflection(scene, bake);
    }
};

Scene& scene() {
    static Scene s;
    return s;
}

// Mirror 0: a sphere (radius 0.5), 1: a plane (side 1, facing +z), both at the origin.
codec::ReflectionFrameOptions mirrorOptions(int mirror) {
    codec::ReflectionFrameOptions options;
    options.reflector.radius = 0.5;
    if (mirror == 1) {
        options.reflector.kind = codec::Reflector::Kind::Plane;
        options.reflector.normal = {0.0, 0.0, 1.0};
    }
    return options;
}

// The three frames of `mirror` (uniform, CoNUS, traced) scored: region 0 the box (ROI), 1 the rest
// of the mirror; both: the whole mirror.
bench::MirrorScore scoreScene(const Scene& s, int mirror, Image (&frames)[2], Image& truth) {
    const codec::ReflectionFrameOptions options = mirrorOptions(mirror);
    truth = codec::renderReflectionFrame(s.scene, nullptr, {0, 0, 0}, s.camera, kFrame, kFrame, options);
    for (int k = 0; k < 2; ++k)
        frames[k] = codec::renderReflectionFrame(s.scene, &s.faces[k], {0, 0, 0}, s.camera, kFrame, kFrame, options);
    return bench::scoreMirror(frames, truth, s.scene, options.reflector, s.camera, kFrame, kBoxTriangles);
}

// Arg: the mirror (mirrorOptions).
void BM_ReflectionSilhouettes(benchmark::State& state) {
    Scene& s = scene();
    Image frames[2], truth;
    bench::MirrorScore score;
    for (auto _ : state) score = scoreScene(s, static_cast<int>(state.range(0)), frames, truth);
    bench::addMirrorCounters(state, score, "", "roi");
    state.counters["roi_pixels"] = score.count[0];
    state.counters["mirror_pixels"] = score.count[0] + score.count[1];
    state.counters["wrong_conus"] = score.wrong[1][0] + score.wrong[1][1];
    state.counters["wrong_uniform"] = score.wrong[0][0] + score.wrong[0][1];
    state.SetLabel(state.range(0) ? "plane mirror" : "sphere mirror");
    if (const char* prefix = std::getenv("CONUS_BENCH_PICTURES")) {
        bench::writeMirrorStrip(std::string(prefix) + (state.range(0) ? "-plane.png" : "-sphere.png"), frames, truth, score, kFrame, 3);
    }
}

BENCHMARK(BM_ReflectionSilhouettes)->Arg(0)->Arg(1)->Iterations(1)->Unit(benchmark::kMillisecond);

// A handful of outline pixels moves one scene's figures by tenths of a dB, so the same figures over
// ten variants of the scene (the defaults; faces of 120, 127 and 136 texels; the wall's top at 2.9
// and 3.1; the floor at -1.03; the wall at z = 3.9 and 4.1; the last three together): per mirror,
// the mean and the lowest of CoNUS - uniform in the ROI and in the rest, in dB.
void BM_ReflectionSilhouetteVariants(benchmark::State& state) {
    struct Variant {
        Room room;
        int size = 128;
    };
    const Variant variants[] = {{{}, 128},
                                {{}, 120},
                                {{}, 127},
                                {{}, 136},
                                {{2.9f, -1, 4}, 128},
                                {{3.1f, -1, 4}, 128},
                                {{3, -1.03f, 4}, 128},
                                {{3, -1, 3.9f}, 128},
                                {{3, -1, 4.1f}, 128},
                                {{3.1f, -1.03f, 4.1f}, 128}};
    // [mirror][0 ROI, 1 rest], of the last iteration
    double sum[2][2] = {}, lowest[2][2] = {};
    for (auto _ : state) {
        for (auto& m : sum) m[0] = m[1] = 0.0;
        for (auto& m : lowest) m[0] = m[1] = 1e9;
        for (const Variant& v : variants) {
            const Scene s(v.room, v.size);
            for (int mirror = 0; mirror < 2; ++mirror) {
                Image frames[2], truth;
                const bench::MirrorScore score = scoreScene(s, mirror, frames, truth);
                for (int region = 0; region < 2; ++region) {
                    const double gain = score.psnr(1, {region}) - score.psnr(0, {region});
                    sum[mirror][region] += gain;
                    lowest[mirror][region] = std::min(lowest[mirror][region], gain);
                }
            }
        }
    }
    const char* names[2] = {"sphere", "plane"};
    const char* regions[2] = {"roi", "rest"};
    for (int mirror = 0; mirror < 2; ++mirror)
        for (int region = 0; region < 2; ++region) {
            const std::string name = std::string(names[mirror]) + "_" + regions[region];
            state.counters[name + "_gain_mean_dB"] = sum[mirror][region] / std::size(variants);
            state.counters[name + "_gain_lowest_dB"] = lowest[mirror][region];
        }
    state.counters["variants"] = static_cast<double>(std::size(variants));
}

BENCHMARK(BM_ReflectionSilhouetteVariants)->Iterations(1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace conus
