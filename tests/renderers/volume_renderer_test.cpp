// The GPU volume ray caster against codec's CPU reference: PSNR >= 40 dB (R, G, B, A) on every
// test volume (the real MRI scan, Marschner-Lobb, the Shepp-Logan phantom, a random asymmetric
// brick), through identity and focus FPCs, on both GL backends; Z agrees to a step on nearly every
// pixel; a renderer reused across transfer functions gives what a fresh one does.
#include "conus/renderers/volume_renderer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <random>
#include <string>

#include "conus/codec/builders/foci.h"
#include "conus/codec/image/metrics.h"
#include "conus/codec/volume/procedural.h"
#include "conus/sceneio/volume_file.h"
#include "gl_test_util.h"

namespace conus::renderers {
namespace {

using test::contextFor;

Image colourOf(const Image& image) {
    Image out = makeImage(image.width, image.height, {"R", "G", "B", "A"});
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x)
            for (int c = 0; c < 4; ++c) out.at(x, y, c) = image.at(x, y, c);
    return out;
}

// Random values smoothed a little along x only (asymmetric), on an anisotropic grid.
Volume randomBrick() {
    Volume v;
    v.width = 37;
    v.height = 23;
    v.depth = 29;
    v.spacing = {1.0, 1.3, 0.8};
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> d(0.0f, 100.0f);
    v.values.resize(std::size_t(37) * 23 * 29);
    for (float& value : v.values) value = d(rng);
    for (int z = 0; z < v.depth; ++z)
        for (int y = 0; y < v.height; ++y)
            for (int x = 1; x < v.width; ++x)
                v.values[v.index(x, y, z)] = 0.5f * (v.values[v.index(x, y, z)] + v.values[v.index(x - 1, y, z)]);
    return v;
}

struct Case {
    std::string name;
    Volume volume;
    std::string tf;
};

std::vector<Case> testVolumes() {
    std::vector<Case> cases;
    const std::string brain = std::string(CONUS_SHARED_DATA) + "/volumes/brainsmall.den";
    if (std::filesystem::exists(brain)) cases.push_back({"brainsmall", sceneio::readVolume(brain), "bone"});
    else std::printf("[ skipped ] the shared MRI scan (shared data not found: %s); the procedural volumes only\n", brain.c_str());
    cases.push_back({"marschner-lobb", codec::marschnerLobb(41), "shells"});
    cases.push_back({"shepp-logan", codec::sheppLogan3d(64), "bone"});
    cases.push_back({"random", randomBrick(), "fire"});
    return cases;
}

class VolumeGpu : public ::testing::TestWithParam<Backend> {
protected:
    Context& context() { return contextFor(GetParam()); }
};

void expectAgreement(const Image& gpu, const Image& cpu, const std::string& what, float step) {
    const double p = codec::psnr(colourOf(gpu), colourOf(cpu));
    std::printf("%s: GPU vs CPU %.1f dB\n", what.c_str(), p);
    EXPECT_GE(p, 40.0) << what;
    int close = 0;
    double covered = 0;
    for (int y = 0; y < cpu.height; ++y)
        for (int x = 0; x < cpu.width; ++x) {
            close += std::abs(gpu.at(x, y, 4) - cpu.at(x, y, 4)) <= step * 1.01f;
            covered += cpu.at(x, y, 3);
        }
    EXPECT_GE(close, int(0.99 * cpu.width * cpu.height)) << what;
    EXPECT_GT(covered, 0.05 * cpu.width * cpu.height) << what << ": the volume should fill part of the frame";
}

TEST_P(VolumeGpu, MatchesTheCpuReferenceOnEveryTestVolume) {
    for (const Case& c : testVolumes()) {
        const codec::TransferFunction tf = codec::TransferFunction::preset(c.tf);
        const int w = 96, h = 72;
        const Camera camera = codec::defaultVolumeCamera(c.volume, double(w) / h);
        const auto map = std::make_shared<codec::SamplingMap>(
            codec::buildFociMap(std::vector<codec::Focus>{{0.45, 0.5, 0.12, 4.0}, {0.7, 0.3, 0.08, 3.0}},
                                {.aspect = double(w) / h}));
        VolumeRendererGpu renderer(context(), c.volume, tf);
        codec::VolumeRenderOptions options;
        const float step = float(options.stepVoxels * std::min({c.volume.spacing.x, c.volume.spacing.y, c.volume.spacing.z}));
        for (const std::shared_ptr<const Distortion>& d : {std::shared_ptr<const Distortion>(), std::shared_ptr<const Distortion>(map)}) {
            const Fpc fpc(camera, d);
            const Image gpu = renderer.render(fpc, w, h, options);
            const Image cpu = codec::renderVolumeReference(c.volume, tf, fpc, w, h, options);
            expectAgreement(gpu, cpu, c.name + (d ? " (foci)" : " (identity)"), step);
        }
    }
}

TEST_P(VolumeGpu, OptionsAndTransferFunctionChangesFollowTheReference) {
    const Volume v = codec::sheppLogan3d(48);
    VolumeRendererGpu renderer(context(), v, codec::TransferFunction::preset("bone"));
    const codec::TransferFunction grey = codec::TransferFunction::preset("grey");
    renderer.setTransferFunction(grey);
    codec::VolumeRenderOptions options;
    options.jitter = false;
    options.stepVoxels = 0.8;
    options.rangeLo = 0.1f;
    options.rangeHi = 0.6f;
    options.depthOpacity = 0.3f;
    const Fpc fpc(codec::defaultVolumeCamera(v, 1.0), nullptr);
    const Image gpu = renderer.render(fpc, 64, 64, options);
    const Image cpu = codec::renderVolumeReference(v, grey, fpc, 64, 64, options);
    expectAgreement(gpu, cpu, "grey, no jitter, range 0.1..0.6", float(0.8 * v.spacing.x));
}

TEST_P(VolumeGpu, DeviceRunsTheGpuPathAndTheCpuPath) {
    const Volume v = codec::marschnerLobb(24);
    const codec::TransferFunction tf = codec::TransferFunction::preset("shells");
    const Fpc fpc(codec::defaultVolumeCamera(v, 1.0), nullptr);
    const Image gpu = renderVolume(Device::on(std::shared_ptr<Context>(&context(), [](Context*) {})), v, tf, fpc, 32, 32, {});
    const Image cpu = renderVolume(Device::cpu(), v, tf, fpc, 32, 32, {});
    EXPECT_GE(codec::psnr(colourOf(gpu), colourOf(cpu)), 40.0);
}

INSTANTIATE_TEST_SUITE_P(Backends, VolumeGpu, ::testing::Values(Backend::Egl, Backend::OsMesa), test::paramName);

}  // namespace
}  // namespace conus::renderers
