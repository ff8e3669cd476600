#version 450 core
// Reflections (paper section 5, Figure 6): the GLSL twin of codec::renderReflectionFrame. Each
// pixel's eye ray meets the reflector (a sphere or a square plane mirror, codec::hitReflector);
// where the reflector lies in front of the scene behind (a mesh frame of the same camera), the
// reflected ray is intersected with the six cube faces of the asset (intersect.inc.glsl, the one
// algorithm), the nearest hit that is not the far plane wins and takes the face's colour there
// (codec::reflectionColour); a ray that meets nothing shows the sky. A layered asset's faces hold
// their layers side by side in their depth and colour textures (intersect.inc.glsl), the deeper
// ones walked as codec::traceReflection walks them. Each pixel casts uSamples x uSamples rays, one
// at the centre of each cell of a regular grid over it, and averages their colours, as the CPU's
// ReflectionFrameOptions::samples does; the scene behind is drawn with one sample a ray (uSamples
// times the frame's size). Out: R, G, B and the mask M of the ray nearest the pixel's centre
// (0 the scene or nothing, 1 the reflector showing the sky, 2 the reflector showing the scene).
// Installed (<datadir>/conus/glsl); examples/reflection_gl sets its uniforms outside CoNUS.
#include "equation1.inc.glsl"
#include "intersect.inc.glsl"

const int kFaces = 6;

uniform sampler2D uDepths[kFaces];
uniform sampler2D uMaps[kFaces];
uniform sampler2D uColours[kFaces];  // R, G, B, coverage per CoNUS pixel
uniform int uLayers;                 // each face's layers (side by side in its textures)
uniform DepthView uViews[kFaces];
uniform float uFar[kFaces];          // each face's far clip (where nothing was seen)
uniform sampler2D uBehind;           // the scene: R, G, B and camera depth (huge where nothing), a texel a ray
uniform int uSamples;                // rays a pixel a side (below 1: one)
// The frame camera's rays, affine in the image point uv (computed in double precision on the
// CPU: a matrix through the near and far planes loses them in float when far / near is large):
// origin o0 + u oU + v oV, direction (unnormalized) d0 + u dU + v dV.
uniform vec3 uRayO0, uRayOU, uRayOV, uRayD0, uRayDU, uRayDV;
uniform vec3 uFrameEye, uFrameForward;  // camera depth = dot(p - eye, forward)
uniform vec2 uFrameSize;
uniform int uReflectorKind;  // 0 sphere, 1 plane
uniform vec3 uReflectorCentre;
uniform float uReflectorRadius;
uniform vec3 uReflectorNormal;  // unit
uniform vec3 uSky;
uniform float uStepTexels;
uniform int uRefinements;
uniform int uMaxSteps;
uniform float uTMax;

out vec4 outColour;

// Each face's map nodes a side, taken in main() with constant indices (equation1.inc.glsl's
// gMapNodes). The faces' depth and colour textures are all of one size (spec), so the size queries
// the includes make of uDepths[f] need no such care.
ivec2 gFaceNodes[kFaces];

// codec::hitReflector: the t along the eye ray and the unit normal facing it; t < 0 on a miss.
float hitReflector(vec3 origin, vec3 d, out vec3 normal) {
    normal = uReflectorNormal;
    if (uReflectorKind == 0) {
        const vec3 oc = origin - uReflectorCentre;
        const float b = dot(oc, d), c = dot(oc, oc) - uReflectorRadius * uReflectorRadius;
        const float disc = b * b - c;
        if (!(disc >= 0.0)) return -1.0;
        const float t = -b - sqrt(disc);
        if (!(t > 0.0)) return -1.0;
        normal = normalize(origin + d * t - uReflectorCentre);
        return t;
    }
    const vec3 n = uReflectorNormal;
    const float facing = dot(d, n);
    if (!(facing < 0.0)) return -1.0;
    const float t = dot(uReflectorCentre - origin, n) / facing;
    if (!(t > 0.0)) return -1.0;
    const vec3 p = origin + d * t - uReflectorCentre;
    const vec3 helper = abs(n.y) < 0.9 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
    const vec3 s = normalize(cross(helper, n)), u = cross(n, s);
    if (abs(dot(p, s)) > uReflectorRadius || abs(dot(p, u)) > uReflectorRadius) return -1.0;
    return t;
}

// codec::reflectionColour: the face's colour at the hit's CoNUS position, with the surface's own
// weights (a silhouette's far side weighs nothing) times coverage (the far plane's texels carry none).
vec3 reflectionColour(sampler2D depths, sampler2D colours, vec2 pd, ivec2 texel) {
    ivec2 i0, i1;
    const vec4 w = surfaceWeights(depths, pd, i0, i1);
    const vec4 c00 = texelFetch(colours, layerTexel(depths, i0), 0);
    const vec4 c10 = texelFetch(colours, layerTexel(depths, ivec2(i1.x, i0.y)), 0);
    const vec4 c01 = texelFetch(colours, layerTexel(depths, ivec2(i0.x, i1.y)), 0);
    const vec4 c11 = texelFetch(colours, layerTexel(depths, i1), 0);
    const vec4 wc = w * vec4(c00.a, c10.a, c01.a, c11.a);
    const float total = wc.x + wc.y + wc.z + wc.w;
    if (!(total > 0.0)) return texelFetch(colours, layerTexel(depths, texel), 0).rgb;
    return (c00.rgb * wc.x + c10.rgb * wc.y + c01.rgb * wc.z + c11.rgb * wc.w) / total;
}

// codec's onSky: the hit lies where face f (the layer gDepthLayer) saw nothing.
bool onSky(int f, DepthHit h) {
    return texelFetch(uColours[f], layerTexel(uDepths[f], h.texel), 0).a < 0.5 ||
           (!h.hidden && h.depth >= uFar[f] * (1.0 - 1e-4));
}

// One ray through the image point uv, the scene behind it `behind`: its colour, and its mask M.
float shadeRay(vec2 uv, vec4 behind, out vec3 colour) {
    const vec3 origin = uRayO0 + uRayOU * uv.x + uRayOV * uv.y;
    const vec3 direction = normalize(uRayD0 + uRayDU * uv.x + uRayDV * uv.y);
    colour = behind.rgb;
    vec3 normal;
    const float tMirror = hitReflector(origin, direction, normal);
    if (tMirror < 0.0) return 0.0;
    const vec3 at = origin + direction * tMirror;
    if (!(dot(at - uFrameEye, uFrameForward) < behind.a)) return 0.0;
    const vec3 reflected = normalize(direction - 2.0 * dot(direction, normal) * normal);

    // codec::traceReflection: the nearest hit among the faces that is not the far plane; a face's
    // deeper layers only where its first went hidden, short of a real first-layer hit.
    bool found = false;
    float best = uTMax;
    colour = uSky;
    gDepthLayers = uLayers;
    for (int f = 0; f < kFaces; ++f) {
        gDepthLayer = 0;
        gMapNodes = gFaceNodes[f];
        const DepthHit h = intersectDepthImage(uDepths[f], uMaps[f], uViews[f], at, reflected, uStepTexels,
                                               uRefinements, uMaxSteps, best);
        bool mine = false;
        float mineT = best;
        vec3 mineColour;
        // A hidden hit (a guess) is the single-layer face's alone: layers hold what lies behind.
        if (h.hit && !(found && h.t >= best) && !onSky(f, h) && !(h.hidden && uLayers > 1)) {
            mine = true;
            mineT = h.t;
            mineColour = reflectionColour(uDepths[f], uColours[f], h.distorted, h.texel);
        }
        // From where the ray first went behind layer 0 (codec::traceReflection).
        if (h.firstHidden < best && uLayers > 1) {
            const vec3 behindLayer = at + reflected * h.firstHidden;
            for (int k = 1; k < uLayers; ++k) {
                if (!(mineT - h.firstHidden > 0.0)) break;
                gDepthLayer = k;
                const DepthHit d = intersectBehindLayer(uDepths[f], uMaps[f], uViews[f], behindLayer, reflected, uStepTexels,
                                                        uRefinements, uMaxSteps, mineT - h.firstHidden);
                if (!d.hit || onSky(f, d)) continue;
                mine = true;
                mineT = d.t + h.firstHidden;
                mineColour = reflectionColour(uDepths[f], uColours[f], d.distorted, d.texel);
            }
        }
        if (mine) {
            found = true;
            best = mineT;
            colour = mineColour;
        }
    }
    return found ? 2.0 : 1.0;
}

void main() {
    gFaceNodes = ivec2[kFaces](textureSize(uMaps[0], 0), textureSize(uMaps[1], 0), textureSize(uMaps[2], 0),
                               textureSize(uMaps[3], 0), textureSize(uMaps[4], 0), textureSize(uMaps[5], 0));
    // GL's window row 0 is the frame's top row (the readback is top row first).
    const int n = max(uSamples, 1);
    const ivec2 pixel = ivec2(gl_FragCoord.xy);
    if (n == 1) {  // one ray through the pixel's centre, outside the loop (on llvmpipe the loop cost 1.3-1.5x)
        vec3 colour;
        const float m = shadeRay(gl_FragCoord.xy / uFrameSize, texelFetch(uBehind, pixel, 0), colour);
        outColour = vec4(colour, m);
        return;
    }
    vec3 sum = vec3(0.0);
    float mask = 0.0;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const vec2 uv = (vec2(pixel) + (vec2(i, j) + 0.5) / float(n)) / uFrameSize;
            vec3 colour;
            const float m = shadeRay(uv, texelFetch(uBehind, pixel * n + ivec2(i, j), 0), colour);
            sum += colour;
            if (i == n / 2 && j == n / 2) mask = m;
        }
    outColour = vec4(sum / float(n * n), mask);
}
