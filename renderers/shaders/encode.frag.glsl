#version 450 core
// One CoNUS pixel: a box filter over its footprint in the source, as codec::encodeImage does.
// The footprint's edges are the screen-space derivatives of the undistorted coordinate (the local
// inverse Jacobian over one pixel); up to kEncodeMaxTaps x kEncodeMaxTaps bilinear taps cover it, on the
// first pyramid level where it is at most kEncodeMaxTaps texels long.
//
// Tiling (sources over the texture limit): the textures may hold only a crop of each level (the
// tile's core plus a margin that covers every tap), placed by uLevelRect; the pixels whose
// undistorted centre lies outside the tile's core (uCore) are left to the other tiles.
in vec2 vUndistorted;
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

// Bilinear at normalized q on a pyramid level, clamped to that level's edge: coordinates stay
// between its edge texel centres, so the atlas neighbours never bleed in.
vec4 tap(vec2 q, int level) {
    const ivec4 rect = uLevelRect[level];
    const vec2 texel = clamp(q * vec2(rect.zw) - 0.5, vec2(0.0), vec2(rect.zw - 1));
    const vec2 at = vec2(rect.xy) + texel + 0.5;
    if (level == 0) return textureLod(uLevel0, at / vec2(textureSize(uLevel0, 0)), 0.0);
    return textureLod(uPyramid, at / vec2(textureSize(uPyramid, 0)), 0.0);
}

void main() {
    const vec2 p = vUndistorted;
    const vec2 da = dFdx(p), db = dFdy(p);  // normalized source units per CoNUS pixel
    if (any(lessThan(p, uCore.xy)) || any(greaterThanEqual(p, uCore.zw))) discard;
    const vec2 size0 = vec2(uLevelRect[0].zw);
    const vec2 a = da * size0, b = db * size0;  // in level-0 texels
    int level = 0;
    float la = length(a), lb = length(b);
    while (max(la, lb) > float(kEncodeMaxTaps) + kEncodeTapTolerance && level + 1 < uLevels) {
        ++level;
        const vec2 s = vec2(uLevelRect[level].zw) / size0;
        la = length(a * s);
        lb = length(b * s);
    }
    const int na = clamp(int(ceil(la - kEncodeTapTolerance)), 1, kEncodeMaxTaps);
    const int nb = clamp(int(ceil(lb - kEncodeTapTolerance)), 1, kEncodeMaxTaps);
    vec4 sum = vec4(0.0);
    for (int j = 0; j < nb; ++j) {
        const vec2 q = p + db * ((float(j) + 0.5) / float(nb) - 0.5);
        for (int i = 0; i < na; ++i) sum += tap(q + da * ((float(i) + 0.5) / float(na) - 0.5), level);
    }
    fragColor = sum / float(na * nb);
}
