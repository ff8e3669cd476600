#version 450 core
// A mesh vertex through the flexible pinhole camera (paper section 3.2, "Geometry data"): the
// camera projects it to (u, v) and depth, Equation 1 moves (u, v) to its distorted position, and
// the rasterizer connects the distorted vertices with straight edges (hence --max-edge).
// Outside [0,1]^2 the map is continued by translation (the edge node's displacement plus the
// overshoot), so triangles that leave the frame keep their shape; a vertex at or behind the eye
// (w <= 0) has no image position and passes undistorted, to be clipped at the near plane.
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in vec3 aColour;
layout(location = 3) in vec2 aUv;
uniform mat4 uWorldToNdc;     // Camera::worldToNdcMatrix: (u, v) = xy / w, z / w from 0 (near) to 1 (far)
uniform vec4 uDepthRow;       // camera depth = dot(uDepthRow, (p, 1)): worldToCamera's z row
uniform sampler2D uMap;       // the map's nodes (RG32F), read exactly by evalMap
out vec3 vWorld;
out vec3 vNormal;
out vec3 vColour;
out vec2 vUv;
out float vDepth;

#include "equation1.inc.glsl"

void main() {
    const vec4 p = vec4(aPosition, 1.0);
    vWorld = aPosition;
    vNormal = aNormal;
    vColour = aColour;
    vUv = aUv;
    vDepth = dot(uDepthRow, p);
    const vec4 ndc = uWorldToNdc * p;
    vec2 position = ndc.xy;  // undistorted, times w
    if (ndc.w > 0.0) {
        const vec2 uv = ndc.xy / ndc.w;
        const vec2 inside = clamp(uv, 0.0, 1.0);
        position = (evalMap(uMap, inside).pd + (uv - inside)) * ndc.w;
    }
    // NDC [0,1] to GL's clip space [-1,1], keeping w for perspective-correct interpolation. v stays
    // GL's row index, so row 0 of the framebuffer is the image's top row.
    gl_Position = vec4(2.0 * position - ndc.w, 2.0 * ndc.z - ndc.w, ndc.w);
}
