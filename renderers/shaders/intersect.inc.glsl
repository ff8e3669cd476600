// Ray / depth-image intersection in GLSL: the twin of codec/src/depth/intersect.cpp and
// depth_surface.cpp, function for function (clip in homogeneous coordinates, project, walk the
// projected segment distorting each point with Equation 1, bisect; walls and hidden rays as
// codec/depth/intersect.h says). Include equation1.inc.glsl first. kIntersectDepthMargin,
// kSilhouetteStep and kSideRuleFarMargin are declared before it from C++ (codec::glslConstants).
// The depth texture is R32F; each depth's lowest mantissa bit is its cell's discontinuity flag
// (DepthImage::cellFlags, computed once on the CPU: codec::flaggedDepths); a DepthView holds
// codec::depthViewValues. Installed (<datadir>/conus/glsl) for renderers of one's own:
// conus/codec/depth/glsl_interface.h, docs/reflections-in-your-renderer.md.
//
// A layered depth image (codec/depth/intersect.h) lies in one texture, its layers side by side
// (layer k's texel (x, y) at (x + k * width, y)); gDepthLayers says how many, gDepthLayer which one
// the functions below read. A single-layer image needs neither set.
int gDepthLayers = 1;
int gDepthLayer = 0;

// One layer's size, and texel i of the layer being read.
ivec2 depthSize(sampler2D depths) {
    const ivec2 all = textureSize(depths, 0);
    return ivec2(all.x / gDepthLayers, all.y);
}
ivec2 layerTexel(sampler2D depths, ivec2 i) { return ivec2(i.x + gDepthLayer * depthSize(depths).x, i.y); }
float depthAt(sampler2D depths, ivec2 i) { return texelFetch(depths, layerTexel(depths, i), 0).r; }

struct DepthView {
    mat4 worldToNdc;  // the camera's worldToNdcMatrix (u, v = xy / w)
    mat4 ndcToWorld;  // its inverse, for unprojectDepth
    vec3 eye;
    vec3 forward;
    float near, far;
    bool perspective;
    float minDepth, maxDepth;  // the range of the stored camera depths
    bool solid;                // DepthImage::solid
    float jumpRelative, jumpAbsolute;  // DepthImage's jump threshold
};

struct DepthHit {
    bool hit;
    float t;
    vec3 position;
    float depth;
    vec2 point;      // undistorted image point
    vec2 distorted;  // its place in the CoNUS image
    ivec2 texel;
    int steps;
    bool hidden;  // the background carried on behind an occluder
    float firstHidden;  // where the walk first went behind the surface (t; 1e38: never): deeper layers from there
    int face;  // the face of the clipped volume the ray entered through when steps == 0 (0..5), else -1
};

// The discontinuity flag a depth carries (always clear in a solid image).
bool flagBit(float depth) { return (floatBitsToUint(depth) & 1u) != 0u; }

// The far side of a flagged cell zeroed in the bilinear weights w of its depths d (x, y, z, w:
// the texels at i0, (i1.x, i0.y), (i0.x, i1.y), i1), f the position in the cell: the texels on
// the nearest texel's side of the cell's middle depth keep theirs.
vec4 splitWeights(vec4 d, vec4 w, vec2 f) {
    const float middle = 0.5 * (min(min(d.x, d.y), min(d.z, d.w)) + max(max(d.x, d.y), max(d.z, d.w)));
    const float nearest = f.y < 0.5 ? (f.x < 0.5 ? d.x : d.y) : (f.x < 0.5 ? d.z : d.w);
    return w * vec4(equal(lessThanEqual(d, vec4(middle)), bvec4(nearest <= middle)));
}

// depth_surface.cpp's cellAt: the cell of four texels around pd (pixel centres at (i + 0.5) /
// size; corners i0 and i1) and pd's place in it, past [0, 1] within half a texel of the image's
// side (the last cell's step carried on to the side).
vec2 cellAt(ivec2 size, vec2 pd, out ivec2 i0, out ivec2 i1) {
    const vec2 g = pd * vec2(size) - 0.5;
    i0 = clamp(ivec2(floor(g)), ivec2(0), max(size - 2, ivec2(0)));
    i1 = min(i0 + 1, size - 1);
    return mix(vec2(0.0), clamp(g - vec2(i0), -0.5, 1.5), greaterThan(i1, i0));
}

// The bilinear weights of a cell's texels (x, y, z, w as splitWeights) at f in [0, 1]^2.
vec4 bilinearWeights(vec2 f) {
    return vec4((1.0 - f.x) * (1.0 - f.y), f.x * (1.0 - f.y), (1.0 - f.x) * f.y, f.x * f.y);
}

// DepthImage::surfaceWeights: the four texels around pd and their weights (x, y, z, w as
// splitWeights), which do not extrapolate.
vec4 surfaceWeights(sampler2D depths, vec2 pd, out ivec2 i0, out ivec2 i1) {
    const vec2 f = clamp(cellAt(depthSize(depths), pd, i0, i1), 0.0, 1.0);
    const float a = depthAt(depths, i0);
    const vec4 w = bilinearWeights(f);
    if (!flagBit(a)) return w;
    const vec4 d = vec4(a, depthAt(depths, ivec2(i1.x, i0.y)), depthAt(depths, ivec2(i0.x, i1.y)),
                        depthAt(depths, i1));
    return splitWeights(d, w, f);
}

// DepthImage::sampleDepth: the stored surface's depth at pd, plain bilinear in an unflagged cell
// (exact weights, texelFetch; carried on to the image's side, in 1/depth for a perspective
// image); `flagged` says which.
float sampleDepth(sampler2D depths, DepthView view, vec2 pd, out bool flagged) {
    ivec2 i0, i1;
    const vec2 f = cellAt(depthSize(depths), pd, i0, i1);
    const float a = depthAt(depths, i0);
    const float b = depthAt(depths, ivec2(i1.x, i0.y)), c = depthAt(depths, ivec2(i0.x, i1.y));
    const float e = depthAt(depths, i1);
    flagged = flagBit(a);
    if (!flagged) {
        if (f == clamp(f, 0.0, 1.0) || !view.perspective) return mix(mix(a, b, f.x), mix(c, e, f.x), f.y);
        const float q = mix(mix(1.0 / a, 1.0 / b, f.x), mix(1.0 / c, 1.0 / e, f.x), f.y);
        return 1.0 / clamp(q, 1.0 / view.far, 1.0 / view.near);
    }
    const vec2 fc = clamp(f, 0.0, 1.0);
    const vec4 d = vec4(a, b, c, e);
    const vec4 w = splitWeights(d, bilinearWeights(fc), fc);
    return dot(w, d) / (w.x + w.y + w.z + w.w);
}

float sampleDepth(sampler2D depths, DepthView view, vec2 pd) {
    bool flagged;
    return sampleDepth(depths, view, pd, flagged);
}

// The world point at image point uv and camera depth `depth` (perspective or orthographic: depth is
// affine along the line from the near plane's point to the far plane's).
vec3 unprojectDepth(DepthView view, vec2 uv, float depth) {
    const vec4 a = view.ndcToWorld * vec4(uv, 0.0, 1.0), b = view.ndcToWorld * vec4(uv, 1.0, 1.0);
    const vec3 pa = a.xyz / a.w, pb = b.xyz / b.w;
    const float da = dot(pa - view.eye, view.forward), db = dot(pb - view.eye, view.forward);
    return mix(pa, pb, (depth - da) / (db - da));
}

// The outward normal (world) of face `face` of the clipped volume, at no point in particular.
vec3 clipFaceNormal(DepthView view, int face) {
    const mat4 m = transpose(view.worldToNdc);  // rows of the matrix as columns
    vec3 inward;
    if (face == 0) inward = m[0].xyz;
    else if (face == 1) inward = m[3].xyz - m[0].xyz;
    else if (face == 2) inward = m[1].xyz;
    else if (face == 3) inward = m[3].xyz - m[1].xyz;
    else if (face == 4) inward = view.forward;
    else inward = -view.forward;
    return -normalize(inward);
}

// The stored surface's depth at s along the projected segment, where s lies in the CoNUS image,
// and whether its cell is flagged.
float surfaceAlong(sampler2D depths, DepthView view, sampler2D map, vec2 p0, vec2 along, float s, out MapPoint m,
                   out bool flagged) {
    m = evalMap(map, p0 + along * s);
    return sampleDepth(depths, view, m.pd, flagged);
}

float surfaceAlong(sampler2D depths, DepthView view, sampler2D map, vec2 p0, vec2 along, float s, out MapPoint m) {
    bool flagged;
    return surfaceAlong(depths, view, map, p0, along, s, m, flagged);
}

// The ray clipped to the image's volume (Segment in intersect.cpp): the projected segment from p0
// along `along`, 1/w, depth/w and t/w at its ends (linear along it), where the walk ends and
// whether that is the data's farthest depth, and the face entered through (-1: none).
struct DepthSegment {
    vec2 p0, along;
    float iw0, iw1, dw0, dw1, tw0, tw1;
    float end;
    bool endsAtRange;
    int entered;
};

// The ray's camera depth and its t at s (perspective-correct).
float segmentDepth(DepthSegment g, float s) { return mix(g.dw0, g.dw1, s) / mix(g.iw0, g.iw1, s); }
float segmentT(DepthSegment g, float s) { return mix(g.tw0, g.tw1, s) / mix(g.iw0, g.iw1, s); }

// The smallest jump that is a discontinuity at depth d (Walk::jump in intersect.cpp).
float depthJump(DepthView view, float d) { return view.jumpRelative * d + view.jumpAbsolute; }

// 1. Clip: u, v in [0,1] and depth in [lo, hi], each a + b t >= 0; 2. project the ends. False when
// the ray misses the volume.
bool clipDepthRay(DepthView view, vec3 origin, vec3 direction, float tMax, out DepthSegment g) {
    const vec4 c0 = view.worldToNdc * vec4(origin, 1.0), cd = view.worldToNdc * vec4(direction, 0.0);
    const float z0 = dot(origin - view.eye, view.forward), zd = dot(direction, view.forward);
    const float margin = kIntersectDepthMargin * (1.0 + max(abs(view.minDepth), abs(view.maxDepth)));
    float lo = view.minDepth - margin;
    const float range = view.maxDepth + margin;
    // a scene's clip reaches a jump further for rays going away from the eye; the walk ends at range
    const float hi = range + (view.solid || !(zd > 0.0) ? 0.0 : view.jumpRelative * view.maxDepth + view.jumpAbsolute);
    if (view.perspective) lo = max(lo, view.near);
    float planes[12] = float[12](c0.x, cd.x, c0.w - c0.x, cd.w - cd.x, c0.y, cd.y, c0.w - c0.y, cd.w - cd.y, z0 - lo,
                                 zd, hi - z0, -zd);
    float tEnter = 0.0, tExit = tMax;
    int entered = -1, exited = -1;
    for (int k = 0; k < 6; ++k) {
        const float a = planes[2 * k], b = planes[2 * k + 1];
        if (b == 0.0) {
            if (a < 0.0) return false;
            continue;
        }
        const float t = -a / b;
        if (b > 0.0) {
            if (t > tEnter) {
                tEnter = t;
                entered = k;
            }
        } else if (t < tExit) {
            tExit = t;
            exited = k;
        }
    }
    if (!(tEnter <= tExit)) return false;

    // 1/w, depth/w and t/w are linear along the projected segment.
    const vec4 ca = c0 + cd * tEnter, cb = c0 + cd * tExit;
    g.iw0 = 1.0 / ca.w;
    g.iw1 = 1.0 / cb.w;
    g.p0 = clamp(ca.xy * g.iw0, 0.0, 1.0);
    g.along = clamp(cb.xy * g.iw1, 0.0, 1.0) - g.p0;
    g.dw0 = (z0 + zd * tEnter) * g.iw0;
    g.dw1 = (z0 + zd * tExit) * g.iw1;
    g.tw0 = tEnter * g.iw0;
    g.tw1 = tExit * g.iw1;
    g.entered = entered;
    g.end = 1.0;  // where the walk ends (Segment::end)
    g.endsAtRange = exited == 5;
    if (hi > range && segmentDepth(g, 1.0) > range) {
        const float den = (g.dw1 - g.dw0) - range * (g.iw1 - g.iw0);
        g.end = den != 0.0 ? clamp((range * g.iw0 - g.dw0) / den, 0.0, 1.0) : 1.0;
        g.endsAtRange = true;
    }
    return true;
}

// Through a side, behind a scene's surface `entry` by less than a jump, short of the far plane
// (where a scene saw nothing): met where it enters.
bool acrossSide(DepthView view, DepthSegment g, float entry) {
    return !view.solid && g.entered >= 0 && g.entered < 4 && entry < view.far * (1.0 - kSideRuleFarMargin) &&
           segmentDepth(g, 0.0) - entry <= depthJump(view, entry);
}

// One step of the linear search (Walk::step in intersect.cpp): stepTexels CoNUS pixels along the
// distorted curve from s, kSilhouetteStep as long from or into a flagged cell. Updates before, s,
// m and flagged; returns the stored depth at the new s.
float stepAlong(sampler2D depths, sampler2D map, DepthView view, DepthSegment g, float stepTexels, vec2 size,
                inout float before, inout float s, inout MapPoint m, inout bool flagged) {
    const float speed = length((m.du * g.along.x + m.dv * g.along.y) * size);
    const bool fine = flagged;
    before = s;
    s = min(g.end, before + (speed > 0.0 ? stepTexels * (fine ? kSilhouetteStep : 1.0) / speed : 1.0));
    float stored = surfaceAlong(depths, view, map, g.p0, g.along, s, m, flagged);
    if (!fine && flagged) {  // a full step into a flagged cell: taken again, finely
        s = min(g.end, before + (speed > 0.0 ? stepTexels * kSilhouetteStep / speed : 1.0));
        stored = surfaceAlong(depths, view, map, g.p0, g.along, s, m, flagged);
    }
    return stored;
}

// The hit at s (where the CoNUS image holds pd).
void finishHit(inout DepthHit result, DepthSegment g, vec3 origin, vec3 direction, float s, vec2 pd, vec2 size,
               int steps) {
    result.hit = true;
    result.t = segmentT(g, s);
    result.position = origin + direction * result.t;
    result.depth = segmentDepth(g, s);
    result.point = g.p0 + g.along * s;
    result.distorted = pd;
    result.texel = clamp(ivec2(floor(pd * size)), ivec2(0), ivec2(size) - 1);
    result.steps = steps;
    result.face = steps == 0 ? g.entered : -1;
}

DepthHit noDepthHit() {
    DepthHit result;
    result.hit = false;
    result.steps = 0;
    result.face = -1;
    result.hidden = false;
    result.firstHidden = 1e38;
    return result;
}

DepthHit intersectDepthImage(sampler2D depths, sampler2D map, DepthView view, vec3 origin, vec3 direction,
                             float stepTexels, int refinements, int maxSteps, float tMax) {
    DepthHit result = noDepthHit();
    DepthSegment g;
    if (!clipDepthRay(view, origin, direction, tMax, g)) return result;
    const vec2 size = vec2(depthSize(depths));

    // 3. Walk near to far, each step stepTexels CoNUS pixels along the distorted curve. The walk
    // stops at an event; the bisections run after it, so that rays bisect together.
    float before = 0.0, s = 0.0;
    int steps = 0;
    bool hidden = false;
    float hiddenDepth = 0.0;
    MapPoint m, hiddenFrom;  // hiddenFrom: the last point in front of the surface
    MapPoint q;
    bool flagged;  // whether the sample at s lies in a flagged cell (never in a solid image)
    const float entry = surfaceAlong(depths, view, map, g.p0, g.along, 0.0, m, flagged);
    const bool behind = entry - segmentDepth(g, 0.0) <= 0.0;
    const bool across = behind && acrossSide(view, g, entry);
    if (behind && !view.solid && !across) {
        if (g.end <= 0.0) return result;  // entered beyond the data's depth range
        hidden = true;
        result.firstHidden = segmentT(g, 0.0);
        hiddenDepth = segmentDepth(g, 0.0);
        hiddenFrom = m;
    }
    if (!(behind && (view.solid || across))) {  // else hit where entered: a solid image, or a surface across the side
        for (;;) {
            // The event: 1 a crossing, 2 behind the background while hidden, 0 the end.
            int event = 0;
            while (!(s >= g.end || steps >= maxSteps)) {
                const float stored = stepAlong(depths, map, view, g, stepTexels, size, before, s, m, flagged);
                ++steps;
                const float gap = stored - segmentDepth(g, s);
                if (hidden) {
                    if (gap > 0.0) {
                        hidden = false;  // in front of the surface again
                    } else if (stored >= hiddenDepth) {
                        event = 2;
                        break;
                    }
                } else if (!(gap > 0.0)) {
                    event = 1;
                    break;
                }
            }
            if (event == 0) {
                // Hidden up to the farthest stored depth: the background where the ray went hidden.
                if (!(hidden && s >= g.end && g.endsAtRange)) return result;
                m = hiddenFrom;
                result.hidden = true;
                s = g.end;
                break;
            }
            float a = before, b = s;
            if (event == 2) {
                // Behind the background: where the stored surface first reaches hiddenDepth.
                for (int k = 0; k < refinements; ++k) {
                    const float mid = 0.5 * (a + b);
                    if (surfaceAlong(depths, view, map, g.p0, g.along, mid, q) >= hiddenDepth)
                        b = mid;
                    else
                        a = mid;
                }
                s = b;
                m = evalMap(map, g.p0 + g.along * s);
                result.hidden = true;
                break;
            }
            // 4. Bisect between the last sample in front and the first behind.
            for (int k = 0; k < refinements; ++k) {
                const float mid = 0.5 * (a + b);
                if (surfaceAlong(depths, view, map, g.p0, g.along, mid, q) - segmentDepth(g, mid) > 0.0)
                    a = mid;
                else
                    b = mid;
            }
            if (view.solid) {
                s = 0.5 * (a + b);
                m = evalMap(map, g.p0 + g.along * s);
                break;
            }
            const float sb = surfaceAlong(depths, view, map, g.p0, g.along, b, q);
            MapPoint qa;
            if (surfaceAlong(depths, view, map, g.p0, g.along, a, qa) - sb <= 0.5 * depthJump(view, sb)) {
                s = 0.5 * (a + b);
                m = evalMap(map, g.p0 + g.along * s);
                break;
            }
            hidden = true;  // a wall: the ray passes behind an occluder's silhouette
            result.firstHidden = min(result.firstHidden, segmentT(g, a));
            hiddenDepth = segmentDepth(g, b);
            hiddenFrom = qa;
        }
    }
    finishHit(result, g, origin, direction, s, m.pd, size, steps);
    return result;
}

// A deeper layer of a layered image (codec::intersectBehind): a continuous crossing of the stored
// surface either way is a hit, a wall none, nothing carried on behind an occluder.
DepthHit intersectBehindLayer(sampler2D depths, sampler2D map, DepthView view, vec3 origin, vec3 direction,
                              float stepTexels, int refinements, int maxSteps, float tMax) {
    DepthHit result = noDepthHit();
    DepthSegment g;
    if (!clipDepthRay(view, origin, direction, tMax, g)) return result;
    const vec2 size = vec2(depthSize(depths));
    MapPoint m, q;
    bool flagged;
    float before = 0.0, s = 0.0;
    int steps = 0;
    const float entry = surfaceAlong(depths, view, map, g.p0, g.along, 0.0, m, flagged);
    if (entry - segmentDepth(g, 0.0) <= 0.0 && acrossSide(view, g, entry)) {
        finishHit(result, g, origin, direction, 0.0, m.pd, size, 0);
        return result;
    }
    bool front = entry - segmentDepth(g, 0.0) > 0.0;
    while (s < g.end && steps < maxSteps) {
        const float stored = stepAlong(depths, map, view, g, stepTexels, size, before, s, m, flagged);
        ++steps;
        if ((stored - segmentDepth(g, s) > 0.0) == front) continue;
        float a = before, b = s;
        for (int k = 0; k < refinements; ++k) {
            const float mid = 0.5 * (a + b);
            if ((surfaceAlong(depths, view, map, g.p0, g.along, mid, q) - segmentDepth(g, mid) > 0.0) == front)
                a = mid;
            else
                b = mid;
        }
        MapPoint qa, qb;
        const float sa = surfaceAlong(depths, view, map, g.p0, g.along, a, qa);
        const float sb = surfaceAlong(depths, view, map, g.p0, g.along, b, qb);
        if ((front ? sa - sb : sb - sa) <= 0.5 * depthJump(view, min(sa, sb))) {
            const float mid = 0.5 * (a + b);
            m = evalMap(map, g.p0 + g.along * mid);
            finishHit(result, g, origin, direction, mid, m.pd, size, steps);
            return result;
        }
        front = !front;  // a wall: the ray is now on the other side, with nothing met
    }
    return result;
}
