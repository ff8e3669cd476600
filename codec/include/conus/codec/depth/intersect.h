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
//      unit of the undistorted image) get proportionally finer steps in the undistorted image;
//   4. stops at the first sample where the ray is at or behind the stored surface (ray depth >=
//      the depth bilinear in the CoNUS image at the distorted point) and refines between that
//      sample and the one before by bisection.
// Depths along the segment come from perspective-correct interpolation (depth / w and t / w are
// linear in the image), so no point is unprojected while stepping.
//
// Surfaces are solid behind what the camera sees: a ray that enters the clipped volume already
// behind the stored surface hits where it enters (the side walls of a relief box). Depth images
// of scenes (reflections) that store the far plane where nothing was seen never hit there, since
// the clipped ray never goes beyond the largest stored depth.
//
// Height fields (depth kind `height`, orthographic camera looking down at the base plane): the
// base plane is the plane through the world origin facing the camera, and height h lies h above
// it toward the camera, i.e. at camera depth depth(origin) - h (heightToDepth below).
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "conus/codec/map/sampling_map.h"
#include "conus/core/camera.h"
#include "conus/core/image.h"
#include "conus/format/container.h"

namespace conus::codec {

class DepthImage {
public:
    // `depths` holds one camera depth per CoNUS pixel (width x height, top row first; finite).
    // Throws conus::Error(InvalidArgument) on a size mismatch or a non-finite depth.
    DepthImage(Camera camera, std::shared_ptr<const SamplingMap> map, int width, int height, std::vector<float> depths);
    // From a CoNUS file with a camera and a Z channel: camera depths as they are, heights through
    // heightToDepth. Throws conus::Error(InvalidArgument) when the file lacks either.
    static DepthImage fromFile(const format::ConusFile& file);

    const Camera& camera() const { return m_camera; }
    const SamplingMap& map() const { return *m_map; }
    int width() const { return m_width; }
    int height() const { return m_height; }
    const std::vector<float>& depths() const { return m_depths; }
    float depthAt(int x, int y) const { return m_depths[static_cast<std::size_t>(y) * m_width + x]; }
    // Bilinear in the CoNUS image at distorted position pd (pixel centres at (i + 0.5) / width,
    // clamped to the edge pixels): what the linear search compares the ray with.
    double sampleDepth(glm::dvec2 pd) const;
    double minDepth() const { return m_minDepth; }
    double maxDepth() const { return m_maxDepth; }

private:
    Camera m_camera;
    std::shared_ptr<const SamplingMap> m_map;
    int m_width = 0, m_height = 0;
    std::vector<float> m_depths;
    double m_minDepth = 0, m_maxDepth = 0;
};

// The camera depth of height h above a height field's base plane (see the file comment).
double heightToDepth(const Camera& camera, double height);

// The clip's depth range is widened by this fraction of (1 + its largest magnitude), so that a
// surface exactly at the range's end is still reached despite rounding (GLSL: same constant).
inline constexpr double kIntersectDepthMargin = 1e-5;

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
    // When the ray entered the clipped volume already behind the surface (steps == 0): the face it
    // came through, 0..5 for u = 0, u = 1, v = 0, v = 1, the nearest and the farthest depth; else -1.
    int face = -1;
};

// The first hit along `ray` (direction unit), or nothing. Never throws for a finite ray.
std::optional<DepthHit> intersect(const DepthImage& image, const Ray& ray, const IntersectOptions& options = {});

// The options' and rays' checks shared with the GL twin: conus::Error(InvalidArgument) for a
// step outside (0, 64], refinements outside [0, 64], maxSteps outside [1, 1<<20], a non-positive
// tMax, or a ray with a non-finite or non-unit direction.
void checkIntersectOptions(const IntersectOptions& options);
void checkRay(const Ray& ray);

}  // namespace conus::codec
