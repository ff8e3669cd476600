// A consumer of the installed package: encode an asymmetric picture (a red patch in the top-left
// corner on a horizontal ramp) through a focus on that patch, write the CoNUS file, read it back,
// decode the whole frame and check that the patch came back where it was and the ramp is intact.
// Then what a GL program of one's own takes from glsl_interface.h: a depth image with a step (a
// near left half, a far right half) whose flagged depths carry exactly its cells' flags, rays that
// codec::intersect hits at the half they point at, and the inverse of the foci map per pixel.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

#include "conus/codec/builders/foci.h"
#include "conus/codec/conus_file.h"
#include "conus/codec/depth/glsl_interface.h"
#include "conus/codec/image/decode.h"
#include "conus/codec/image/encode.h"
#include "conus/codec/image/metrics.h"
#include "conus/core/error.h"
#include "conus/format/container.h"

static bool checkGlslInterface(const conus::codec::SamplingMap& focus) {
    const int n = 16;
    std::vector<float> depths(n * n);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) depths[y * n + x] = x < n / 2 ? 1.0f : 3.0f;
    const conus::Camera camera = conus::Camera::perspective({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 60, 1, 0.1, 10);
    const conus::codec::DepthImage image(camera, std::make_shared<conus::codec::SamplingMap>(conus::codec::SamplingMap::identity(2, 2)),
                                         n, n, depths, false);
    const std::vector<float> flagged = conus::codec::flaggedDepths(image);
    int flags = 0;
    bool bitsOk = true;
    for (std::size_t i = 0; i < flagged.size(); ++i) {
        std::uint32_t bits;
        std::memcpy(&bits, &flagged[i], sizeof bits);
        bitsOk = bitsOk && (bits & 1u) == image.cellFlags()[i] && std::abs(flagged[i] - depths[i]) <= 1e-6f * depths[i];
        flags += image.cellFlags()[i];
    }
    // Rays from the eye through a quarter and three quarters across, and the view's projection.
    const auto hitDepth = [&](double u) {
        const conus::Ray ray = camera.ray({u, 0.5});
        const auto hit = conus::codec::intersect(image, ray);
        return hit ? hit->depth : -1.0;
    };
    const double nearHit = hitDepth(0.25), farHit = hitDepth(0.75);
    const conus::codec::DepthViewValues view = conus::codec::depthViewValues(image);
    const glm::vec4 clip = view.worldToNdc * glm::vec4(0.0f, 0.0f, -2.0f, 1.0f);
    const bool viewOk = std::abs(clip.x / clip.w - 0.5f) < 1e-5f && std::abs(clip.y / clip.w - 0.5f) < 1e-5f && !view.solid;
    // undistortedTable inverts Equation 1 at each pixel centre of a 32 x 24 CoNUS image.
    const std::vector<float> table = conus::codec::undistortedTable(focus, 32, 24);
    double worst = 0;
    for (int y = 0; y < 24; ++y)
        for (int x = 0; x < 32; ++x) {
            const glm::dvec2 back = focus.distort({table[(y * 32 + x) * 2], table[(y * 32 + x) * 2 + 1]});
            worst = std::max(worst, glm::length(back - glm::dvec2((x + 0.5) / 32, (y + 0.5) / 24)));
        }
    const bool constants = conus::codec::glslConstants().find("const float kSilhouetteStep = 0.25;") != std::string::npos;
    const bool ok = bitsOk && flags > 0 && std::abs(nearHit - 1) < 1e-3 && std::abs(farHit - 3) < 1e-3 && viewOk &&
                    worst < 1e-6 && constants;
    std::printf("consumer: glsl_interface: %d flagged cells %s, hits at depth %.4f and %.4f, view %s, inverse within %.1e, "
                "constants %s\n", flags, bitsOk ? "ok" : "WRONG", nearHit, farHit, viewOk ? "ok" : "WRONG", worst,
                constants ? "ok" : "WRONG");
    return ok;
}

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: consumer OUT.exr\n");
        return 2;
    }
    try {
        const int w = 256, h = 128;
        conus::Image source = conus::makeImage(w, h, {"R", "G", "B"});
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const bool patch = x < 32 && y < 24;
                source.at(x, y, 0) = patch ? 1.0f : 0.0f;
                source.at(x, y, 1) = patch ? 0.0f : float(x) / (w - 1);
                source.at(x, y, 2) = patch ? 0.0f : 0.25f;
            }
        const std::vector<conus::codec::Focus> foci{{0.06, 0.1, 0.08, 4}};
        conus::codec::FociOptions fociOptions;
        fociOptions.aspect = double(w) / h;
        const conus::codec::SamplingMap map = conus::codec::buildFociMap(foci, fociOptions);
        const conus::Image encoded = conus::codec::encodeImage(source, map, {w / 2, h / 2});
        conus::format::writeConusFile(argv[1], conus::codec::makeImageFile(encoded, map, w, h, {}));

        const conus::format::ConusFile file = conus::format::readConusFile(argv[1]);
        const conus::codec::SamplingMap read = conus::codec::SamplingMap::fromGrid(file.map);
        conus::codec::DecodeOptions decodeOptions;
        decodeOptions.width = w;
        decodeOptions.height = h;
        const conus::Image frame = conus::codec::decodeImage(file.image, read, decodeOptions);
        const int r = frame.channelIndex("R"), g = frame.channelIndex("G");
        const bool patch = frame.at(12, 10, r) > 0.9f && frame.at(12, 10, g) < 0.1f;
        const bool ramp = frame.at(w - 10, h - 10, r) < 0.05f && std::abs(frame.at(w - 10, h - 10, g) - float(w - 10) / (w - 1)) < 0.05f;
        std::printf("consumer: %dx%d CoNUS image, decoded PSNR %.1f dB, patch %s, ramp %s\n", encoded.width, encoded.height,
                    conus::codec::psnr(frame, source), patch ? "ok" : "WRONG", ramp ? "ok" : "WRONG");
        try {
            conus::format::readConusFile(std::string(argv[1]) + ".missing");
            std::fprintf(stderr, "consumer: reading a missing file did not throw\n");
            return 1;
        } catch (const conus::Error& e) {
            std::printf("consumer: a missing file throws conus::Error: %s\n", e.what());
        }
        const bool gpu = checkGlslInterface(map);
        return patch && ramp && gpu ? 0 : 1;
    } catch (const conus::Error& e) {
        std::fprintf(stderr, "consumer: %s\n", e.what());
        return 1;
    }
}
