// How the reflection benches score a mirror: each reflector pixel of the traced reference is put in
// the region of interest when its reflected ray meets the box (the scene's first `boxTriangles`),
// else in the rest, and the CoNUS and uniform frames are compared with the reference there
// (colour clamped to [0, 1]); and the picture they write: the three frames above, the box enlarged
// below.
#pragma once

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "conus/codec/depth/reflection.h"
#include "conus/core/camera.h"
#include "conus/core/image.h"
#include "conus/imageio/image_file.h"

namespace conus::bench {

struct MirrorScore {
    // [frame: 0 uniform, 1 CoNUS][region: 0 ROI, 1 rest]
    double squared[2][2] = {}, wrong[2][2] = {};
    double count[2] = {};
    glm::ivec2 roiLo{0}, roiHi{0};  // the ROI's pixel bounds

    // PSNR of frame k over `regions` (a list of region indices; both: the whole mirror).
    double psnr(int k, std::initializer_list<int> regions) const {
        double s = 0, n = 0;
        for (int r : regions) s += squared[k][r], n += count[r];
        return 10.0 * std::log10(n / std::max(s, 1e-30));
    }
};

// frames[0] uniform, frames[1] CoNUS; all `side` x `side`. A pixel more than 0.1 RMS off counts as
// wrong: a hit on another surface (the silhouettes).
inline MirrorScore scoreMirror(const Image (&frames)[2], const Image& truth, const codec::MeshScene& scene,
                               const codec::Reflector& reflector, const Camera& camera, int side, std::uint32_t boxTriangles) {
    MirrorScore s;
    s.roiLo = glm::ivec2(side);
    for (int y = 0; y < side; ++y)
        for (int x = 0; x < side; ++x) {
            if (truth.at(x, y, 3) == 0.0f) continue;
            const auto mirror = codec::hitReflector(reflector, camera.ray({(x + 0.5) / side, (y + 0.5) / side}));
            const auto hit = mirror ? scene.intersect(mirror->reflected, 1e-6) : std::nullopt;
            const int region = hit && hit->triangle < boxTriangles ? 0 : 1;
            if (region == 0) {
                s.roiLo = glm::min(s.roiLo, glm::ivec2(x, y));
                s.roiHi = glm::max(s.roiHi, glm::ivec2(x, y));
            }
            for (int k = 0; k < 2; ++k) {
                double e = 0;
                for (int c = 0; c < 3; ++c) {
                    const double d = std::clamp(frames[k].at(x, y, c), 0.0f, 1.0f) - std::clamp(truth.at(x, y, c), 0.0f, 1.0f);
                    e += d * d / 3.0;
                }
                s.squared[k][region] += e;
                s.wrong[k][region] += e > 0.01;
            }
            s.count[region] += 1;
        }
    return s;
}

// The PSNR counters of a scored mirror, each name led by `prefix`: mirror_ (the whole mirror),
// `roi`_ (the region of interest) and rest_, each of them _conus_dB and _uniform_dB.
inline void addMirrorCounters(benchmark::State& state, const MirrorScore& s, const std::string& prefix, const std::string& roi) {
    const char* frames[2] = {"_uniform_dB", "_conus_dB"};
    for (int k = 0; k < 2; ++k) {
        state.counters[prefix + "mirror" + frames[k]] = s.psnr(k, {0, 1});
        state.counters[prefix + roi + frames[k]] = s.psnr(k, {0});
        state.counters[prefix + "rest" + frames[k]] = s.psnr(k, {1});
    }
}

// CoNUS | uniform | reference above; below, each `zoom` times enlarged (nearest) around the ROI's centre.
inline void writeMirrorStrip(const std::string& path, const Image (&frames)[2], const Image& truth, const MirrorScore& score,
                             int side, int zoom) {
    const int crop = side / zoom;
    const glm::ivec2 corner = glm::clamp((score.roiLo + score.roiHi) / 2 - crop / 2, 0, side - crop);
    Image strip{3 * side, 2 * side, {"R", "G", "B"}, std::vector<float>(std::size_t(6) * side * side * 3)};
    const Image* parts[3] = {&frames[1], &frames[0], &truth};
    for (int p = 0; p < 3; ++p)
        for (int y = 0; y < side; ++y)
            for (int x = 0; x < side; ++x)
                for (int c = 0; c < 3; ++c) {
                    strip.at(p * side + x, y, c) = parts[p]->at(x, y, c);
                    strip.at(p * side + x, side + y, c) = parts[p]->at(corner.x + x / zoom, corner.y + y / zoom, c);
                }
    imageio::writeImageFile(path, strip);
}

}  // namespace conus::bench
