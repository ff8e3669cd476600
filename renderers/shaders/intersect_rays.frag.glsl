#version 450 core
// One ray per fragment through the shared intersection (intersect.inc.glsl): the GLSL twin of
// codec::intersect under test. Rays come in two RGBA32F textures laid out row by row; each of the
// four outputs holds part of the hit.
#include "equation1.inc.glsl"
#include "intersect.inc.glsl"

uniform sampler2D uDepths;
uniform sampler2D uMap;
uniform sampler2D uOrigins;
uniform sampler2D uDirections;
uniform DepthView uView;
uniform float uStepTexels;
uniform int uRefinements;
uniform int uMaxSteps;
uniform float uTMax;

layout(location = 0) out vec4 outHit;       // hit, t, depth, steps
layout(location = 1) out vec4 outPosition;  // position, face
layout(location = 2) out vec4 outPoints;    // point, distorted
layout(location = 3) out vec4 outTexel;     // texel, hidden

void main() {
    const ivec2 at = ivec2(gl_FragCoord.xy);
    const vec3 origin = texelFetch(uOrigins, at, 0).xyz, direction = texelFetch(uDirections, at, 0).xyz;
    const DepthHit h = intersectDepthImage(uDepths, uMap, uView, origin, direction, uStepTexels, uRefinements,
                                           uMaxSteps, uTMax);
    outHit = vec4(h.hit ? 1.0 : 0.0, h.t, h.depth, float(h.steps));
    outPosition = vec4(h.position, float(h.face));
    outPoints = vec4(h.point, h.distorted);
    outTexel = vec4(vec2(h.texel), h.hidden ? 1.0 : 0.0, 0.0);
}
