// Fuzz harness: a sampling map from arbitrary bytes, then its rules, its inverse (index bounds and
// round trip) and a small decode through it. Byte 0 and 1 give the grid (2..33 nodes a side);
// byte 2 says how the rest is read: odd, as raw floats over the identity's nodes (mostly invalid
// maps: the rules); even, as small signed moves of the identity's nodes with the boundary on its
// edges (mostly valid maps: the inverse).
#include <algorithm>
#include <cmath>
#include <cstring>

#include "conus/codec/image/decode.h"
#include "conus/codec/map/sampling_map.h"
#include "conus/format/container.h"
#include "fuzz.h"

namespace {

using namespace conus;

format::GridNodes gridFrom(const std::uint8_t* data, std::size_t size) {
    format::GridNodes g;
    g.columns = 2 + data[0] % 32;
    g.rows = 2 + data[1] % 32;
    const bool raw = data[2] & 1;
    data += 3;
    size -= 3;
    g.xy.resize(std::size_t{2} * g.columns * g.rows);
    for (int j = 0; j < g.rows; ++j) {
        for (int i = 0; i < g.columns; ++i) {
            const std::size_t k = std::size_t(j) * g.columns + i;
            g.xy[2 * k] = float(i) / float(g.columns - 1);
            g.xy[2 * k + 1] = float(j) / float(g.rows - 1);
        }
    }
    if (raw) {
        std::memcpy(g.xy.data(), data, std::min(size, g.xy.size() * sizeof(float)));
        return g;
    }
    // Moves of up to half a cell; nodes on an edge move only along it, corners not at all.
    for (std::size_t c = 0; c < std::min(size, g.xy.size()); ++c) {
        const std::size_t k = c / 2;
        const int i = int(k % g.columns), j = int(k / g.columns);
        const bool alongX = c % 2 == 0;
        if (alongX ? (i == 0 || i == g.columns - 1) : (j == 0 || j == g.rows - 1)) continue;
        const float cell = 1.0f / float((alongX ? g.columns : g.rows) - 1);
        g.xy[c] += 0.5f * cell * float(static_cast<std::int8_t>(data[c])) / 128.0f;
    }
    return g;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size < 3) return 0;
    const format::GridNodes grid = gridFrom(data, size);
    const format::ValidationReport report = format::validateGrid(grid);
    CONUS_FUZZ_CHECK(report.str().find('\n') == std::string::npos, "a report is one line");
    if (!report.ok()) {
        try {
            codec::SamplingMap::fromGrid(grid);
            CONUS_FUZZ_CHECK(false, "SamplingMap accepted a grid validateGrid refused");
        } catch (const Error& e) {
            CONUS_FUZZ_CHECK(e.code() == ErrorCode::InvalidMap, "an invalid grid is InvalidMap");
        }
        return 0;
    }
    const codec::SamplingMap map = codec::SamplingMap::fromGrid(grid);
    const std::int64_t cells = std::int64_t{grid.columns - 1} * (grid.rows - 1);
    CONUS_FUZZ_CHECK(std::int64_t(map.indexBytes()) <= std::min(kMaxIndexBytes, kIndexBytesPerCell * cells + kIndexBytesBase),
                     "the index stays within its budget");
    // The inverse: every distorted point maps back onto itself, inside the unit square.
    for (int j = 0; j <= 4; ++j) {
        for (int i = 0; i <= 4; ++i) {
            const glm::dvec2 q(i / 4.0, j / 4.0);
            const glm::dvec2 p = map.undistort(q);
            CONUS_FUZZ_CHECK(p.x >= 0 && p.x <= 1 && p.y >= 0 && p.y <= 1, "undistort stays in [0,1]^2");
            const glm::dvec2 back = map.distort(p);
            CONUS_FUZZ_CHECK(std::abs(back.x - q.x) < 1e-7 && std::abs(back.y - q.y) < 1e-7, "distort(undistort(q)) == q");
        }
    }
    Image image = makeImage(5, 4, {"Y"});
    for (std::size_t k = 0; k < image.pixels.size(); ++k) image.pixels[k] = float(k);
    codec::DecodeOptions decode;
    decode.view = {0.2, 0.1, 0.7, 0.9};
    decode.width = 7;
    decode.height = 5;
    decode.threads = 1;
    const Image frame = codec::decodeImage(image, map, decode);
    for (float v : frame.pixels) CONUS_FUZZ_CHECK(v >= 0.0f && v <= 19.0f, "decoded values stay within the image's");
    return 0;
}
