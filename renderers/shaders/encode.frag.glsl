#version 450 core
// One CoNUS pixel: a box filter over its footprint in the source, as codec::encodeImage does.
// The footprint's edges are the screen-space derivatives of the undistorted coordinate (the local
// inverse Jacobian over one pixel); up to kMaxTaps x kMaxTaps bilinear taps cover it, on the
// first pyramid level where it is at most kMaxTaps texels long.
in vec2 vUndistorted;
layout(location = 0) out vec4 fragColor;
uniform sampler2D uLevel0;   // the source, bilinear, clamp to edge
uniform sampler2D uPyramid;  // levels 1.. side by side (pyramid.frag.glsl), bilinear
uniform int uLevels;
uniform ivec4 uLevelRect[32];  // per level >= 1: x, y offset in uPyramid, width, height

const int kMaxTaps = 4;
// As in the CPU encoder: a footprint of 4.0005 texels is still 4 taps (float map nodes).
const float kTapTolerance = 1e-3;

// Bilinear at normalized q on a pyramid level, clamped to that level's edge: coordinates stay
// between its edge texel centres, so the atlas neighbours never bleed in.
vec4 tap(vec2 q, int level) {
    if (level == 0) return textureLod(uLevel0, q, 0.0);
    const ivec4 rect = uLevelRect[level];
    const vec2 texel = clamp(q * vec2(rect.zw) - 0.5, vec2(0.0), vec2(rect.zw - 1));
    return textureLod(uPyramid, (vec2(rect.xy) + texel + 0.5) / vec2(textureSize(uPyramid, 0)), 0.0);
}

void main() {
    const vec2 p = vUndistorted;
    const vec2 da = dFdx(p), db = dFdy(p);  // normalized source units per CoNUS pixel
    const vec2 size0 = vec2(textureSize(uLevel0, 0));
    const vec2 a = da * size0, b = db * size0;  // in level-0 texels
    int level = 0;
    float la = length(a), lb = length(b);
    while (max(la, lb) > float(kMaxTaps) + kTapTolerance && level + 1 < uLevels) {
        ++level;
        const vec2 s = vec2(uLevelRect[level].zw) / size0;
        la = length(a * s);
        lb = length(b * s);
    }
    const int na = clamp(int(ceil(la - kTapTolerance)), 1, kMaxTaps);
    const int nb = clamp(int(ceil(lb - kTapTolerance)), 1, kMaxTaps);
    vec4 sum = vec4(0.0);
    for (int j = 0; j < nb; ++j) {
        const vec2 q = p + db * ((float(j) + 0.5) / float(nb) - 0.5);
        for (int i = 0; i < na; ++i) sum += tap(q + da * ((float(i) + 0.5) / float(na) - 0.5), level);
    }
    fragColor = sum / float(na * nb);
}
