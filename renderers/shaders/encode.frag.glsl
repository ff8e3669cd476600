#version 450 core
// One CoNUS pixel, filtered as codec::encodeImage does (encode.h states the rule): the footprint's
// edges a and b come from the mesh (codec::FootprintField, interpolated); the filter is the unit box
// in CoNUS pixel units convolved with a Gaussian along the footprint's major axis that grows with
// its anisotropy and with how far that axis outspans the uniform image's pixel; taps at most a texel apart along each edge, on a continuous pyramid level (the
// two levels around it blended) where the minor axis is at most kEncodeMaxTaps texels and the
// filter at most kEncodeMaxAxisTaps texels along each edge.
//
// Tiling (sources over the texture limit): the textures may hold only a crop of each level (the
// tile's core plus a margin that covers every tap), placed by uLevelRect; the pixels whose
// undistorted centre lies outside the tile's core (uCore) are left to the other tiles.
in vec2 vUndistorted;
in vec4 vFootprint;
layout(location = 0) out vec4 fragColor;
uniform sampler2D uLevel0;   // level 0: the source or a crop of it, bilinear, clamp to edge
uniform sampler2D uPyramid;  // levels 1.. (or crops of them) side by side (pyramid.frag.glsl), bilinear
uniform int uLevels;
// Per level: x, y = where the full level's texel (0, 0) sits in its texture (uLevel0 for level 0,
// uPyramid for the others; negative for a crop that starts inside the level); z, w = the full
// level's width and height.
uniform ivec4 uLevelRect[32];
// u0, v0, u1, v1: only pixels with the undistorted centre in [u0, u1) x [v0, v1) are drawn.
uniform vec4 uCore;
// The uniform image's pixel in level-0 source pixels (codec::uniformSpacing).
uniform float uUniform;

// Bilinear at normalized q on a pyramid level, clamped to that level's edge: coordinates stay
// between its edge texel centres, so the atlas neighbours never bleed in.
vec4 tap(vec2 q, int level) {
    const ivec4 rect = uLevelRect[level];
    const vec2 texel = clamp(q * vec2(rect.zw) - 0.5, vec2(0.0), vec2(rect.zw - 1));
    const vec2 at = vec2(rect.xy) + texel + 0.5;
    if (level == 0) return textureLod(uLevel0, at / vec2(textureSize(uLevel0, 0)), 0.0);
    return textureLod(uPyramid, at / vec2(textureSize(uPyramid, 0)), 0.0);
}

#include "encode_footprint.inc.glsl"

// Narrows [lo, hi] to the offsets o for which |x - o * d| <= 0.5; false when none is left.
bool slab(float x, float d, inout float lo, inout float hi) {
    if (abs(d) < 1e-9) return abs(x) <= 0.5;
    const float o1 = (x - 0.5) / d, o2 = (x + 0.5) / d;
    lo = max(lo, min(o1, o2));
    hi = min(hi, max(o1, o2));
    return hi > lo;
}

// The filter's weight at (s,t) in CoNUS pixels: the Gaussian's mass (std sigma along the unit
// direction major, cut at +-reach) over the offsets that keep (s,t) - o * major in the unit box.
float filterWeight(float s, float t, float sigma, vec2 major, float reach) {
    if (sigma < 1e-4) return abs(s) <= 0.5 && abs(t) <= 0.5 ? 1.0 : 0.0;
    float lo = -reach, hi = reach;
    if (!slab(s, major.x, lo, hi) || !slab(t, major.y, lo, hi)) return 0.0;
    const float k = 1.0 / (sqrt(2.0) * sigma);
    return 0.5 * (erfApprox(hi * k) - erfApprox(lo * k));
}

// The normalized filtered value on one level.
vec4 filterOnLevel(int level, vec2 p, vec2 a, vec2 b, float sigma, vec2 major, float reach, vec2 extent) {
    const vec2 scale = vec2(uLevelRect[level].zw) / vec2(uLevelRect[0].zw);
    const vec2 aL = a * scale, bL = b * scale;
    const int ns = clamp(int(ceil(length(aL) * extent.x - kEncodeTapTolerance)), 1, 2 * kEncodeMaxAxisTaps);
    const int nt = clamp(int(ceil(length(bL) * extent.y - kEncodeTapTolerance)), 1, 2 * kEncodeMaxAxisTaps);
    // Normalized source units per unit of s and t.
    const vec2 da = a / vec2(uLevelRect[0].zw), db = b / vec2(uLevelRect[0].zw);
    vec4 sum = vec4(0.0);
    float total = 0.0;
    for (int j = 0; j < nt; ++j) {
        const float t = ((float(j) + 0.5) / float(nt) - 0.5) * extent.y;
        for (int i = 0; i < ns; ++i) {
            const float s = ((float(i) + 0.5) / float(ns) - 0.5) * extent.x;
            const float w = filterWeight(s, t, sigma, major, reach);
            if (w <= 0.0) continue;
            total += w;
            sum += w * tap(p + da * s + db * t, level);
        }
    }
    return total > 0.0 ? sum / total : vec4(0.0);
}

void main() {
    const vec2 p = vUndistorted;
    if (any(lessThan(p, uCore.xy)) || any(greaterThanEqual(p, uCore.zw))) discard;
    const vec2 size0 = vec2(uLevelRect[0].zw);
    const vec2 a = vFootprint.xy * size0, b = vFootprint.zw * size0;  // in level-0 texels
    const FootprintFilter f = footprintFilter(a, b, uUniform);
    const float minor = f.minor, sigma = f.sigma, reach = f.reach;
    const vec2 major = f.major;
    const vec2 extent = vec2(1.0) + 2.0 * reach * abs(major);
    const float tol = kEncodeTapTolerance;
    const float coarsest = max(max(minor / (float(kEncodeMaxTaps) + tol), 1.0),
                               max(length(a) * extent.x, length(b) * extent.y) / (float(kEncodeMaxAxisTaps) + tol));
    const float lambda = log2(coarsest);
    const int top = uLevels - 1;
    const int level = min(int(lambda), top);
    const float blend = level < top ? lambda - float(level) : 0.0;
    vec4 value = filterOnLevel(level, p, a, b, sigma, major, reach, extent);
    if (blend > 0.0) value = mix(value, filterOnLevel(level + 1, p, a, b, sigma, major, reach, extent), blend);
    fragColor = value;
}
