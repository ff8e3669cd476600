// Overlapping copies of a triangle (a work bomb: every ray, every rasterized pixel pays once per
// copy) through every render that reaches a mesh, by the real tools: the CPU renders probe the
// rays they would trace (eye rays, and the rays a mirror reflects), the GL renders and the viewer
// bound the overlap whatever the view. Each refusal is one line, in seconds, within 500 MB; a few
// copies render, and someone else's reader (OpenImageIO) finds them in the picture.
#include <OpenImageIO/imageio.h>

#include "hostile_fixture.h"

namespace {

using namespace conus::hostile;

class OverlapHostile : public Hostile {
protected:
    // Refused in one line for `reason`, quickly and within 500 MB, with no output left.
    void expectRefusedFast(const Outcome& r, const std::string& command, const std::string& reason, const std::string& output) {
        expectRefused(r, command, reason);
        EXPECT_TRUE(contains(r.err, "limit meshOverlap")) << r.err;
        EXPECT_LT(r.seconds, 5.0 * conus::testing::kTimeScale) << r.err;
        expectMemory(r, 500);
        EXPECT_FALSE(fs::exists(path(output))) << output;
    }
    // The fraction of `file`'s pixels whose channel `channel` is above 0.5, read by OpenImageIO.
    static double fractionAbove(const std::string& file, const char* channel) {
        auto in = OIIO::ImageInput::open(file);
        if (!in) return -1;
        const OIIO::ImageSpec spec = in->spec();
        const int c = spec.channelindex(channel);
        if (c < 0) return -1;
        std::vector<float> pixels(std::size_t(spec.image_pixels()) * spec.nchannels);
        if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data())) return -1;
        std::size_t above = 0;
        for (std::size_t p = 0; p < std::size_t(spec.image_pixels()); ++p) above += pixels[p * spec.nchannels + c] > 0.5f;
        return double(above) / double(spec.image_pixels());
    }
};

constexpr const char* kProbed = "deep along the average ray of this view";
constexpr const char* kBounded = "overlap about";

// The GL mesh render and the viewer rasterize: their bound holds for any view, checked before
// the mesh is uploaded.
TEST_F(OverlapHostile, RasterizedMeshRendersRefuseOverlappingCopiesWhateverTheView) {
    writeNearCopies(m_dir / "near17.gltf", 1 << 17);
    writeNearCopies(m_dir / "near6.gltf", 64);
    Outcome r = run({"render", "mesh", path("near17.gltf"), "-o", path("x.exr"), "--size", "512x512", "--backend", "egl", "--uniform"});
    expectRefusedFast(r, "render", kBounded, "x.exr");
    // Seen edge-on the CPU probe finds one surface a ray; a rasterizer's bound does not depend on it.
    r = run({"render", "mesh", path("near17.gltf"), "-o", path("x.exr"), "--size", "512x512", "--backend", "egl", "--uniform",
             "--camera", "0.5,0.5,5,0.5,0.5,0,30"});
    expectRefusedFast(r, "render", kBounded, "x.exr");
    for (const char* size : {"1024x768", "32x32"}) {
        r = runTool("conus-view", {"--mesh", path("near17.gltf"), "--screenshot", path("s.png"), "--size", size});
        EXPECT_EQ(r.exitCode, 1) << r.err;
        EXPECT_TRUE(contains(r.err, kBounded) && contains(r.err, "limit meshOverlap")) << r.err;
        EXPECT_EQ(errorLines(r.err).size(), 1u) << r.err;
        EXPECT_LT(r.seconds, 5.0 * conus::testing::kTimeScale);
        expectMemory(r, 500);
        EXPECT_FALSE(fs::exists(path("s.png")));
    }
    // 64 copies: drawn by both, the triangle covering part of the picture.
    r = run({"render", "mesh", path("near6.gltf"), "-o", path("ok.exr"), "--size", "64x64", "--backend", "egl", "--uniform"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const double covered = fractionAbove(path("ok.exr"), "A");
    EXPECT_GT(covered, 0.05);
    EXPECT_LT(covered, 0.95);
    r = runTool("conus-view", {"--mesh", path("near6.gltf"), "--screenshot", path("s.png"), "--size", "64x64"});
    EXPECT_EQ(r.exitCode, 0) << r.err;
    EXPECT_TRUE(fs::exists(path("s.png")));
}

// `render reflection`: the eye rays meet the mesh on every backend's CPU path; with --reference
// the rays the mirror reflects are traced against the mesh too; the GL path rasterizes it. Here
// the stack is behind the camera and seen only in a mirror before it.
TEST_F(OverlapHostile, ReflectionFramesRefuseOverlappingCopiesSeenDirectlyOrInTheMirror) {
    writeNearCopies(m_dir / "near17.gltf", 1 << 17);
    writeNearCopies(m_dir / "near6.gltf", 64);
    ASSERT_EQ(run({"bake", "reflection", path("near6.gltf"), "--size", "16", "-o", path("a.exr"), "--layers", "1"}).exitCode, 0);
    // A plane mirror at z = -2 facing the camera at z = -1, which looks away from the stack at
    // z = 0: the stack is seen only in the mirror (about a tenth of the frame).
    const std::vector<std::string> behind = {"--camera", "0.4,0.4,-1,0.4,0.4,-5,40", "--reflector", "plane", "--normal", "0,0,1",
                                             "--at", "0.4,0.4,-2", "--radius", "3", "--size", "256x192"};
    auto command = [&](const std::string& scene, std::vector<std::string> extra) {
        std::vector<std::string> args = {"render", "reflection", path("a.exr"), "--scene", path(scene), "-o", path("f.png")};
        args.insert(args.end(), behind.begin(), behind.end());
        args.insert(args.end(), extra.begin(), extra.end());
        return args;
    };
    Outcome r = run(command("near17.gltf", {"--reference"}));
    expectRefusedFast(r, "render", kProbed, "f.png");
    EXPECT_TRUE(contains(r.err, "reflection frame")) << r.err;
    r = run(command("near17.gltf", {"--backend", "egl"}));
    expectRefusedFast(r, "render", kBounded, "f.png");
    // The faces path on the CPU traces only the eye rays against the mesh, which miss the stack
    // behind the camera: it renders, the mirror showing the asset's faces.
    r = run(command("near17.gltf", {"--backend", "cpu"}));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    // Facing the stack, the eye rays alone are refused on the CPU.
    r = run({"render", "reflection", path("a.exr"), "--scene", path("near17.gltf"), "-o", path("g.png"), "--camera",
             "0.4,0.4,3,0.4,0.4,0,40", "--size", "256x192", "--backend", "cpu"});
    expectRefusedFast(r, "render", kProbed, "g.png");
    // 64 copies: the traced frame shows the triangle in the mirror (OpenImageIO reads it back).
    r = run(command("near6.gltf", {"--reference"}));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    auto in = OIIO::ImageInput::open(path("f.png"));
    ASSERT_TRUE(in);
    EXPECT_EQ(in->spec().width, 256);
    std::vector<float> pixels(std::size_t(in->spec().image_pixels()) * in->spec().nchannels);
    ASSERT_TRUE(in->read_image(0, 0, 0, in->spec().nchannels, OIIO::TypeDesc::FLOAT, pixels.data()));
    float lo = 1, hi = 0;
    for (float v : pixels) lo = std::min(lo, v), hi = std::max(hi, v);
    EXPECT_LT(lo, hi) << "not one flat colour";
    // The viewer's reflection mode rasterizes the scene behind: refused before the upload.
    r = runTool("conus-view", {"--reflection", path("a.exr"), "--scene", path("near17.gltf"), "--screenshot", path("s.png"),
                               "--size", "64x64"});
    EXPECT_EQ(r.exitCode, 1) << r.err;
    EXPECT_TRUE(contains(r.err, kBounded)) << r.err;
    expectMemory(r, 500);
}

}  // namespace
