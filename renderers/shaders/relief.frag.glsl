#version 450 core
// Relief texture mapping (paper section 5, Figure 2): each pixel's eye ray is intersected with the
// asset's CoNUS height texture (intersect.inc.glsl); the hit takes the stored colour, lit by one
// directional light through the surface's normal, and, with shadows on, a second ray toward the
// light decides whether the hit sees it.
#include "equation1.inc.glsl"
#include "intersect.inc.glsl"

uniform sampler2D uDepths;
uniform sampler2D uMap;
uniform sampler2D uColour;
uniform DepthView uView;
uniform mat4 uFrameNdcToWorld;  // the frame camera's NDC -> world
uniform vec2 uFrameSize;
uniform vec3 uBackground;
uniform vec3 uTowardLight;  // unit
uniform float uAmbient;
uniform bool uShadows;
uniform float uStepTexels;
uniform int uRefinements;
uniform int uMaxSteps;

out vec4 outColour;

vec3 worldAt(vec2 uv, float ndcZ) {
    const vec4 p = uFrameNdcToWorld * vec4(uv, ndcZ, 1.0);
    return p.xyz / p.w;
}

// The stored surface's world point at undistorted image point p.
vec3 surfaceAt(vec2 p) { return unprojectDepth(uView, p, sampleDepth(uDepths, uView, evalMap(uMap, p).pd)); }

void main() {
    // GL's window row 0 is the frame's top row (the readback is top row first).
    const vec2 uv = gl_FragCoord.xy / uFrameSize;
    const vec3 origin = worldAt(uv, 0.0), direction = normalize(worldAt(uv, 1.0) - origin);
    const DepthHit h = intersectDepthImage(uDepths, uMap, uView, origin, direction, uStepTexels, uRefinements,
                                           uMaxSteps, 1e30);
    if (!h.hit) {
        outColour = vec4(uBackground, 1.0);
        return;
    }
    vec3 normal;
    if (h.face >= 0) {
        normal = clipFaceNormal(uView, h.face);
    } else {
        // Differences over about one CoNUS pixel in each direction, wherever the map puts it:
        // magnified regions shade their finer detail.
        const MapPoint m = evalMap(uMap, h.point);
        const vec2 size = vec2(textureSize(uDepths, 0));
        const float eu = 1.0 / max(length(m.du * size), 1e-3), ev = 1.0 / max(length(m.dv * size), 1e-3);
        const vec3 du = surfaceAt(h.point + vec2(eu, 0.0)) - surfaceAt(h.point - vec2(eu, 0.0));
        const vec3 dv = surfaceAt(h.point + vec2(0.0, ev)) - surfaceAt(h.point - vec2(0.0, ev));
        normal = normalize(cross(du, dv));
    }
    if (dot(normal, direction) > 0.0) normal = -normal;
    float light = max(dot(normal, uTowardLight), 0.0);
    if (uShadows && light > 0.0) {
        const float lift = 1e-3 * (1.0 + abs(uView.maxDepth - uView.minDepth));
        const DepthHit blocker = intersectDepthImage(uDepths, uMap, uView, h.position + normal * lift, uTowardLight,
                                                     uStepTexels, uRefinements, uMaxSteps, 1e30);
        if (blocker.hit) light = 0.0;
    }
    const vec3 colour = textureLod(uColour, h.distorted, 0.0).rgb;
    outColour = vec4(colour * (uAmbient + (1.0 - uAmbient) * light), 1.0);
}
