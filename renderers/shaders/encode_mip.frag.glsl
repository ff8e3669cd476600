#version 450 core
// One CoNUS pixel by the anisotropic kernel (codec::EncodeFilter::Anisotropic; encode.h states it)
// on GL's own mipmaps of the source (glGenerateMipmap). The footprint's principal axes set the
// continuous level lambda, where the minor axis spans kEncodeAnisotropicMinorTexels texels (coarser
// where the major axis would need more than kEncodeAnisotropicMaxTaps taps); on level floor(lambda)
// rows of taps across the minor axis (slice centres of the unit box) and along the major axis (slice
// centres of the box widened by the Gaussian's reach), at most a texel apart, each weighted by the
// truncated Gaussian's mass over the offsets that keep it in the box; bilinear taps on the level,
// the same on the next level with its own (fewer) taps, the two blended by lambda's fraction, as the
// CPU kernel does (one trilinear sample per tap at the coarser level's positions would blur past
// the box: 48 dB against the area average at 4:1, where this is exact).
//
// uSegment > 1: the sampler's anisotropic filter stands in for up to uSegment neighbouring taps of a
// row, in one textureGrad sample whose gradients are that stretch of the major axis and the minor
// axis over kEncodeAnisotropicMinorTexels (so that the sampler's own level is lambda, from the minor
// axis, wherever the minor axis sets it), weighted by the taps' summed weight. What the sampler
// does within that footprint is the driver's own (llvmpipe's is an elliptical Gaussian, wider than
// the box): gpu_image.h says where it is used.
in vec2 vUndistorted;
in vec4 vFootprint;
layout(location = 0) out vec4 fragColor;
uniform sampler2D uSource;  // mipmapped, trilinear, clamp to edge; the sampler gives linear light
uniform float uUniform;     // the uniform image's pixel in level-0 texels (codec::uniformSpacing)
uniform int uSegment;       // taps per sample along the major axis

#include "encode_footprint.inc.glsl"

// A tap's weight at offset u (CoNUS pixels) along the major axis: the truncated Gaussian's mass
// over the offsets that keep it in the unit box (up to a common factor).
float tapWeight(float u, float sigma, float reach) {
    if (sigma < 1e-4) return 1.0;
    const float lo = max(u - 0.5, -reach), hi = min(u + 0.5, reach);
    if (hi <= lo) return 0.0;
    const float k = 1.0 / (sqrt(2.0) * sigma);
    return erfApprox(hi * k) - erfApprox(lo * k);
}

// The kernel's taps on one level, normalized: rows across the minor axis, taps along the major
// axis, as many as that level's texels need (the CPU kernel's counts), each bilinear on the level.
vec4 filterOnLevel(int level, vec2 major, vec2 minor, float extent, FootprintFilter f) {
    const float tol = kEncodeTapTolerance;
    const vec2 scale = vec2(textureSize(uSource, level)) / vec2(textureSize(uSource, 0));
    const int maxTaps = 2 * kEncodeMaxAxisTaps;
    const int nu = clamp(int(ceil(length(major * scale) * extent - tol)), 1, maxTaps);
    const int nw = clamp(int(ceil(length(minor * scale) - tol)), 1, maxTaps);
    const float du = extent / float(nu), dw = 1.0 / float(nw);
    const vec2 size0 = vec2(textureSize(uSource, 0));
    const vec2 majorStep = major / size0, minorStep = minor / size0;  // normalized, per CoNUS pixel
    const int segment = max(uSegment, 1);
    vec4 sum = vec4(0.0);
    float total = 0.0;
    for (int j = 0; j < nw; ++j) {
        const vec2 row = vUndistorted + minorStep * ((float(j) + 0.5) * dw - 0.5);
        for (int i = 0; i < nu; i += segment) {
            const int n = min(segment, nu - i);
            float w = 0.0;
            for (int k = 0; k < n; ++k) w += tapWeight((float(i + k) + 0.5) * du - 0.5 * extent, f.sigma, f.reach);
            if (w <= 0.0) continue;
            const vec2 q = row + majorStep * ((float(i) + 0.5 * float(n)) * du - 0.5 * extent);
            const vec4 value = segment == 1 ? textureLod(uSource, q, float(level))
                                            : textureGrad(uSource, q, majorStep * (float(n) * du), minorStep / kEncodeAnisotropicMinorTexels);
            sum += w * value;
            total += w;
        }
    }
    return total > 0.0 ? sum / total : vec4(0.0);
}

void main() {
    const vec2 size0 = vec2(textureSize(uSource, 0));
    const vec2 a = vFootprint.xy * size0, b = vFootprint.zw * size0;  // in level-0 texels
    const FootprintFilter f = footprintFilter(a, b, uUniform);
    const vec2 across = vec2(-f.major.y, f.major.x);
    const vec2 major = a * f.major.x + b * f.major.y, minor = a * across.x + b * across.y;
    const float extent = 1.0 + 2.0 * f.reach;
    const float tol = kEncodeTapTolerance;
    const float coarsest = max(max(length(minor) / (kEncodeAnisotropicMinorTexels + tol),
                                   length(major) * extent / (float(kEncodeAnisotropicMaxTaps) + tol)), 1.0);
    const float lambda = log2(coarsest);
    const int top = textureQueryLevels(uSource) - 1;
    const int level = min(int(lambda), top);
    const float blend = level < top ? lambda - float(level) : 0.0;
    vec4 value = filterOnLevel(level, major, minor, extent, f);
    if (blend > 0.0) value = mix(value, filterOnLevel(level + 1, major, minor, extent, f), blend);
    fragColor = value;
}
