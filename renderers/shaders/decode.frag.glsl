#version 450 core
// One output pixel of a view: its undistorted (u,v), distorted by Equation 1 from the map's nodes,
// then the CoNUS image sampled bilinearly there, as codec::decodeImage does. Where the pixel's
// footprint in the CoNUS image is longer than kDecodeMultiTap pixels (zoomed out, or inside a
// focus) several taps are averaged. Window y is the output's row index (images travel top row
// first), so no flip. DECODE_PYRAMID 1 (defined by the renderer): uConus is mipmapped with
// codec::buildPyramid's levels and a zoomed-out pixel takes one trilinear tap instead.
#ifndef DECODE_PYRAMID
#define DECODE_PYRAMID 0
#endif
layout(location = 0) out vec4 fragColor;
uniform sampler2D uConus;  // bilinear, clamp to edge
uniform sampler2D uMap;    // columns x rows texels, RG32F: the distorted node positions
uniform vec4 uView;        // u0, v0, u1, v1
uniform vec2 uOutputSize;

#include "equation1.inc.glsl"

void main() {
    const vec2 uv = uView.xy + gl_FragCoord.xy / uOutputSize * (uView.zw - uView.xy);
    // Outside the image: the background, as codec::decodeImage gives it.
    if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) {
        fragColor = vec4(0.0);
        return;
    }
    const MapPoint m = evalMap(uMap, uv);
    // The output pixel's edges carried into the CoNUS image (normalized units).
    const vec2 step = abs(uView.zw - uView.xy) / uOutputSize;
#if DECODE_PYRAMID
    fragColor = trilinearFiltered(uConus, m.pd, m.du * step.x, m.dv * step.y);
#else
    fragColor = footprintFiltered(uConus, m.pd, m.du * step.x, m.dv * step.y);
#endif
}
