// The CPU reference of ray / depth-image intersection (intersect.h). Its GLSL twin,
// renderers/shaders/intersect.inc.glsl, follows these functions one for one: change both together.
#include "conus/codec/depth/intersect.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "conus/core/error.h"

namespace conus::codec {
namespace {

// The segment of a ray inside the depth image's clipped volume, as the image sees it: its
// undistorted end points and the reciprocal w, depth / w and t / w there, which are linear along
// the projected segment (perspective-correct interpolation).
struct Segment {
    glm::dvec2 p0, p1;
    double iw0, iw1, dw0, dw1, tw0, tw1;
    int face;  // the face the ray entered through (-1: it starts inside)
    int exit;  // the face it leaves through (-1: cut short by tMax)
    // Where the walk ends and whether that is the data's farthest depth (a scene's clip reaches a
    // jump beyond it, for a ray entering through a side just behind the surface; intersect.h).
    double end;
    bool endsAtRange;

    glm::dvec2 point(double s) const { return p0 + (p1 - p0) * s; }
    double invW(double s) const { return iw0 + (iw1 - iw0) * s; }
    double depth(double s) const { return (dw0 + (dw1 - dw0) * s) / invW(s); }
    double t(double s) const { return (tw0 + (tw1 - tw0) * s) / invW(s); }
};

// Clips `ray` to u, v in [0,1] and depth in [lo, hi] (each a half-space a + b t >= 0 in
// homogeneous clip coordinates, where perspective and orthographic cameras are alike).
std::optional<Segment> clipRay(const DepthImage& image, const Ray& ray, double tMax) {
    const Camera& camera = image.camera();
    const glm::dmat4 m = camera.worldToNdcMatrix();
    const glm::dvec4 c0 = m * glm::dvec4(ray.origin, 1.0), cd = m * glm::dvec4(ray.direction, 0.0);
    const glm::dvec3 forward = camera.forward();
    const double z0 = glm::dot(ray.origin - camera.eye(), forward), zd = glm::dot(ray.direction, forward);
    // The data's depth range, a hair wider so a surface exactly at its extreme is still reached;
    // in front of a perspective eye's near plane nothing projects. A scene's reaches a jump further
    // for rays going away from the eye (the walk still ends at the range: Segment::end).
    const double margin = kIntersectDepthMargin * (1.0 + std::max(std::abs(image.minDepth()), std::abs(image.maxDepth())));
    double lo = image.minDepth() - margin;
    const double range = image.maxDepth() + margin;
    const double hi = range + (image.solid() || !(zd > 0.0) ? 0.0 : image.jumpRelative() * image.maxDepth() + image.jumpAbsolute());
    if (camera.projection() == Projection::Perspective) lo = std::max(lo, camera.near());

    double tEnter = 0.0, tExit = tMax;
    int face = -1, exit = -1;
    const double planes[6][2] = {{c0.x, cd.x},
                                 {c0.w - c0.x, cd.w - cd.x},
                                 {c0.y, cd.y},
                                 {c0.w - c0.y, cd.w - cd.y},
                                 {z0 - lo, zd},
                                 {hi - z0, -zd}};
    for (int k = 0; k < 6; ++k) {
        const double a = planes[k][0], b = planes[k][1];
        if (b == 0.0) {
            if (a < 0.0) return std::nullopt;
            continue;
        }
        const double t = -a / b;
        if (b > 0.0) {
            if (t > tEnter) {
                tEnter = t;
                face = k;
            }
        } else if (t < tExit) {
            tExit = t;
            exit = k;
        }
    }
    if (!(tEnter <= tExit)) return std::nullopt;

    const auto end = [&](double t, glm::dvec2& p, double& iw, double& dw, double& tw) {
        const glm::dvec4 c = c0 + cd * t;
        iw = 1.0 / c.w;
        p = glm::clamp(glm::dvec2(c.x, c.y) * iw, 0.0, 1.0);
        dw = (z0 + zd * t) * iw;
        tw = t * iw;
    };
    Segment segment{};
    segment.face = face;
    segment.exit = exit;
    end(tEnter, segment.p0, segment.iw0, segment.dw0, segment.tw0);
    end(tExit, segment.p1, segment.iw1, segment.dw1, segment.tw1);
    segment.end = 1.0;
    segment.endsAtRange = exit == 5;
    if (hi > range && segment.depth(1.0) > range) {  // where the ray's depth reaches the range
        const double den = (segment.dw1 - segment.dw0) - range * (segment.iw1 - segment.iw0);
        segment.end = den != 0.0 ? std::clamp((range * segment.iw0 - segment.dw0) / den, 0.0, 1.0) : 1.0;
        segment.endsAtRange = true;
    }
    return segment;
}

}  // namespace

double heightToDepth(const Camera& camera, double height) {
    return glm::dot(-camera.eye(), camera.forward()) - height;
}

void checkIntersectOptions(const IntersectOptions& o) {
    if (!(o.stepTexels > 0.0 && o.stepTexels <= 64.0) || o.refinements < 0 || o.refinements > 64 || o.maxSteps < 1 ||
        o.maxSteps > (1 << 20) || !(o.tMax > 0.0))
        throw Error(ErrorCode::InvalidArgument,
                    "intersect: step " + std::to_string(o.stepTexels) + " texels, " + std::to_string(o.refinements) +
                        " refinements, " + std::to_string(o.maxSteps) + " steps, tMax " + std::to_string(o.tMax) +
                        ": want a step in (0, 64], refinements in [0, 64], steps in [1, 2^20], tMax > 0");
}

void checkRay(const Ray& ray) {
    const double length = glm::length(ray.direction);
    if (!std::isfinite(length) || !std::isfinite(glm::length(ray.origin)) || std::abs(length - 1.0) > 1e-6)
        throw Error(ErrorCode::InvalidArgument, "intersect: the ray's origin must be finite and its direction unit (length " +
                                                    std::to_string(length) + ")");
}

namespace {

// Where a walk stands: at s along its segment (pd: where that lies in the CoNUS image), the step
// before it at `before`, after `steps` steps.
struct Cursor {
    glm::dvec2 pd{0.0};
    double before = 0.0, s = 0.0;
    int steps = 0;
};

// What both walks (the first surface's and a deeper layer's) share: the clipped segment, the
// stored surface along it, the step and the hit record.
struct Walk {
    const DepthImage& image;
    const Ray& ray;
    const Segment segment;
    glm::dvec2 size, along;

    Walk(const DepthImage& i, const Ray& r, const Segment& s)
        : image(i), ray(r), segment(s), size(i.width(), i.height()), along(s.p1 - s.p0) {}

    // The walk of `ray` clipped to the image's volume, or nothing when it misses.
    static std::optional<Walk> start(const DepthImage& image, const Ray& ray, double tMax) {
        const std::optional<Segment> clipped = clipRay(image, ray, tMax);
        if (!clipped) return std::nullopt;
        return Walk(image, ray, *clipped);
    }

    // The stored surface's depth at s (and where s lies in the CoNUS image).
    double surface(double s, glm::dvec2& pd) const {
        pd = image.map().distort(segment.point(s));
        return image.sampleDepth(pd);
    }
    // Whether pd lies in a flagged cell: steps from or into one are kSilhouetteStep as long, so that
    // a near surface a texel wide is not stepped over (a wall, unlike a skin, can be).
    bool flagged(glm::dvec2 p) const { return !image.solid() && image.cellFlags()[image.cellIndex(p)] != 0; }
    // The smallest jump that is a discontinuity at depth d.
    double jump(double d) const { return image.jumpRelative() * d + image.jumpAbsolute(); }
    // One step of the linear search from c.s (c updated, its steps counted): stepTexels CoNUS pixels
    // along the curve, as measured by the map's Jacobian where the step starts, kSilhouetteStep
    // as long from or into a flagged cell. Returns the stored depth at the new c.s.
    double step(Cursor& c, double stepTexels) const {
        // CoNUS pixels the curve covers per unit s here: |J (p1 - p0)| in pixels.
        const double speed = glm::length(image.map().jacobian(segment.point(c.s)) * along * size);
        const auto advance = [&](double texels) { return std::min(segment.end, c.before + (speed > 0.0 ? texels / speed : 1.0)); };
        const bool fine = flagged(c.pd);
        c.before = c.s;
        c.s = advance(stepTexels * (fine ? kSilhouetteStep : 1.0));
        double stored = surface(c.s, c.pd);
        if (!fine && flagged(c.pd)) {  // a full step into a flagged cell: taken again, finely
            c.s = advance(stepTexels * kSilhouetteStep);
            stored = surface(c.s, c.pd);
        }
        ++c.steps;
        return stored;
    }
    DepthHit hitAt(double s, glm::dvec2 pd, int steps, bool hidden) const {
        DepthHit hit;
        hit.t = segment.t(s);
        hit.position = ray.origin + ray.direction * hit.t;
        hit.depth = segment.depth(s);
        hit.point = segment.point(s);
        hit.distorted = pd;
        hit.texel = glm::clamp(glm::ivec2(glm::floor(pd * size)), glm::ivec2(0), glm::ivec2(size) - 1);
        hit.steps = steps;
        hit.hidden = hidden;
        hit.face = steps == 0 ? segment.face : -1;
        return hit;
    }
    // Through a side, behind a scene's surface `entry` by less than a jump (continuous with it by
    // the image's own measure), short of the camera's far plane (where a scene's image saw
    // nothing): the surface goes on across the edge, and the ray met it there.
    bool acrossSide(double entry) const {
        return segment.face >= 0 && segment.face < 4 && entry < image.camera().far() * (1.0 - kSideRuleFarMargin) &&
               segment.depth(0.0) - entry <= jump(entry);
    }
};

}  // namespace

std::optional<DepthHit> intersect(const DepthImage& image, const Ray& ray, const IntersectOptions& options) {
    double firstHidden = 0;
    return intersect(image, ray, options, firstHidden);
}

std::optional<DepthHit> intersect(const DepthImage& image, const Ray& ray, const IntersectOptions& options,
                                  double& firstHidden) {
    firstHidden = std::numeric_limits<double>::infinity();
    const std::optional<Walk> started = Walk::start(image, ray, options.tMax);
    if (!started) return std::nullopt;
    const Walk& walk = *started;
    const Segment& segment = walk.segment;
    Cursor c;
    // Hidden: behind the surface of a scene, since the ray was at depth `hiddenDepth` (file comment).
    bool hidden = false;
    double hiddenDepth = 0.0;
    glm::dvec2 hiddenFrom(0.0);  // the last point in front of the surface: the background's side
    if (const double entry = walk.surface(0.0, c.pd); entry - segment.depth(0.0) <= 0.0) {
        if (image.solid() || walk.acrossSide(entry)) return walk.hitAt(0.0, c.pd, 0, false);
        if (segment.end <= 0.0) return std::nullopt;  // entered beyond the data's depth range
        hidden = true;
        firstHidden = segment.t(0.0);
        hiddenDepth = segment.depth(0.0);
        hiddenFrom = c.pd;
    }
    for (;;) {
        if (c.s >= segment.end || c.steps >= options.maxSteps) {
            // Hidden up to the farthest stored depth: behind the background, which takes the
            // colour of where the ray went hidden.
            if (hidden && c.s >= segment.end && segment.endsAtRange) return walk.hitAt(segment.end, hiddenFrom, c.steps, true);
            return std::nullopt;
        }
        const double stored = walk.step(c, options.stepTexels);
        const double gap = stored - segment.depth(c.s);
        if (hidden) {
            if (gap > 0.0) {
                hidden = false;  // in front of the surface again
            } else if (stored >= hiddenDepth) {
                // Behind the background: where the stored surface first reaches hiddenDepth.
                double a = c.before, b = c.s;
                for (int k = 0; k < options.refinements; ++k) {
                    const double m = 0.5 * (a + b);
                    (walk.surface(m, c.pd) >= hiddenDepth ? b : a) = m;
                }
                walk.surface(b, c.pd);
                return walk.hitAt(b, c.pd, c.steps, true);
            }
            continue;
        }
        if (gap > 0.0) continue;
        // A crossing between `before` (in front) and s (behind): bisect it.
        double a = c.before, b = c.s;
        for (int k = 0; k < options.refinements; ++k) {
            const double m = 0.5 * (a + b);
            (walk.surface(m, c.pd) - segment.depth(m) > 0.0 ? a : b) = m;
        }
        glm::dvec2 pa, pb;
        const double jump = walk.surface(a, pa) - walk.surface(b, pb);
        if (image.solid() || jump <= 0.5 * walk.jump(walk.surface(b, pb))) {
            const double mid = 0.5 * (a + b);
            walk.surface(mid, c.pd);
            return walk.hitAt(mid, c.pd, c.steps, false);
        }
        // A wall: the ray passes behind an occluder's silhouette.
        hidden = true;
        firstHidden = std::min(firstHidden, segment.t(a));
        hiddenDepth = segment.depth(b);
        hiddenFrom = pa;
    }
}

std::optional<DepthHit> intersectBehind(const DepthImage& layer, const Ray& ray, const IntersectOptions& options) {
    const std::optional<Walk> started = Walk::start(layer, ray, options.tMax);
    if (!started) return std::nullopt;
    const Walk& walk = *started;
    const Segment& segment = walk.segment;
    Cursor c;
    const double entry = walk.surface(0.0, c.pd);
    if (entry - segment.depth(0.0) <= 0.0 && walk.acrossSide(entry)) return walk.hitAt(0.0, c.pd, 0, false);
    // Which side of the stored surface the ray is on; a crossing either way is a hit where the
    // surface is continuous (the mirror meets a surface that faces the centre from its front, one
    // that faces away from its back), a wall where it is not.
    bool front = entry - segment.depth(0.0) > 0.0;
    while (c.s < segment.end && c.steps < options.maxSteps) {
        const double stored = walk.step(c, options.stepTexels);
        if ((stored - segment.depth(c.s) > 0.0) == front) continue;
        double a = c.before, b = c.s;
        for (int k = 0; k < options.refinements; ++k) {
            const double m = 0.5 * (a + b);
            ((walk.surface(m, c.pd) - segment.depth(m) > 0.0) == front ? a : b) = m;
        }
        glm::dvec2 pa, pb;
        const double sa = walk.surface(a, pa), sb = walk.surface(b, pb);
        if ((front ? sa - sb : sb - sa) <= 0.5 * walk.jump(std::min(sa, sb))) {
            const double mid = 0.5 * (a + b);
            walk.surface(mid, c.pd);
            return walk.hitAt(mid, c.pd, c.steps, false);
        }
        front = !front;  // a wall: the ray is now on the other side, with nothing met
    }
    return std::nullopt;
}

}  // namespace conus::codec
