// What a GL program needs to intersect rays with a CoNUS depth image in GLSL, with the same
// shader code `conus render reflection` and `render relief` run: the installed includes
// <datadir>/conus/glsl/equation1.inc.glsl (Equation 1, evalMap) and intersect.inc.glsl (the
// walk, intersectDepthImage / intersectBehindLayer), whose functions are the GLSL twins of
// SamplingMap::distort and codec::intersect / codec::intersectBehind (intersect.h).
// docs/reflections-in-your-renderer.md shows them in a program of its own
// (share/doc/conus/examples/reflection_gl).
//
// The includes expect, per depth image:
//   - a depth texture, R32F, GL_NEAREST: the camera depths (top row first) with each cell's
//     discontinuity flag in the lowest mantissa bit (flaggedDepths); a layered image's layers
//     side by side in one texture (sideBySide; gDepthLayers / gDepthLayer say which is read);
//   - a map texture, RG32F, GL_NEAREST: the sampling map's nodes (SamplingMap::nodes(), columns x
//     rows, row 0 first), read with texelFetch;
//   - a `DepthView` uniform (intersect.inc.glsl) holding depthViewValues();
//   - the constants glslConstants() declares, placed after the shader's #version line.
// The inverse of Equation 1 has no GLSL twin: where a shader needs the undistorted point of each
// CoNUS pixel it reads undistortedTable() (exact, SamplingMap::undistort), as the volume renderer does.
// Everything here is header-only and uses codec's own values, so the GPU and the CPU reference
// cannot drift apart.
#pragma once

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "conus/codec/depth/intersect.h"
#include "conus/codec/image/decode.h"
#include "conus/core/fpc.h"
#include "conus/core/parallel.h"

namespace conus::codec {

// A float as exact GLSL text (9 significant digits round-trip it; always with a '.' or an 'e').
inline std::string glslFloat(double value) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.9g", value);
    std::string text = buffer;
    if (text.find_first_of(".e") == std::string::npos) text += ".0";
    return text;
}

// The GLSL declarations of the constants equation1.inc.glsl and intersect.inc.glsl use:
// kDecodeMultiTap, kDecodeMaxTaps, kDecodePyramidBias (image/decode.h) and kIntersectDepthMargin,
// kSilhouetteStep, kSideRuleFarMargin (intersect.h), one `const` a line.
inline std::string glslConstants() {
    std::string s;
    s += "const float kDecodeMultiTap = " + glslFloat(kDecodeMultiTap) + ";\n";
    s += "const int kDecodeMaxTaps = " + std::to_string(kDecodeMaxTaps) + ";\n";
    s += "const float kDecodePyramidBias = " + glslFloat(kDecodePyramidBias) + ";\n";
    s += "const float kIntersectDepthMargin = " + glslFloat(kIntersectDepthMargin) + ";\n";
    s += "const float kSilhouetteStep = " + glslFloat(kSilhouetteStep) + ";\n";
    s += "const float kSideRuleFarMargin = " + glslFloat(kSideRuleFarMargin) + ";\n";
    return s;
}

// The depths as the GLSL walk reads them: each carries its cell's flag (DepthImage::cellFlags;
// never set in a solid image) in the lowest mantissa bit, a change of at most one unit in the last
// place, so that one R32F fetch gives both.
inline std::vector<float> flaggedDepths(const DepthImage& image) {
    std::vector<float> out = image.depths();
    for (std::size_t i = 0; i < out.size(); ++i) {
        std::uint32_t bits;
        std::memcpy(&bits, &out[i], sizeof bits);
        bits = (bits & ~std::uint32_t{1}) | std::uint32_t{image.cellFlags()[i]};
        std::memcpy(&out[i], &bits, sizeof bits);
    }
    return out;
}

// Images of one size side by side in one, `channels` floats a texel: layer k's texel (x, y) at
// (x + k * width, y), as intersect.inc.glsl reads a layered depth image (and a renderer its colours).
inline std::vector<float> sideBySide(const std::vector<std::vector<float>>& layers, int width, int height, int channels) {
    const std::size_t row = std::size_t(width) * channels, count = layers.size();
    std::vector<float> out(row * count * height);
    for (std::size_t k = 0; k < count; ++k)
        for (int y = 0; y < height; ++y)
            std::memcpy(&out[(std::size_t(y) * count + k) * row], &layers[k][std::size_t(y) * row], row * sizeof(float));
    return out;
}

// The undistorted point (u, v) of each pixel centre of a width x height CoNUS image, interleaved,
// top row first: the exact inverse of Equation 1 (Distortion::undistort) as an RG32F texture's
// data, computed on `threads` cores (0: all).
inline std::vector<float> undistortedTable(const Distortion& distortion, int width, int height, int threads = 0) {
    std::vector<float> table(static_cast<std::size_t>(width) * height * 2);
    parallelRows(height, threads, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y)
            for (int x = 0; x < width; ++x) {
                const glm::dvec2 p = distortion.undistort({(x + 0.5) / width, (y + 0.5) / height});
                float* out = &table[(static_cast<std::size_t>(y) * width + x) * 2];
                out[0] = float(p.x);
                out[1] = float(p.y);
            }
    });
    return table;
}

// The fields of intersect.inc.glsl's `DepthView` uniform for `image`, in its order (matrices
// column-major, as glm and glUniformMatrix4fv with transpose false take them).
struct DepthViewValues {
    glm::mat4 worldToNdc{1.0f}, ndcToWorld{1.0f};
    glm::vec3 eye{0.0f}, forward{0.0f, 0.0f, -1.0f};
    float near = 0, far = 0;
    bool perspective = true;
    float minDepth = 0, maxDepth = 0;
    bool solid = true;
    float jumpRelative = 0, jumpAbsolute = 0;
};

inline DepthViewValues depthViewValues(const DepthImage& image) {
    const Camera& camera = image.camera();
    const glm::dmat4 toNdc = camera.worldToNdcMatrix();
    DepthViewValues v;
    v.worldToNdc = glm::mat4(toNdc);
    v.ndcToWorld = glm::mat4(glm::inverse(toNdc));  // inverted in double, then rounded
    v.eye = glm::vec3(camera.eye());
    v.forward = glm::vec3(camera.forward());
    v.near = static_cast<float>(camera.near());
    v.far = static_cast<float>(camera.far());
    v.perspective = camera.projection() == Projection::Perspective;
    v.minDepth = static_cast<float>(image.minDepth());
    v.maxDepth = static_cast<float>(image.maxDepth());
    v.solid = image.solid();
    v.jumpRelative = static_cast<float>(image.jumpRelative());
    v.jumpAbsolute = static_cast<float>(image.jumpAbsolute());
    return v;
}

}  // namespace conus::codec
