// Rays against CoNUS depth images (paper section 5): the CPU reference of the one intersection
// algorithm; renderers/shaders/intersect.inc.glsl is its GLSL twin, step for step.
//
// A DepthImage is a camera (perspective or orthographic), its sampling map (the identity for a
// conventional depth image: the same code path) and one camera depth per CoNUS pixel. intersect():
//   1. clips the ray to the image's view volume (frustum or box) and to the depth range its samples
//      span (the 3-D bounding box of the data), in homogeneous clip coordinates (Liang-Barsky), so
//      perspective and orthographic cameras clip the same way;
//   2. projects the clipped ray conventionally: a segment from p0 to p1 in the undistorted image;
//   3. walks that segment near to far, distorting each point with Equation 1 (the projection is a
//      curve in the CoNUS image); each step advances `stepTexels` CoNUS pixels along that curve, as
//      measured by the map's Jacobian where the step starts, so magnified regions (more samples per
//      unit of the undistorted image) get proportionally finer steps in the undistorted image
//      (and kSilhouetteStep as long in a flagged cell, below);
//   4. stops at the first sample where the ray is at or behind the stored surface and refines
//      between that sample and the one before by bisection (walls of scenes aside, below).
// Depths along the segment come from perspective-correct interpolation (depth / w and t / w are
// linear in the image), so no point is unprojected while stepping.
//
// What lies behind the stored surface depends on the image. Solid images (height fields, relief):
// the matter under the surface is solid, so the bilinear surface between a near and a far sample
// is the best estimate of the wall between them (split walls measured worse on the tablet's
// engraved text, bench/notes/2026-11-27-reflection-silhouettes.md), a wall is hit like any
// surface, and a ray that enters the clipped volume already behind the surface hits where it
// enters (the side walls of a relief box).
//
// Images of scenes (camera depth: reflections, mesh renders) know nothing behind a silhouette, and
// the bilinear surface across one is a "skin" no ray may hit (the false intersections of distance
// impostors, Szirmay-Kalos et al. 2005, and of single-layer relief mapping, which layered maps
// resolve and a single layer cannot). A cell of four texels straddles a depth discontinuity when
// one of its edges steps (in 1/depth for perspective cameras, where a plane is affine; in depth
// for orthographic ones) by kJumpRatio times more than every step beside it on the same line that
// goes the same way (so a plane seen at a grazing angle and a crease where two surfaces meet are
// continuous, and an object a texel wide is not), and by more than the image's jump threshold;
// such cells are flagged once, when the image is made (cellFlags). In a flagged cell the surface
// splits in two: the texels on the nearest texel's side of the cell's middle depth keep their
// bilinear weights, the others none, so the surface ends in a wall halfway between a near and a
// far sample. A refined crossing that is a wall (the surface jumps nearer inside the final bracket
// by more than half the jump threshold) is no hit: the ray walks on hidden until it is in front
// of the surface again, or until the stored surface is back at least as far as the ray was when
// it went hidden, which means the ray has gone behind the background: it hits there, the
// background carried on behind the occluder (the nearest honest guess; the true surface is not in
// the image). A ray still hidden where it leaves the data's depth range hits the background where
// it went hidden; one that leaves through the image's side hits nothing here (a reflection then
// takes another face, or the sky). A ray that enters a scene's image through a side less than a
// jump behind the stored surface hits where it enters: the surface goes on across the image's
// edge (a floor seen by two cube faces), and the ray would otherwise pass both images; not where
// the stored surface is at the camera's far plane (within kSideRuleFarMargin of it), which is
// where depth images of scenes store nothing seen. Those never hit there: the walk ends at the
// largest stored depth.
//
// Height fields (depth kind `height`, orthographic camera looking down at the base plane): the
// base plane is the plane through the world origin facing the camera, and height h lies h above
// it toward the camera, i.e. at camera depth depth(origin) - h (heightToDepth below).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "conus/codec/map/sampling_map.h"
#include "conus/core/camera.h"
#include "conus/core/image.h"
#include "conus/format/container.h"

namespace conus::codec {

// A discontinuity: an edge's step exceeds this many times the steps beside it (file comment).
inline constexpr double kJumpRatio = 4.0;
// The jump threshold: perspective, this fraction of the nearer depth; orthographic, this fraction
// of a texel's width in the world at the identity map.
inline constexpr double kJumpRelative = 0.05;
inline constexpr double kJumpTexels = 0.5;

// The linear search's step inside a flagged cell, a fraction of stepTexels: a surface ends in a wall
// there, and a ray that enters a near surface a texel wide in front of it and crosses it must be
// sampled behind it before it leaves.
inline constexpr double kSilhouetteStep = 0.25;

class DepthImage {
public:
    // `depths` holds one camera depth per CoNUS pixel (width x height, top row first; finite);
    // `solid`: what lies behind the surface is matter (height fields) rather than unknown (scenes).
    // Throws conus::Error(InvalidArgument) on a size mismatch or a non-finite depth.
    DepthImage(Camera camera, std::shared_ptr<const SamplingMap> map, int width, int height, std::vector<float> depths,
               bool solid = true);
    // From a CoNUS file with a camera and a Z channel: camera depths as they are, heights through
    // heightToDepth; solid for heights, not for camera depths. Throws conus::Error(InvalidArgument)
    // when the file lacks either.
    static DepthImage fromFile(const format::ConusFile& file);

    const Camera& camera() const { return m_camera; }
    const SamplingMap& map() const { return *m_map; }
    const std::shared_ptr<const SamplingMap>& sharedMap() const { return m_map; }
    int width() const { return m_width; }
    int height() const { return m_height; }
    const std::vector<float>& depths() const { return m_depths; }
    float depthAt(int x, int y) const { return m_depths[static_cast<std::size_t>(y) * m_width + x]; }
    // The surface's depth at distorted position pd: bilinear in the CoNUS image (pixel centres at
    // (i + 0.5) / width; between the last centres and the image's side, an unflagged cell's
    // surface carried on, in 1/depth for a perspective camera, where a plane's is affine, within
    // its near and far planes), split in flagged cells (file comment): what the linear search
    // compares the ray with.
    double sampleDepth(glm::dvec2 pd) const;
    // The four texels around pd and their weights in sampleDepth (zero for the far side of a
    // flagged cell; at the side, the edge texels' without extrapolation); the colour a hit takes
    // uses the same weights.
    struct Weights {
        glm::ivec2 texel[4];
        double weight[4];
    };
    Weights surfaceWeights(glm::dvec2 pd) const;
    // The index (y * width + x) of the cell around pd: its top-left texel, as surfaceWeights finds it.
    std::size_t cellIndex(glm::dvec2 pd) const;
    // The range of depths the surface spans (sampleDepth's, the sides' included).
    double minDepth() const { return m_minDepth; }
    double maxDepth() const { return m_maxDepth; }
    bool solid() const { return m_solid; }
    // 1 where the cell whose top-left texel this is straddles a discontinuity, else 0 (always 0 in
    // a solid image).
    const std::vector<std::uint8_t>& cellFlags() const { return m_flags; }
    // The smallest jump that is a discontinuity at `depth`: jumpRelative() * depth + jumpAbsolute().
    double jumpRelative() const { return m_jumpRelative; }
    double jumpAbsolute() const { return m_jumpAbsolute; }

private:
    void flagCells();  // m_flags of a scene's image (file comment)

    Camera m_camera;
    std::shared_ptr<const SamplingMap> m_map;
    int m_width = 0, m_height = 0;
    std::vector<float> m_depths;
    std::vector<std::uint8_t> m_flags;
    double m_minDepth = 0, m_maxDepth = 0;
    bool m_solid = true;
    double m_jumpRelative = 0, m_jumpAbsolute = 0;
};

// The camera depth of height h above a height field's base plane (see the file comment).
double heightToDepth(const Camera& camera, double height);

// The clip's depth range is widened by this fraction of (1 + its largest magnitude), so that a
// surface exactly at the range's end is still reached despite rounding (GLSL: same constant).
inline constexpr double kIntersectDepthMargin = 1e-5;
// A stored surface within this fraction of the camera's far plane is not continued across an
// image's side (the file comment; GLSL: same constant): a scene's image stores the far plane
// where it saw nothing.
inline constexpr double kSideRuleFarMargin = 1e-4;

struct IntersectOptions {
    double stepTexels = 1.0;  // linear-search step, in CoNUS pixels along the projected curve
    int refinements = 12;     // bisections after the linear search
    int maxSteps = 8192;      // the linear search gives up (no hit) after this many steps
    double tMax = 1e30;       // ignore hits farther along the ray than this
};

struct DepthHit {
    double t = 0;               // distance along the ray (its direction is unit)
    glm::dvec3 position{0.0};   // world point
    double depth = 0;           // camera depth of the hit
    glm::dvec2 point{0.0};      // undistorted image point (the conventional camera's u, v)
    glm::dvec2 distorted{0.0};  // where it lies in the CoNUS image (Equation 1 of point)
    glm::ivec2 texel{0};        // the CoNUS pixel holding `distorted`
    int steps = 0;              // linear-search steps taken
    bool hidden = false;        // a scene's background carried on behind an occluder (file comment)
    // When the ray entered the clipped volume already behind the surface (steps == 0): the face it
    // came through, 0..5 for u = 0, u = 1, v = 0, v = 1, the nearest and the farthest depth; else -1.
    int face = -1;
};

// The first hit along `ray` (direction unit), or nothing. Never throws for a finite ray.
std::optional<DepthHit> intersect(const DepthImage& image, const Ray& ray, const IntersectOptions& options = {});
// The same, saying where the walk first went behind a scene's surface (a wall crossed: the last
// sample in front of it; or where the ray entered hidden), as a distance along the ray; infinity
// when it never did: only beyond it can a deeper layer of a layered image hold what the ray meets
// (below).
std::optional<DepthHit> intersect(const DepthImage& image, const Ray& ray, const IntersectOptions& options,
                                  double& firstHidden);

// Layered depth images (depth peeling: layer k holds the k-th surface along each texel's ray, the
// camera's far plane where there is none) keep what a single layer loses behind a silhouette.
// Layer 0 is an ordinary scene image and is walked by intersect() above. A deeper layer is walked
// by intersectBehind: the same clip, steps, flags and bisection, but a crossing of the stored
// surface counts either way (a ray from beside the camera meets surfaces that face away from it
// from their back: a teapot's far side), is no hit where the surface jumps (the discontinuity
// rule, per layer), and nothing is carried on behind an occluder (the next layer holds it).
//
// The nearest hit among the layers is the ray's. A ray that never goes behind layer 0 before its
// layer-0 hit (or its exit) stays in front of every deeper layer too (each lies behind layer 0
// along the camera's rays), so the deeper layers are walked only when intersect() reports that it
// went hidden, and only from there on (the ray's origin moved to firstHidden); then a deeper hit
// short of the layer-0 hit wins. A hidden (carried-on, guessed)
// layer-0 hit is no hit in a layered image: its layers hold what lies behind the occluders, and a
// ray that meets none of them there meets nothing. A one-layer image is intersected exactly as
// before.
std::optional<DepthHit> intersectBehind(const DepthImage& layer, const Ray& ray, const IntersectOptions& options = {});

// The options' and rays' checks shared with the GL twin: conus::Error(InvalidArgument) for a
// step outside (0, 64], refinements outside [0, 64], maxSteps outside [1, 1<<20], a non-positive
// tMax, or a ray with a non-finite or non-unit direction.
void checkIntersectOptions(const IntersectOptions& options);
void checkRay(const Ray& ray);

}  // namespace conus::codec
