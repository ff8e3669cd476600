// The planar pinhole camera (PPC) every 3-D part of CoNUS shares: where the eye is, where it
// looks, what it sees; the FPC (fpc.h) is this camera plus a distortion of its image plane.
//
// Conventions (spec/conus-format.md, "Camera"; they are OpenEXR's own):
// - Camera space is left-handed: x right, y up, +z the viewing direction. `depth` is camera-space
//   z, the distance along the view axis (the spec's cameraDepth), positive in front of the eye.
// - The image plane is (u,v) in [0,1]^2, u right, v down, (0,0) the top-left corner: the spec's
//   convention, which is also OpenEXR's NDC (worldToNDC sends a point there after division by w).
// - Matrices are OpenEXR's: row vectors (p' = p M), 16 floats row-major. That is exactly the
//   memory layout of glm's column-vector, column-major matrix, so they load as they are.
// Errors are conus::Error(InvalidArgument): a degenerate camera, a non-finite or singular matrix.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include <glm/glm.hpp>

#include "conus/core/bounds.h"
#include "conus/core/enum_names.h"

namespace conus {

enum class Projection { Perspective, Orthographic };
constexpr auto enumNameTable(Projection) {
    return makeEnumNameTable<Projection>(
        "projection", {{Projection::Perspective, "perspective"}, {Projection::Orthographic, "orthographic"}});
}

struct Ray {
    glm::dvec3 origin{0.0};
    glm::dvec3 direction{0.0, 0.0, 1.0};  // unit
};

class Camera {
public:
    // Looking from `eye` at `target` with `up` roughly up; the vertical field of view in degrees,
    // in (0, 180); aspect = image width / height; clip distances 0 < near < far.
    static Camera perspective(glm::dvec3 eye, glm::dvec3 target, glm::dvec3 up, double fovYDegrees, double aspect,
                              double near, double far);
    // A view volume `height` world units tall (width = height * aspect) around the axis from eye
    // to target; near and far are depths along that axis (near < far, either may be negative).
    static Camera orthographic(glm::dvec3 eye, glm::dvec3 target, glm::dvec3 up, double height, double aspect,
                               double near, double far);
    // From the container's attributes (worldToCamera, worldToNDC, conus:projection).
    static Camera fromMatrices(const std::array<float, 16>& worldToCamera, const std::array<float, 16>& worldToNDC,
                               Projection projection);

    std::array<float, 16> worldToCamera() const;
    std::array<float, 16> worldToNDC() const;
    Projection projection() const { return m_projection; }

    // World -> (u, v, depth). Depth <= 0 for a point behind a perspective eye (u, v then mean nothing).
    glm::dvec3 project(glm::dvec3 world) const;
    // The world point at image position uv and `depth`.
    glm::dvec3 unproject(glm::dvec2 uv, double depth) const;
    // The ray through uv: from the eye (perspective) or from the plane of depth 0 (orthographic).
    // A point at distance t along it has depth t * dot(direction, forward()) (+ origin's depth).
    Ray ray(glm::dvec2 uv) const;

    // World -> NDC as one column-vector matrix: (u, v) = xy / w of worldToNdcMatrix() * (p, 1), and
    // z / w runs from 0 at near to 1 at far (what a rasterizer needs, once mapped to its clip space).
    glm::dmat4 worldToNdcMatrix() const { return m_cameraToNdc * m_worldToCamera; }
    // The vertical field of view in degrees of a perspective camera (0 for an orthographic one).
    double verticalFovDegrees() const;

    glm::dvec3 eye() const;      // the centre of projection (orthographic: the origin of camera space)
    glm::dvec3 forward() const;  // unit viewing direction in world space
    double near() const { return m_near; }
    double far() const { return m_far; }

private:
    Camera(const glm::dmat4& worldToCamera, const glm::dmat4& cameraToNdc, Projection projection, double near, double far);
    glm::dmat4 m_worldToCamera, m_cameraToWorld;
    glm::dmat4 m_cameraToNdc;
    Projection m_projection = Projection::Perspective;
    double m_near = 0.1, m_far = 1000.0;
};

// ---- Framing a scene ----

struct ClipRange {
    double near = 0, far = 0;
};

// The clip distances that hold all of `box` seen from `eye` looking along unit `forward`: its
// corners' depths widened a little (far 2% past the farthest, near 2% short of the nearest but at
// least far / 10^4, so depth keeps its precision). std::nullopt when the box lies entirely behind
// the eye.
std::optional<ClipRange> clipRangeFor(const AxisBox& box, glm::dvec3 eye, glm::dvec3 forward);

// A perspective camera looking at the box's centre from `direction` (toward the eye; one along
// `up` is replaced by (1, 0, 0.2)), as close as keeps the box's corners within 90% of the frame
// and never inside its bounding sphere, clipped by clipRangeFor: a default view of a scene.
Camera framingCamera(const AxisBox& box, glm::dvec3 direction, glm::dvec3 up, double aspect, double fovYDegrees = 40.0);

// A perspective camera at `eye` looking at `target` (vertical field of view in degrees), its clip
// range the one that holds `box` (clipRangeFor): a user's view of a scene. Throws
// InvalidArgument when the eye is the target or looks along `up`, and when the box lies entirely
// behind the eye (`what` names the box in that message: "the model", "the volume").
Camera lookingAtBox(const AxisBox& box, glm::dvec3 eye, glm::dvec3 target, glm::dvec3 up, double fovYDegrees, double aspect,
                    const std::string& what);

}  // namespace conus
