#version 450 core
// One window pixel of conus-view: the undistorted (u,v) of the pixel, then by mode the CoNUS image
// decoded there (equation1.inc.glsl, as decode.frag.glsl), the raw CoNUS image, the uniform image, a wipe of the two, or the
// sampling density det J; then the CoNUS pixel grid and focus outlines over it.
// uBottomUp flips rows for a window's default framebuffer (row 0 at the bottom); offscreen targets
// are read back top row first and need no flip.
// VIEW_MODE, VIEW_GRID and VIEW_OUTLINES are compile-time: the renderer compiles one program per
// combination, because llvmpipe runs both sides of every branch under a mask, so a run-time mode
// switch would pay for every mode's taps on every pixel (measured: 2.5 -> see view_renderer.cpp).
#ifndef VIEW_MODE
#define VIEW_MODE 0
#endif
#ifndef VIEW_GRID
#define VIEW_GRID 0
#endif
#ifndef VIEW_OUTLINES
#define VIEW_OUTLINES 0
#endif
// VIEW_OVERLAY 1: the overlays alone, premultiplied (rgb, coverage), for blending (GL_ONE,
// GL_ONE_MINUS_SRC_ALPHA) over a frame already in the target (the CPU-decoded frame on software
// GL, see view_renderer.cpp): the same result as drawing them over the frame in one pass.
#ifndef VIEW_OVERLAY
#define VIEW_OVERLAY 0
#endif
const int kMode = VIEW_MODE;  // 0 reconstructed, 1 raw, 2 uniform, 3 wipe, 4 density
const bool kGrid = VIEW_GRID != 0;
const bool kOutlines = VIEW_OUTLINES != 0;
const bool kOverlayOnly = VIEW_OVERLAY != 0;
layout(location = 0) out vec4 fragColor;
uniform sampler2D uConus;    // display channels as RGBA, bilinear, clamp to edge
uniform sampler2D uMap;      // columns x rows texels, RG32F: the distorted node positions
uniform sampler2D uUniform;  // the uniform image of the same pixel count, RGBA
uniform vec4 uView;          // u0, v0, u1, v1
uniform vec2 uOutputSize;
uniform bool uBottomUp;
uniform vec2 uGridLines;     // CoNUS pixels (or every n-th) across u and v; 0: no grid
uniform vec2 uSourceSize;    // conventional frame in pixels (focus radii are fractions of its width)
uniform int uFocusCount;
uniform vec3 uFoci[kMaxFoci];  // u, v, r
#ifdef VIEW_PLAIN_DISPLAY
// The browser page's display: exposure 1, no tone map, the sRGB curve, as constants. As uniforms,
// llvmpipe and SwiftShader evaluate every branch of display() under a mask, the plain gamma's pow
// included (the page's pan/zoom on llvmpipe: 1.35x the frames a second as constants).
const float uExposure = 1.0;
const float uInvGamma = 0.0;
const int uToneMap = 0;
#else
uniform float uExposure;     // 2^ev, applied before gamma
uniform float uInvGamma;     // 0: the sRGB curve
uniform int uToneMap;        // conus::ToneMap: 0 none, 1 reinhard, 2 aces
#endif
uniform float uWipeX;        // pixels
uniform vec2 uLogDensity;    // log density range for the heat map

#include "equation1.inc.glsl"

vec3 heat(float t) {  // kInferno, as cli/pictures.cpp draws it
    t = clamp(t, 0.0, 1.0) * float(kInferno.length() - 1);
    const int i = min(int(t), kInferno.length() - 2);
    return mix(kInferno[i], kInferno[i + 1], t - float(i));
}

// color := mix(color, c, t), and the same step on the premultiplied overlay `over`.
void paint(inout vec3 color, inout vec4 over, vec3 c, float t) {
    color = mix(color, c, t);
    over = mix(over, vec4(c, 1.0), t);
}

// Linear light to the display: exposure, tone map, then the sRGB curve (uInvGamma 0) or a plain
// gamma; the CPU path's twins are conus::exposeAndToneMap and linearToSrgbDisplay (core/display.h).
vec3 display(vec4 c) {
    vec3 x = max(c.rgb * uExposure, vec3(0.0));
    if (uToneMap == 1) x = x / (1.0 + x);
    if (uToneMap == 2) x = min((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), vec3(1.0));
    if (uInvGamma != 0.0) return pow(x, vec3(uInvGamma));
    const vec3 v = clamp(x, 0.0, 1.0);
    return mix(12.92 * v, 1.055 * pow(v, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), v));
}

void main() {
    const float row = uBottomUp ? uOutputSize.y - gl_FragCoord.y : gl_FragCoord.y;
    const vec2 pixel = vec2(gl_FragCoord.x, row);
    const vec2 extent = uView.zw - uView.xy;
    const vec2 step = extent / uOutputSize;  // signed: one pixel right / one row down
    const vec2 uv = uView.xy + pixel * step;
    const bool inside = all(greaterThanEqual(uv, vec2(0.0))) && all(lessThanEqual(uv, vec2(1.0)));
    const vec2 insideAxes = vec2(uv.x >= 0.0 && uv.x <= 1.0 ? 1.0 : 0.0, uv.y >= 0.0 && uv.y <= 1.0 ? 1.0 : 0.0);
    const vec2 astep = abs(step) * insideAxes;
    const MapPoint m = evalMap(uMap, uv);

    int mode = kMode;
    if (mode == 3) mode = gl_FragCoord.x < uWipeX ? 0 : 2;
    vec3 color = kBackground;
    vec4 over = vec4(0.0);
    if (kOverlayOnly) {
        // the frame is in the target already
    } else if (!inside && mode != 4) {
        color = kBackground;
    } else if (mode == 0) {
        // uConus holds codec::buildPyramid's levels: one trilinear tap, as the CPU path's decode.
        color = display(trilinearFiltered(uConus, m.pd, m.du * astep.x, m.dv * astep.y));
    } else if (mode == 1) {
        color = display(footprintFiltered(uConus, clamp(uv, 0.0, 1.0), vec2(astep.x, 0.0), vec2(0.0, astep.y)));
    } else if (mode == 2) {
        color = display(footprintFiltered(uUniform, clamp(uv, 0.0, 1.0), vec2(astep.x, 0.0), vec2(0.0, astep.y)));
    } else {
        const float det = m.du.x * m.dv.y - m.du.y * m.dv.x;
        const float range = uLogDensity.y - uLogDensity.x;
        color = heat(range > 1e-6 ? (log(max(det, 1e-12)) - uLogDensity.x) / range : 0.5);
        if (!inside) color *= 0.35;
    }

    // The CoNUS pixel grid: this pixel is on a line where the distorted column (row) index changes
    // between it and its right (lower) neighbour, as cli/pictures.cpp draws it.
    if (kGrid && inside) {
        const vec2 right = evalMap(uMap, uv + vec2(step.x, 0.0)).pd;
        const vec2 below = evalMap(uMap, uv + vec2(0.0, step.y)).pd;
        const vec2 lines = uGridLines;
        const bool edge = floor(m.pd.x * lines.x) != floor(right.x * lines.x) ||
                          floor(m.pd.y * lines.y) != floor(below.y * lines.y);
        if (edge) paint(color, over, vec3(1.0), 0.55);
    }
    // Focus circles at r (solid) and 2r (where the density has fallen back to the context's).
    for (int k = 0; kOutlines && k < uFocusCount; ++k) {
        const vec2 d = (uv - uFoci[k].xy) * uSourceSize;
        const float radius = uFoci[k].z * uSourceSize.x, dist = length(d);
        const float pixelSize = abs(step.x) * uSourceSize.x;
        if (abs(dist - radius) < 0.75 * pixelSize) paint(color, over, vec3(0.2, 1.0, 0.4), 1.0);
        else if (abs(dist - 2.0 * radius) < 0.6 * pixelSize) paint(color, over, vec3(0.2, 1.0, 0.4), 0.5);
    }
    if (kMode == 3 && abs(gl_FragCoord.x - uWipeX) < 1.0) color = vec3(1.0);
    fragColor = kOverlayOnly ? over : vec4(color, 1.0);
}
