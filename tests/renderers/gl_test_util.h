// Shared by the renderers tests: one context per backend for the whole run, and test images.
#pragma once

#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "conus/codec/builders/foci.h"
#include "conus/codec/map/sampling_map.h"
#include "conus/core/image.h"
#include "conus/renderers/context.h"
#include "test_images.h"

namespace conus::renderers::test {

// Both backends must work on CI machines (Mesa's EGL and OSMesa): a missing one fails, never skips.
inline Context& contextFor(Backend backend) {
    // Never destroyed: Mesa's own exit handlers may run before static destructors.
    static auto* contexts = new std::map<Backend, std::unique_ptr<Context>>;
    auto& slot = (*contexts)[backend];
    if (!slot) slot = Context::create(backend);
    return *slot;
}

inline std::string paramName(const ::testing::TestParamInfo<Backend>& info) { return enumName(info.param); }


using conus::test::photoLike;

// A valid random map: a coarse grid with interior nodes jittered by up to `amplitude` of a cell.
inline codec::SamplingMap jitteredMap(int columns, int rows, double amplitude, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> d(-amplitude, amplitude);
    std::vector<glm::vec2> nodes;
    for (int j = 0; j < rows; ++j)
        for (int i = 0; i < columns; ++i) {
            double u = double(i) / (columns - 1), v = double(j) / (rows - 1);
            if (i > 0 && i < columns - 1) u += d(rng) / (columns - 1);
            if (j > 0 && j < rows - 1) v += d(rng) / (rows - 1);
            nodes.emplace_back(float(u), float(v));
        }
    return codec::SamplingMap(columns, rows, std::move(nodes));
}

// buildFociMap with 1-3 random foci.
inline codec::SamplingMap randomFociMap(unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> pos(0.15, 0.85), radius(0.04, 0.12), gain(1.5, 5.0);
    std::vector<codec::Focus> foci(1 + seed % 3);
    for (auto& f : foci) f = {pos(rng), pos(rng), radius(rng), gain(rng)};
    codec::FociOptions options;
    options.composition = seed % 2 ? codec::FociComposition::Density : codec::FociComposition::Add;
    return codec::buildFociMap(foci, options);
}

}  // namespace conus::renderers::test
