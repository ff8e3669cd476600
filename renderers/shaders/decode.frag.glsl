#version 450 core
// One output pixel of a view: its undistorted (u,v), distorted by Equation 1 from the map's nodes
// (bilinear interpolation of the four nodes of its cell, fetched exactly), then the CoNUS image
// sampled bilinearly there, as codec::decodeImage does. Where the pixel's footprint in the CoNUS
// image is longer than kMultiTap pixels (zoomed out, or inside a focus) several taps are averaged.
// Window y is the output's row index (images travel top row first), so no flip.
layout(location = 0) out vec4 fragColor;
uniform sampler2D uConus;  // bilinear, clamp to edge
uniform sampler2D uMap;    // columns x rows texels, RG32F: the distorted node positions
uniform vec4 uView;        // u0, v0, u1, v1
uniform vec2 uOutputSize;

const float kMultiTap = 1.5;
const int kMaxTaps = 8;

int taps(float len) { return len <= kMultiTap ? 1 : min(kMaxTaps, int(ceil(len))); }

void main() {
    const vec2 uv = uView.xy + gl_FragCoord.xy / uOutputSize * (uView.zw - uView.xy);
    // Outside the image: the background, as codec::decodeImage gives it.
    if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) {
        fragColor = vec4(0.0);
        return;
    }
    // Outside [0,1] Eq. 1 clamps: the point no longer moves with that coordinate.
    const vec2 inside = vec2(uv.x >= 0.0 && uv.x <= 1.0 ? 1.0 : 0.0, uv.y >= 0.0 && uv.y <= 1.0 ? 1.0 : 0.0);
    const ivec2 nodes = textureSize(uMap, 0);
    const vec2 cells = vec2(nodes - 1);
    const vec2 g = clamp(uv, 0.0, 1.0) * cells;
    const ivec2 c = clamp(ivec2(g), ivec2(0), nodes - 2);
    const vec2 st = g - vec2(c);
    const vec2 n00 = texelFetch(uMap, c, 0).xy;
    const vec2 n10 = texelFetch(uMap, c + ivec2(1, 0), 0).xy;
    const vec2 n01 = texelFetch(uMap, c + ivec2(0, 1), 0).xy;
    const vec2 n11 = texelFetch(uMap, c + ivec2(1, 1), 0).xy;
    // Along v first, then u, like the CPU decoder's row stepping.
    const vec2 left = mix(n00, n01, st.y), right = mix(n10, n11, st.y);
    const vec2 pd = mix(left, right, st.x);

    // The output pixel's edges carried into the CoNUS image, in CoNUS pixels.
    const vec2 conusSize = vec2(textureSize(uConus, 0));
    const vec2 step = abs(uView.zw - uView.xy) / uOutputSize;
    const vec2 a = (right - left) * (cells.x * step.x * inside.x) * conusSize;
    const vec2 b = mix(n01 - n00, n11 - n10, st.x) * (cells.y * step.y * inside.y) * conusSize;
    const int na = taps(length(a)), nb = taps(length(b));
    if (na == 1 && nb == 1) {
        fragColor = textureLod(uConus, pd, 0.0);
        return;
    }
    const vec2 an = a / conusSize, bn = b / conusSize;
    vec4 sum = vec4(0.0);
    for (int j = 0; j < nb; ++j) {
        const vec2 q = pd + bn * ((float(j) + 0.5) / float(nb) - 0.5);
        for (int i = 0; i < na; ++i)
            sum += textureLod(uConus, clamp(q + an * ((float(i) + 0.5) / float(na) - 0.5), 0.0, 1.0), 0.0);
    }
    fragColor = sum / float(na * nb);
}
