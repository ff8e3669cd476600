// Procedural test images shared by the suites: varied content (noise, textures, zone plates), never
// constants, so a resampler that is wrong cannot pass by accident.
#pragma once

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "conus/core/image.h"

namespace conus::test {

// Uniform noise in [0,1) in every channel.
inline Image noise(int w, int h, std::vector<std::string> channels, unsigned seed = 1) {
    Image im = makeImage(w, h, std::move(channels));
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> d(0.0f, 1.0f);
    for (float& v : im.pixels) v = d(rng);
    return im;
}

// An RGB picture made from RGB noise: channel c at (x, y) is value(n, x, y, c), n the noise
// (noise above, of `seed`).
template <class Value>
Image fromNoise(int w, int h, unsigned seed, Value value) {
    const Image n = noise(w, h, {"R", "G", "B"}, seed);
    Image im = makeImage(w, h, {"R", "G", "B"});
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) im.at(x, y, c) = value(n, x, y, c);
    return im;
}

// Noise box-blurred over 3x3: a detailed texture with little energy at the very top frequencies.
inline Image texture(int size, unsigned seed) {
    const Image n = noise(size, size, {"Y"}, seed);
    Image t = makeImage(size, size, {"Y"});
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            float sum = 0;
            for (int j = -1; j <= 1; ++j)
                for (int i = -1; i <= 1; ++i)
                    sum += n.at(std::clamp(x + i, 0, size - 1), std::clamp(y + j, 0, size - 1));
            t.at(x, y) = sum / 9;
        }
    return t;
}

// cos(pi * k * r^2) with r in pixels from the centre: the local frequency grows linearly with r
// and reaches `edgeFrequency` cycles per pixel at the middle of the sides.
inline Image zonePlate(int size, double edgeFrequency) {
    Image im = makeImage(size, size, {"Y"});
    const double half = size / 2.0, k = edgeFrequency / half;
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const double dx = x + 0.5 - half, dy = y + 0.5 - half;
            im.at(x, y) = static_cast<float>(0.5 + 0.5 * std::cos(M_PI * k * (dx * dx + dy * dy)));
        }
    return im;
}

// The largest difference between two images' values; a size mismatch fails the calling test.
inline float maxAbsDifference(const Image& a, const Image& b) {
    EXPECT_EQ(a.pixels.size(), b.pixels.size());
    float worst = 0;
    for (std::size_t i = 0; i < std::min(a.pixels.size(), b.pixels.size()); ++i)
        worst = std::max(worst, std::abs(a.pixels[i] - b.pixels[i]));
    return worst;
}

// Photo-like: smooth shading, hard-edged shapes, fine texture and a little noise, per channel
// slightly different.
inline Image photoLike(int w, int h, std::vector<std::string> channels = {"R", "G", "B"}, unsigned seed = 7) {
    Image im = makeImage(w, h, std::move(channels));
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> noise(-0.03f, 0.03f);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const double u = (x + 0.5) / w, v = (y + 0.5) / h;
            for (int c = 0; c < im.channelCount(); ++c) {
                double value = 0.35 + 0.25 * std::sin(3.0 * u + 2.0 * v + c) * std::cos(2.5 * v - c);
                const double dx = u - 0.3 - 0.1 * c, dy = v - 0.55;
                if (dx * dx + dy * dy < 0.04) value += 0.3;
                if (u > 0.6 && u < 0.85 && v > 0.15 && v < 0.4) value -= 0.2;
                value += 0.08 * std::sin(140.0 * u * (1 + v)) * std::sin(90.0 * v);
                im.at(x, y, c) = static_cast<float>(value) + noise(rng);
            }
        }
    return im;
}

}  // namespace conus::test
