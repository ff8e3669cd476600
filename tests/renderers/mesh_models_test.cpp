// The GPU mesh encoder against the exact Embree reference on the five models of
// ../shared/data/meshes, through a strong focus: with edge subdivision >= 35 dB and camera depth
// within 1% of the model's depth range; without it, measurably worse on a coarse mesh.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "conus/codec/builders/foci.h"
#include "conus/codec/mesh/raycast.h"
#include "conus/codec/mesh/subdivide.h"
#include "conus/renderers/mesh_render.h"
#include "conus/sceneio/mesh_file.h"
#include "gl_test_util.h"
#include "mesh_test_util.h"

namespace conus::renderers {
namespace {

constexpr int kSide = 192;

// Looking at the bounding box's centre from the front right and above, the box's sphere in view.
Camera framing(const Mesh& mesh) {
    glm::dvec3 lo(1e300), hi(-1e300);
    for (const auto& p : mesh.positions) {
        lo = glm::min(lo, glm::dvec3(p));
        hi = glm::max(hi, glm::dvec3(p));
    }
    const glm::dvec3 centre = 0.5 * (lo + hi);
    const double radius = 0.5 * glm::length(hi - lo);
    const double distance = 1.05 * radius / std::sin(20.0 * 3.14159265358979 / 180.0);
    const glm::dvec3 eye = centre + distance * glm::normalize(glm::dvec3(0.55, 0.45, 1.0));
    return Camera::perspective(eye, centre, {0, 1, 0}, 40.0, 1.0, distance - 1.5 * radius, distance + 1.5 * radius);
}

struct Comparison {
    double psnr = 0;
    test::DepthError depth;
};

Comparison compare(const Image& gpu, const Image& reference) { return {test::colourPsnr(gpu, reference), test::depthError(gpu, reference)}; }

// The depth range the model covers in the reference.
double depthRange(const Image& reference) {
    double lo = 1e300, hi = -1e300;
    for (int y = 0; y < reference.height; ++y)
        for (int x = 0; x < reference.width; ++x)
            if (reference.at(x, y, 3) > 0) {
                lo = std::min(lo, double(reference.at(x, y, 4)));
                hi = std::max(hi, double(reference.at(x, y, 4)));
            }
    return hi - lo;
}

// `mesh` through one focus, rendered on the GPU as it is, subdivided for the map on the CPU (both
// drawn without tessellation) and split by the tessellation stages (the default), each compared
// with the Embree reference.
struct SubdivisionRun {
    Image reference;
    Mesh fine;  // the subdivided mesh
    Comparison coarse, split, tessellated;
};

SubdivisionRun renderWithAndWithoutSubdivision(const Mesh& mesh, const Camera& camera, const codec::Focus& focus) {
    const auto map = std::make_shared<codec::SamplingMap>(codec::buildFociMap(std::span(&focus, 1)));
    const codec::MeshScene scene{Mesh(mesh)};
    SubdivisionRun run;
    run.reference = codec::renderMeshReference(scene, Fpc(camera, map), kSide, kSide);
    Context& context = test::contextFor(Backend::Egl);
    MeshRenderOptions options;
    options.samples = 1;  // the pixel centre, like the reference's one ray
    run.tessellated = compare(renderMeshGpu(context, mesh, camera, *map, kSide, kSide, options), run.reference);
    options.maxBend = 0;
    run.fine = codec::subdivideForMap(mesh, camera, *map, 0.5);
    run.coarse = compare(renderMeshGpu(context, mesh, camera, *map, kSide, kSide, options), run.reference);
    run.split = compare(renderMeshGpu(context, run.fine, camera, *map, kSide, kSide, options), run.reference);
    return run;
}

class MeshModels : public ::testing::TestWithParam<std::string> {};

TEST_P(MeshModels, GpuMatchesTheEmbreeReferenceWithSubdivision) {
    const std::filesystem::path file = std::filesystem::path(CONUS_SHARED_DATA) / "meshes" / GetParam();
    if (!std::filesystem::exists(file)) GTEST_SKIP() << file << " is absent (the shared test data is not here)";
    const Mesh mesh = sceneio::readMesh(file.string());
    const Camera camera = framing(mesh);
    // A strong focus a little off the model's centre.
    const auto [reference, fine, coarse, split, tessellated] =
        renderWithAndWithoutSubdivision(mesh, camera, {0.42, 0.45, 0.12, 4.0});
    const double range = depthRange(reference);
    std::printf("%s: %zu -> %zu triangles; PSNR %.2f dB -> %.2f dB (tessellated %.2f dB); depth error p99 %.3g%% -> "
                "%.3g%% (%.3g%%) of the range\n",
                GetParam().c_str(), mesh.triangleCount(), fine.triangleCount(), coarse.psnr, split.psnr, tessellated.psnr,
                100 * coarse.depth.p99 / range, 100 * split.depth.p99 / range, 100 * tessellated.depth.p99 / range);
    EXPECT_GE(split.psnr, 35.0);
    EXPECT_LT(split.depth.p99, 0.01 * range);
    EXPECT_GE(tessellated.psnr, 35.0);
    EXPECT_GE(tessellated.psnr, coarse.psnr - 0.01);  // small triangles stay whole
    EXPECT_LT(tessellated.depth.p99, 0.01 * range);
    EXPECT_GT(split.depth.pixels, kSide * kSide / 10);
}

INSTANTIATE_TEST_SUITE_P(SharedData, MeshModels,
                         ::testing::Values("stanford-bunny.obj", "spot.obj", "teapot.obj", "suzanne.obj", "cow.obj"),
                         [](const auto& info) {
                             std::string name = info.param.substr(0, info.param.find('.'));
                             for (char& c : name)
                                 if (c == '-') c = '_';
                             return name;
                         });

// A big box seen up close through a strong focus: its long edges and faces cross many map cells,
// so without subdivision the straight edges miss Equation 1's curves; split on the CPU or by the
// tessellation stages they follow them.
TEST(MeshSubdivision, ACoarseBoxUnderAStrongFocusNeedsIt) {
    Mesh box;
    test::appendBox(box, {-2.0, -1.0, -2.0}, {2.0, 1.2, 1.5});
    const Camera camera = Camera::perspective({2.5, 2.0, 5.0}, {0.0, 0.0, 0.0}, {0, 1, 0}, 55.0, 1.0, 1.0, 20.0);
    const auto [reference, fine, coarse, split, tessellated] =
        renderWithAndWithoutSubdivision(box, camera, {0.45, 0.5, 0.15, 6.0});
    ASSERT_GT(fine.triangleCount(), 20 * box.triangleCount());
    std::printf("box: %zu -> %zu triangles; PSNR %.2f dB -> %.2f dB (tessellated %.2f dB); depth error mean %.4g -> %.4g (%.4g)\n",
                box.triangleCount(), fine.triangleCount(), coarse.psnr, split.psnr, tessellated.psnr, coarse.depth.mean,
                split.depth.mean, tessellated.depth.mean);
    for (const Comparison& followed : {split, tessellated}) {
        EXPECT_GE(followed.psnr, 35.0);
        EXPECT_GT(followed.psnr, coarse.psnr + 6.0);  // measurably better: a quarter of the error energy
        EXPECT_LT(followed.depth.mean, 0.5 * coarse.depth.mean);
    }
}

}  // namespace
}  // namespace conus::renderers
