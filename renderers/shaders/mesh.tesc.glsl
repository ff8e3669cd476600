#version 450 core
// How finely a triangle is split so that its picture follows Equation 1 (paper section 3.2: the
// rasterizer draws straight edges and affine insides between distorted vertices, while the map
// bends both). The error of a straight piece is measured as the rasterizer makes it: the distorted
// position in pixels times w, H, is what perspective-correct interpolation treats as linear in the
// triangle's (world) barycentric coordinates, so a piece of parameter length h strays from the
// picture by about |H''| h^2 / (8 w) pixels. H'' comes from second differences of H sampled along
// each edge and over a lattice inside; each edge and the inside get the fewest equal segments that
// keep the error within uMaxBend pixels (up to kMeshMaxTessLevel). An edge's level depends on its
// two ends only, taken in one order, and its arithmetic is `precise`, so the two triangles that
// share it split it alike: no cracks.
// Edges with an end at or in front of a perspective camera's near plane are not split, nor the
// insides of triangles with such a corner (the rasterizer clips them; Equation 1 has no position
// for a point behind the eye).
layout(vertices = 3) out;
in vec3 pWorld[];
in vec3 pNormal[];
in vec3 pColour[];
in vec2 pUv[];
out vec3 tWorld[];
out vec3 tNormal[];
out vec3 tColour[];
out vec2 tUv[];
uniform vec2 uPixels;    // the frame's width and height
uniform float uMaxBend;  // pixels
uniform bool uPerspective;

#include "equation1.inc.glsl"
#include "mesh_project.inc.glsl"

const int kEdgeSamples = 64;            // intervals along an edge, at most (one every 4 pixels below that)
const int kInsideSamples = 16;          // lattice intervals a side inside, at most (one every 8 pixels)
const float kPixelsPerEdgeSample = 4.0, kPixelsPerInsideSample = 8.0;

vec3 lattice[(kInsideSamples + 1) * (kInsideSamples + 2) / 2];

// H (xy) and w (z) of a world point.
vec3 homogeneousPixels(vec3 world) {
    precise const vec4 ndc = uWorldToNdc * vec4(world, 1.0);
    precise const vec3 h = vec3(distortedUv(ndc) * uPixels * ndc.w, ndc.w);
    return h;
}

bool measurable(vec3 world) {
    const vec4 ndc = uWorldToNdc * vec4(world, 1.0);
    return ndc.w > 0.0 && (!uPerspective || ndc.z >= 0.0);
}

// Equal segments that keep the error within uMaxBend, from the largest |second difference| / w
// of samples `intervals` to the unit parameter.
float segmentsFor(float secondDifference, int intervals) {
    if (!(secondDifference > 0.0)) return 1.0;
    return clamp(ceil(float(intervals) * sqrt(secondDifference / (8.0 * uMaxBend))), 1.0, kMeshMaxTessLevel);
}

float edgeLevel(vec3 a, vec3 b) {
    if (!measurable(a) || !measurable(b)) return 1.0;
    if (a.x > b.x || (a.x == b.x && (a.y > b.y || (a.y == b.y && a.z > b.z)))) {
        const vec3 t = a;
        a = b;
        b = t;
    }
    precise const vec3 ha = homogeneousPixels(a), hb = homogeneousPixels(b);
    precise const float span = distance(ha.xy / ha.z, hb.xy / hb.z);
    const int intervals = int(clamp(ceil(span / kPixelsPerEdgeSample), 2.0, float(kEdgeSamples)));
    precise float worst = 0.0;
    precise vec3 previous = ha, current = homogeneousPixels(mix(a, b, 1.0 / float(intervals)));
    for (int j = 1; j < intervals; ++j) {
        precise const vec3 next = j + 1 == intervals ? hb : homogeneousPixels(mix(a, b, float(j + 1) / float(intervals)));
        worst = max(worst, length(previous.xy - 2.0 * current.xy + next.xy) / current.z);
        previous = current;
        current = next;
    }
    return segmentsFor(worst, intervals);
}

// The lattice point (i, j, m - i - j) / m of the triangle, row i first.
int latticeIndex(int i, int j, int m) { return i * (m + 1) - i * (i - 1) / 2 + j; }

float insideLevel(float longestEdge) {
    const int m = int(clamp(ceil(longestEdge / kPixelsPerInsideSample), 2.0, float(kInsideSamples)));
    for (int i = 0; i <= m; ++i)
        for (int j = 0; j <= m - i; ++j)
            lattice[latticeIndex(i, j, m)] =
                homogeneousPixels((float(i) * pWorld[0] + float(j) * pWorld[1] + float(m - i - j) * pWorld[2]) / float(m));
    float worst = 0.0;
    for (int i = 0; i <= m; ++i)
        for (int j = 0; j <= m - i; ++j) {
            const vec3 h = lattice[latticeIndex(i, j, m)];
            const vec2 twice = 2.0 * h.xy;
            if (i > 0 && i + j < m)  // along i (k changes)
                worst = max(worst, length(lattice[latticeIndex(i - 1, j, m)].xy - twice + lattice[latticeIndex(i + 1, j, m)].xy) / h.z);
            if (j > 0 && i + j < m)  // along j
                worst = max(worst, length(lattice[latticeIndex(i, j - 1, m)].xy - twice + lattice[latticeIndex(i, j + 1, m)].xy) / h.z);
            if (i > 0 && j > 0)  // along i - j (k fixed)
                worst = max(worst, length(lattice[latticeIndex(i - 1, j + 1, m)].xy - twice + lattice[latticeIndex(i + 1, j - 1, m)].xy) / h.z);
        }
    return segmentsFor(worst, m);
}

// Whether the three corners lie beyond one plane of the view volume (0 <= x, y, z <= w in the
// projection's clip coordinates), so the whole triangle does. Equation 1 keeps the frame's edges
// on themselves (spec V10) and mesh_project continues the map outside by translation, so nothing
// beyond a side before the map lands inside after it: the patch is dropped before it is split.
bool outsideTheFrustum() {
    ivec3 below = ivec3(0), above = ivec3(0);  // corners beyond each plane
    for (int k = 0; k < 3; ++k) {
        const vec4 c = uWorldToNdc * vec4(pWorld[k], 1.0);
        below += ivec3(lessThan(c.xyz, vec3(0.0)));
        above += ivec3(greaterThan(c.xyz, vec3(c.w)));
    }
    return any(equal(below, ivec3(3))) || any(equal(above, ivec3(3)));
}

void main() {
    tWorld[gl_InvocationID] = pWorld[gl_InvocationID];
    tNormal[gl_InvocationID] = pNormal[gl_InvocationID];
    tColour[gl_InvocationID] = pColour[gl_InvocationID];
    tUv[gl_InvocationID] = pUv[gl_InvocationID];
    if (gl_InvocationID != 0) return;
    if (outsideTheFrustum()) {
        gl_TessLevelOuter[0] = gl_TessLevelOuter[1] = gl_TessLevelOuter[2] = 0.0;
        gl_TessLevelInner[0] = 0.0;
        return;
    }
    // Outer level k belongs to the edge opposite corner k (the edge where gl_TessCoord[k] is 0).
    gl_TessLevelOuter[0] = edgeLevel(pWorld[1], pWorld[2]);
    gl_TessLevelOuter[1] = edgeLevel(pWorld[2], pWorld[0]);
    gl_TessLevelOuter[2] = edgeLevel(pWorld[0], pWorld[1]);
    if (!measurable(pWorld[0]) || !measurable(pWorld[1]) || !measurable(pWorld[2])) {
        gl_TessLevelInner[0] = 1.0;
        return;
    }
    vec2 corner[3];
    for (int k = 0; k < 3; ++k) {
        const vec3 h = homogeneousPixels(pWorld[k]);
        corner[k] = h.xy / h.z;
    }
    const float longest = max(distance(corner[0], corner[1]), max(distance(corner[1], corner[2]), distance(corner[2], corner[0])));
    gl_TessLevelInner[0] = insideLevel(longest);
}
