// Layered reflection assets on real models: a plane mirror (half side 4) and a sphere mirror
// (radius 4) beside the Utah teapot (shared/data/meshes/teapot.obj; /2 and /3: beside Cesium's
// milk truck from Debian's assimp-testmodels, the same set-up), each asset centred on its
// mirror, 128-texel faces, the region of interest the model, the camera seeing the mirror at an
// angle. BM_LayeredReflectionQuality scores single-layer and layered assets, CoNUS and uniform,
// against the traced reference (the reflected rays traced against the mesh, Embree) over the mirror
// and the teapot's reflection, reports the asset bytes and the bake's disocclusion fractions, and
// writes CONUS_BENCH_PICTURES-<mirror>.png (CoNUS 1 layer | CoNUS layered | reference; below, 3x)
// when that variable names a path prefix. The "placed_" figures are the layered asset baked from
// the eye placeReflectionEye picks for the camera (CONUS_BENCH_PICTURES-placed-<mirror>.png: CoNUS
// layered from the centre | from the placed eye | reference; each asset scored against the
// reference shaded from its own eye); "moved_" the layered CoNUS assets seen from kMovedEye, a
// viewpoint the eye was not placed for. BM_LayeredReflectionPaired times single-layer and
// layered CoNUS frames in interleaved pairs, on the CPU (/0) and through GLSL (/1, the context
// CONUS_BACKEND names, default auto). BM_PlacedMirrorFocus scores the asset baked from the placed
// eye by face size and magnification, also on antialiased frames (CONUS_BENCH_SUPERSAMPLE).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>

#include "conus/codec/depth/reflection.h"
#include "conus/format/reflection_asset.h"
#include "conus/renderers/reflection.h"
#include "conus/sceneio/mesh_file.h"
#include "bench_context.h"
#include "paired.h"
#include "reflection_scoring.h"

namespace conus {
namespace {

constexpr int kFace = 128;
constexpr int kFrame = 256;

struct Setup {
    codec::MeshScene scene;
    codec::ReflectionFrameOptions options;
    Camera camera;
    double fov = 40;
    // [uniform 0 / CoNUS 1][single 0 / layered 1 / layered from the placed eye 2]
    std::vector<codec::ReflectionFace> faces[2][3];
    double bytes[2][3] = {};
    double disoccluded[2] = {};  // single, layered
    codec::EyePlacement placed{};  // the faces' eye placed for the camera (placeReflectionEye)
};

// The camera moved away from the one the eye was placed for: what the placed asset shows a viewer
// elsewhere.
const glm::dvec3 kMovedEye(2.5, 2.0, 6.5);

// The models: the Utah teapot, Cesium's milk truck (a textured glTF from Debian's
// assimp-testmodels, a model the project was not tuned on) and assimp-testmodels' spider (a
// textured OBJ, held out: never looked at while the bake was tuned).
constexpr int kModelCount = 3;
const std::string kModels[kModelCount] = {std::string(CONUS_SHARED_DATA) + "/meshes/teapot.obj",
                                          "/usr/share/assimp/models/glTF/CesiumMilkTruck/CesiumMilkTruck.gltf",
                                          "/usr/share/assimp/models/OBJ/spider.obj"};

// Model `m` as the mirrors see it. The teapot and the truck stand as they are (about 5 units
// long, on the ground, about the origin); the spider, 193 units long about (-17, -2, -10), is
// brought to the same: its longer ground side 5 units, centred over the origin, on the ground.
Mesh readModel(int m) {
    Mesh mesh = sceneio::readMesh(kModels[m]);
    if (m < 2) return mesh;
    const AxisBox b = boundsOf(mesh);
    const glm::dvec3 size = b.hi - b.lo;
    const double scale = 5.0 / std::max(size.x, size.z);
    const glm::dvec3 base(0.5 * (b.lo.x + b.hi.x), b.lo.y, 0.5 * (b.lo.z + b.hi.z));
    for (glm::vec3& p : mesh.positions) p = glm::vec3((glm::dvec3(p) - base) * scale);
    return mesh;
}

// The mirror of a setup (even index: the plane mirror, odd: the sphere), and the camera's field of
// view on it; the camera stands at (6, 3.5, 4) looking at the mirror's centre.
codec::Reflector mirrorOf(int index) {
    codec::Reflector r;
    const bool plane = index % 2 == 0;
    r.kind = plane ? codec::Reflector::Kind::Plane : codec::Reflector::Kind::Sphere;
    r.centre = plane ? glm::dvec3(0.0, 1.5, -6.0) : glm::dvec3(0.0, 1.5, -7.0);
    r.radius = 4.0;
    r.normal = glm::normalize(glm::dvec3(0.15, 0.0, 1.0));
    return r;
}
double fovOf(int index) { return index % 2 == 0 ? 38.0 : 45.0; }
Camera cameraOn(const codec::Reflector& r, double fov) {
    return Camera::perspective({6.0, 3.5, 4.0}, r.centre, {0, 1, 0}, fov, 1.0, 1e-3, 1e3);
}

// The bytes of the reflection asset file of `faces`.
double assetBytes(const std::vector<codec::ReflectionFace>& faces) {
    const std::string path = (std::filesystem::temp_directory_path() / "conus-layered-bench.exr").string();
    format::writeReflectionAsset(path, codec::reflectionAssetFile(faces));
    const auto bytes = static_cast<double>(std::filesystem::file_size(path));
    std::filesystem::remove(path);
    return bytes;
}

// Setup 0: the plane mirror, 1: the sphere, beside the teapot; 2 and 3 beside the truck; 4 and 5 beside the spider.
// Null when the model is not installed.
Setup* setup(int index) {
    static std::unique_ptr<Setup> setups[2 * kModelCount];
    auto& s = setups[index];
    if (s) return s.get();
    if (!std::filesystem::exists(kModels[index / 2])) return nullptr;
    s = std::make_unique<Setup>(Setup{codec::MeshScene(readModel(index / 2)), {},
                                      Camera::perspective({0, 0, 1}, {0, 0, 0}, {0, 1, 0}, 40, 1, 0.1, 10), 40.0, {}});
    codec::Reflector& r = s->options.reflector;
    r = mirrorOf(index);
    s->fov = fovOf(index);
    s->camera = cameraOn(r, s->fov);
    const AxisBox bounds = boundsOf(s->scene.mesh());
    for (int uniform = 0; uniform < 2; ++uniform)
        for (int layered = 0; layered < 3; ++layered) {
            if (layered == 2 && uniform == 0)  // placed once, as `bake reflection --view` places it for --layers auto
                s->placed = codec::placeReflectionEye(s->scene, r, s->camera.eye(), 0);
            codec::ReflectionBakeOptions bake;
            bake.centre = layered == 2 ? s->placed.eye : r.centre;
            bake.size = kFace;
            bake.uniform = uniform == 0;
            bake.roi = bounds;
            bake.layers = layered == 2 ? s->placed.layers : layered ? 0 : 1;
            auto& faces = s->faces[uniform][layered];
            faces = codec::bakeReflection(s->scene, bake);
            s->bytes[uniform][layered] = assetBytes(faces);
        }
    const int layers = s->faces[1][1].front().layers();
    s->disoccluded[0] = codec::disocclusionFraction(s->scene, r.centre, r.radius, 1);
    s->disoccluded[1] = codec::disocclusionFraction(s->scene, r.centre, r.radius, layers);
    return s.get();
}

// The setup of the row's range(0), or null when its model is not installed (the row then skips).
Setup* setupOrSkip(benchmark::State& state) {
    Setup* found = setup(static_cast<int>(state.range(0)));
    if (!found) state.SkipWithError("the model is not installed (assimp-testmodels)");
    return found;
}

void BM_LayeredReflectionQuality(benchmark::State& state) {
    Setup* found = setupOrSkip(state);
    if (!found) return;
    Setup& s = *found;
    // The reference shades with the headlight at the faces' eye, as the asset does: the placed
    // asset has its own (traced rays land on the same surfaces; only the shading moves).
    Image truth[2], frames[2][3];
    const Camera moved = Camera::perspective(kMovedEye, s.options.reflector.centre, {0, 1, 0}, s.fov, 1.0, 1e-3, 1e3);
    Image movedTruth[2], movedFrames[2];
    for (auto _ : state) {
        for (int l = 0; l < 3; ++l) {
            const glm::dvec3 eye = s.faces[1][l].front().depth.camera().eye();
            if (l != 1) truth[l / 2] = codec::renderReflectionFrame(s.scene, nullptr, eye, s.camera, kFrame, kFrame, s.options);
            for (int u = 0; u < 2; ++u)
                frames[u][l] = codec::renderReflectionFrame(s.scene, &s.faces[u][l], eye, s.camera, kFrame, kFrame, s.options);
        }
        for (int p = 0; p < 2; ++p) {  // the layered asset from the centre, from the placed eye
            const glm::dvec3 eye = s.faces[1][p + 1].front().depth.camera().eye();
            movedTruth[p] = codec::renderReflectionFrame(s.scene, nullptr, eye, moved, kFrame, kFrame, s.options);
            movedFrames[p] = codec::renderReflectionFrame(s.scene, &s.faces[1][p + 1], eye, moved, kFrame, kFrame, s.options);
        }
    }
    const auto triangles = static_cast<std::uint32_t>(s.scene.mesh().indices.size() / 3);
    for (int l = 0; l < 3; ++l) {
        const Image pair[2] = {frames[0][l], frames[1][l]};
        const bench::MirrorScore score =
            bench::scoreMirror(pair, truth[l == 2 ? 1 : 0], s.scene, s.options.reflector, s.camera, kFrame, triangles);
        const char* tags[3] = {"single_", "layered_", "placed_"};
        const std::string tag = tags[l];
        bench::addMirrorCounters(state, score, tag, "teapot");
        state.counters[tag + "wrong_conus"] = score.wrong[1][0] + score.wrong[1][1];
    }
    state.counters["layers"] = s.faces[1][1].front().layers();
    for (int p = 0; p < 2; ++p) {
        const Image pair[2] = {movedFrames[p], movedFrames[p]};
        const bench::MirrorScore score = bench::scoreMirror(pair, movedTruth[p], s.scene, s.options.reflector, moved, kFrame, triangles);
        state.counters[std::string(p ? "moved_placed" : "moved_layered") + "_mirror_conus_dB"] = score.psnr(1, {0, 1});
    }
    state.counters["placed_layers"] = s.faces[1][2].front().layers();
    state.counters["placed_disoccluded_pct"] = 100.0 * s.placed.disoccluded;
    state.counters["centre_disoccluded_pct"] = 100.0 * s.placed.centreDisoccluded;
    state.counters["placed_eye_x"] = s.placed.eye.x;
    state.counters["placed_eye_z"] = s.placed.eye.z;
    state.counters["bytes_ratio_conus"] = s.bytes[1][1] / s.bytes[1][0];
    state.counters["bytes_ratio_uniform"] = s.bytes[0][1] / s.bytes[0][0];
    state.counters["bytes_ratio_placed"] = s.bytes[1][2] / s.bytes[1][0];
    state.counters["bytes_single_conus"] = s.bytes[1][0];
    state.counters["disoccluded_single_pct"] = 100.0 * s.disoccluded[0];
    state.counters["disoccluded_layered_pct"] = 100.0 * s.disoccluded[1];
    if (const char* prefix = std::getenv("CONUS_BENCH_PICTURES")) {
        // CoNUS single | CoNUS layered | reference (writeMirrorStrip's order: frames[1], frames[0], truth).
        const Image pair[2] = {frames[1][1], frames[1][0]};
        const bench::MirrorScore score = bench::scoreMirror(pair, truth[0], s.scene, s.options.reflector, s.camera, kFrame, triangles);
        const char* names[2 * kModelCount] = {"-plane.png", "-sphere.png", "-truck-plane.png", "-truck-sphere.png",
                                              "-spider-plane.png", "-spider-sphere.png"};
        bench::writeMirrorStrip(std::string(prefix) + names[state.range(0)], pair, truth[0], score, kFrame, 3);
        // CoNUS layered from the centre | from the placed eye | the reference shaded from the placed eye.
        const Image placed[2] = {frames[1][2], frames[1][1]};
        const bench::MirrorScore placedScore =
            bench::scoreMirror(placed, truth[1], s.scene, s.options.reflector, s.camera, kFrame, triangles);
        bench::writeMirrorStrip(std::string(prefix) + "-placed" + names[state.range(0)], placed, truth[1], placedScore, kFrame, 3);
    }
}

// The eye at candidate k of placeReflectionEye's (k/4 of the way from the mirror's centre to the
// reflected viewpoint; range(1)), one layer, faces of range(2) texels: the rays toward the camera that land in a
// disocclusion there and the mirror's dB against the reference shaded from that eye.
void BM_LayeredReflectionEyeSweep(benchmark::State& state) {
    Setup* found = setupOrSkip(state);
    if (!found) return;
    Setup& s = *found;
    const codec::Reflector& r = s.options.reflector;
    const glm::dvec3 image = codec::reflectedViewpoint(r, s.camera.eye());
    const glm::dvec3 eye = r.centre + (image - r.centre) * (double(state.range(1)) / (codec::kEyeCandidates - 1));
    codec::ReflectionBakeOptions bake;
    bake.centre = eye;
    bake.size = static_cast<int>(state.range(2));
    bake.roi = boundsOf(s.scene.mesh());
    Image frames[2], truth;
    double bytes = 0;
    for (auto _ : state) {
        for (int u = 0; u < 2; ++u) {
            bake.uniform = u == 0;
            const auto faces = codec::bakeReflection(s.scene, bake);
            frames[u] = codec::renderReflectionFrame(s.scene, &faces, eye, s.camera, kFrame, kFrame, s.options);
            if (u == 1) bytes = assetBytes(faces);
        }
        truth = codec::renderReflectionFrame(s.scene, nullptr, eye, s.camera, kFrame, kFrame, s.options);
    }
    const auto triangles = static_cast<std::uint32_t>(s.scene.mesh().indices.size() / 3);
    const bench::MirrorScore score = bench::scoreMirror(frames, truth, s.scene, r, s.camera, kFrame, triangles);
    state.counters["mirror_conus_dB"] = score.psnr(1, {0, 1});
    state.counters["mirror_uniform_dB"] = score.psnr(0, {0, 1});
    state.counters["model_conus_dB"] = score.psnr(1, {0});
    state.counters["bytes_ratio"] = bytes / s.bytes[1][0];
    state.counters["disoccluded_pct"] = 100.0 * codec::disocclusionFraction(s.scene, eye, codec::reflectedRays(r, s.camera.eye(), codec::kViewRays), 1);
}

// The eye placed as placeReflectionEye places it for the camera (one layer), one layer, faces of range(2) texels, the focus's
// magnification range(1): the mirror, the model's reflection and the rest, CoNUS and uniform, and
// the CoNUS asset's bytes against the centred single-layer CoNUS asset of 128-texel faces. With
// CONUS_BENCH_SUPERSAMPLE set, "ss_" scores the frames (reference and assets alike) rendered with
// 3x3 rays a pixel, box-filtered (ReflectionFrameOptions::samples), "aaref_" the one-ray asset frames
// against that reference, and "truth1spp_" the one-ray reference against it.
void BM_PlacedMirrorFocus(benchmark::State& state) {
    const int index = static_cast<int>(state.range(0));
    if (!std::filesystem::exists(kModels[index / 2])) {
        state.SkipWithError("the model is not installed (assimp-testmodels)");
        return;
    }
    static std::unique_ptr<codec::MeshScene> scenes[kModelCount];
    if (!scenes[index / 2]) scenes[index / 2] = std::make_unique<codec::MeshScene>(readModel(index / 2));
    const codec::MeshScene& scene = *scenes[index / 2];
    codec::ReflectionFrameOptions options;
    codec::Reflector& r = options.reflector;
    r = mirrorOf(index);
    const Camera camera = cameraOn(r, fovOf(index));
    const glm::dvec3 eye = codec::placeReflectionEye(scene, r, camera.eye(), 1).eye;
    codec::ReflectionBakeOptions bake;
    bake.centre = eye;
    bake.size = static_cast<int>(state.range(2));
    bake.roi = boundsOf(scene.mesh());
    bake.magnification = static_cast<double>(state.range(1));
    Image frames[2], truth;
    double bytes = 0;
    for (auto _ : state) {
        for (int u = 0; u < 2; ++u) {
            bake.uniform = u == 0;
            const auto faces = codec::bakeReflection(scene, bake);
            frames[u] = codec::renderReflectionFrame(scene, &faces, eye, camera, kFrame, kFrame, options);
            if (u == 1) bytes = assetBytes(faces);
        }
        truth = codec::renderReflectionFrame(scene, nullptr, eye, camera, kFrame, kFrame, options);
    }
    codec::ReflectionBakeOptions centred;  // the centred single-layer CoNUS asset of 128-texel faces
    centred.centre = r.centre;
    centred.size = kFace;
    centred.roi = bake.roi;
    state.counters["bytes_ratio"] = bytes / assetBytes(codec::bakeReflection(scene, centred));
    state.counters["eye_x"] = eye.x;
    state.counters["eye_z"] = eye.z;
    const auto triangles = static_cast<std::uint32_t>(scene.mesh().indices.size() / 3);
    const bench::MirrorScore score = bench::scoreMirror(frames, truth, scene, r, camera, kFrame, triangles);
    if (std::getenv("CONUS_BENCH_SUPERSAMPLE")) {  // 3x3 rays a frame pixel, box-filtered
        codec::ReflectionFrameOptions ssOptions = options;
        ssOptions.samples = 3;
        const Image ssTruth = codec::renderReflectionFrame(scene, nullptr, eye, camera, kFrame, kFrame, ssOptions);
        Image ss[2];
        for (int u = 0; u < 2; ++u) {
            bake.uniform = u == 0;
            const auto faces = codec::bakeReflection(scene, bake);
            ss[u] = codec::renderReflectionFrame(scene, &faces, eye, camera, kFrame, kFrame, ssOptions);
        }
        const bench::MirrorScore s2 = bench::scoreMirror(ss, ssTruth, scene, r, camera, kFrame, triangles);
        const Image alias[2] = {truth, truth};
        const bench::MirrorScore s3 = bench::scoreMirror(alias, ssTruth, scene, r, camera, kFrame, triangles);
        // The one-ray asset frames (what the GLSL renderer draws) against the antialiased reference.
        const bench::MirrorScore s4 = bench::scoreMirror(frames, ssTruth, scene, r, camera, kFrame, triangles);
        bench::addMirrorCounters(state, s4, "aaref_", "model");
        bench::addMirrorCounters(state, s2, "ss_", "model");
        state.counters["truth1spp_mirror_dB"] = s3.psnr(1, {0, 1});
        state.counters["truth1spp_model_dB"] = s3.psnr(1, {0});
    }
    bench::addMirrorCounters(state, score, "", "model");
    if (const char* prefix = std::getenv("CONUS_BENCH_PICTURES"))
        bench::writeMirrorStrip(std::string(prefix) + "-focus-" + std::to_string(index) + "-" +
                                    std::to_string(state.range(1)) + "-" + std::to_string(state.range(2)) + ".png", frames, truth, score, kFrame, 3);
}

// Single-layer (A) against layered (B) CoNUS frames: /x/0 the CPU reference, /x/1 GLSL; /x/x/1 the
// layered asset from the placed eye as B.
void BM_LayeredReflectionPaired(benchmark::State& state) {
    Setup* found = setupOrSkip(state);
    if (!found) return;
    Setup& s = *found;
    const int b = state.range(2) ? 2 : 1;
    const auto ms = [](auto&& render) {
        const auto start = std::chrono::steady_clock::now();
        render();
        return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    };
    if (state.range(1) == 0) {
        const auto frame = [&](int l) {
            return ms([&] {
                benchmark::DoNotOptimize(codec::renderReflectionFrame(s.scene, &s.faces[1][l], s.options.reflector.centre,
                                                                      s.camera, kFrame, kFrame, s.options));
            });
        };
        bench::pairedRatio(state, [&] { return frame(0); }, [&] { return frame(b); });
        return;
    }
    static std::unique_ptr<renderers::Context> context = bench::createBenchContext();
    renderers::ReflectionRenderer single(*context, s.scene.mesh(), s.faces[1][0], s.options);
    renderers::ReflectionRenderer layered(*context, s.scene.mesh(), s.faces[1][b], s.options);
    single.draw(s.camera, kFrame, kFrame);  // compiles the program
    layered.draw(s.camera, kFrame, kFrame);
    bench::pairedRatio(state, [&] { return ms([&] { single.draw(s.camera, kFrame, kFrame); }); },
                       [&] { return ms([&] { layered.draw(s.camera, kFrame, kFrame); }); });
    state.SetLabel(context->renderer());
}

BENCHMARK(BM_LayeredReflectionQuality)->DenseRange(0, 2 * kModelCount - 1)->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LayeredReflectionEyeSweep)->ArgsProduct({{0, 2}, {0, 1, 2, 3, 4}, {kFace}})->Args({0, 4, 160})->Args({2, 4, 160})
    ->Args({0, 4, 192})->Args({2, 4, 192})->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PlacedMirrorFocus)->ArgsProduct({{0, 1, 2, 3, 4, 5}, {4}, {kFace, 160}})->Args({2, 8, kFace})->Args({2, 16, kFace})
    ->Args({2, 4, 256})->Args({2, 4, 512})->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LayeredReflectionPaired)->ArgsProduct({{0, 1}, {0, 1}, {0, 1}})->Iterations(21)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace conus
