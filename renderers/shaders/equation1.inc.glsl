// Equation 1 in GLSL, the one copy every shader includes (#include "equation1.inc.glsl", resolved
// when the shaders are embedded): the distorted position of undistorted uv, bilinear in the four
// nodes of its cell fetched exactly (texelFetch and manual weights, not the sampler's), along v
// first and then u as codec's row stepping does, with its partial derivatives. Outside [0,1] the
// point is clamped to the edge, as SamplingMap::distort does. And the decoder's footprint filter:
// bilinear taps over a pixel's footprint, as many as codec::decodeImage takes; or, with a mipmapped
// texture, one trilinear tap at the level codec's pyramid decode chooses. The constants it reads
// (kDecodeMultiTap, kDecodeMaxTaps, kDecodePyramidBias) are declared before it from C++
// (codec::glslConstants). Installed with intersect.inc.glsl (<datadir>/conus/glsl).
struct MapPoint {
    vec2 pd;  // distorted position
    vec2 du;  // d pd / du
    vec2 dv;  // d pd / dv
};

// The map's nodes a side where the caller sets them, else (0, 0): the texture's size. A shader
// that picks the map from a sampler array by a variable index sets them from sizes taken with
// constant indices (reflection.frag.glsl): llvmpipe (Mesa 22.3) answers such a size query with
// another element's size in invocations beside ones that have returned.
ivec2 gMapNodes = ivec2(0);

MapPoint evalMap(sampler2D map, vec2 uv) {
    const ivec2 nodes = gMapNodes.x > 0 ? gMapNodes : textureSize(map, 0);
    const vec2 cells = vec2(nodes - 1);
    const vec2 g = clamp(uv, 0.0, 1.0) * cells;
    const ivec2 c = clamp(ivec2(g), ivec2(0), nodes - 2);
    const vec2 st = g - vec2(c);
    const vec2 n00 = texelFetch(map, c, 0).xy;
    const vec2 n10 = texelFetch(map, c + ivec2(1, 0), 0).xy;
    const vec2 n01 = texelFetch(map, c + ivec2(0, 1), 0).xy;
    const vec2 n11 = texelFetch(map, c + ivec2(1, 1), 0).xy;
    const vec2 left = mix(n00, n01, st.y), right = mix(n10, n11, st.y);
    MapPoint p;
    p.pd = mix(left, right, st.x);
    p.du = (right - left) * cells.x;
    p.dv = mix(n01 - n00, n11 - n10, st.x) * cells.y;
    return p;
}

// Taps along a footprint axis `len` CoNUS pixels long (codec/decode.h's rule).
int footprintTaps(float len) { return len <= kDecodeMultiTap ? 1 : min(kDecodeMaxTaps, int(ceil(len))); }

// Bilinear taps over the footprint with edges a, b (normalized texture units) centred at q.
vec4 footprintFiltered(sampler2D tex, vec2 q, vec2 a, vec2 b) {
    const vec2 size = vec2(textureSize(tex, 0));
    const int na = footprintTaps(length(a * size)), nb = footprintTaps(length(b * size));
    if (na == 1 && nb == 1) return textureLod(tex, q, 0.0);
    vec4 sum = vec4(0.0);
    for (int j = 0; j < nb; ++j) {
        const vec2 r = q + b * ((float(j) + 0.5) / float(nb) - 0.5);
        for (int i = 0; i < na; ++i)
            sum += textureLod(tex, clamp(r + a * ((float(i) + 0.5) / float(na) - 0.5), 0.0, 1.0), 0.0);
    }
    return sum / float(na * nb);
}

// The pyramid's level of detail, codec::pyramidLevel's formula: lambda = log2(rho) - bias (at
// least 0) for rho^2, the squared longer footprint edge in CoNUS pixels, with log2 by a quadratic
// in the mantissa.
float pyramidLevel(float rhoSquared) {
    if (!(rhoSquared > 1.0)) return 0.0;
    const uint bits = floatBitsToUint(rhoSquared);
    const float t = uintBitsToFloat((bits & 0x7fffffu) | 0x3f800000u) - 1.0;
    return max(0.0, 0.5 * (float(int(bits >> 23) - 127) + t * (1.3465553 - 0.3465553 * t)) - kDecodePyramidBias);
}

// One trilinear tap of a mipmapped texture (the levels codec::buildPyramid makes) over the
// footprint with edges a, b (normalized texture units) centred at q: codec's pyramid decode.
vec4 trilinearFiltered(sampler2D tex, vec2 q, vec2 a, vec2 b) {
    const vec2 size = vec2(textureSize(tex, 0));
    const vec2 ap = a * size, bp = b * size;
    return textureLod(tex, q, pyramidLevel(max(dot(ap, ap), dot(bp, bp))));
}
