// A world point through the flexible pinhole camera, as every mesh vertex goes (paper section 3.2,
// "Geometry data"): the camera projects it to (u, v) and depth, Equation 1 moves (u, v) to its
// distorted position. Outside [0,1]^2 the map is continued by translation (the edge node's
// displacement plus the overshoot), so triangles that leave the frame keep their shape; a point at
// or behind the eye (w <= 0) has no image position and passes undistorted, to be clipped at the
// near plane. Needs equation1.inc.glsl.
uniform mat4 uWorldToNdc;     // Camera::worldToNdcMatrix: (u, v) = xy / w, z / w from 0 (near) to 1 (far)
uniform sampler2D uMap;       // the map's nodes (RG32F), read exactly by evalMap

// The distorted (u, v) of a point with ndc.w > 0.
vec2 distortedUv(vec4 ndc) {
    const vec2 uv = ndc.xy / ndc.w;
    const vec2 inside = clamp(uv, 0.0, 1.0);
    return evalMap(uMap, inside).pd + (uv - inside);
}

// GL's clip position of a world point: NDC [0,1] to clip space [-1,1], keeping w for
// perspective-correct interpolation. v stays GL's row index, so row 0 of the framebuffer is the
// image's top row.
vec4 fpcClipPosition(vec3 world) {
    const vec4 ndc = uWorldToNdc * vec4(world, 1.0);
    const vec2 position = ndc.w > 0.0 ? distortedUv(ndc) * ndc.w : ndc.xy;  // distorted, times w
    return vec4(2.0 * position - ndc.w, 2.0 * ndc.z - ndc.w, ndc.w);
}
