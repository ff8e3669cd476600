// A consumer of the installed package: encode an asymmetric picture (a red patch in the top-left
// corner on a horizontal ramp) through a focus on that patch, write the CoNUS file, read it back,
// decode the whole frame and check that the patch came back where it was and the ramp is intact.
#include <cmath>
#include <cstdio>
#include <vector>

#include "conus/codec/build/foci.h"
#include "conus/codec/conus_file.h"
#include "conus/codec/image/decode.h"
#include "conus/codec/image/encode.h"
#include "conus/codec/image/metrics.h"
#include "conus/core/error.h"
#include "conus/format/container.h"

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
        return patch && ramp ? 0 : 1;
    } catch (const conus::Error& e) {
        std::fprintf(stderr, "consumer: %s\n", e.what());
        return 1;
    }
}
