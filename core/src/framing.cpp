// Framing a scene's box with a camera (camera.h): the clip range that holds it, the default view
// the mesh commands start from, and a user's eye and look-at point clipped to the box.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "conus/core/camera.h"
#include "conus/core/error.h"

namespace conus {

std::optional<ClipRange> clipRangeFor(const AxisBox& box, glm::dvec3 eye, glm::dvec3 forward) {
    double lo = std::numeric_limits<double>::max(), hi = std::numeric_limits<double>::lowest();
    for (int corner = 0; corner < 8; ++corner) {
        const double depth = glm::dot(box.corner(corner) - eye, forward);
        lo = std::min(lo, depth);
        hi = std::max(hi, depth);
    }
    if (!(hi > 0)) return std::nullopt;
    const double far = hi * 1.02 + 1e-6;
    return ClipRange{std::max(lo * 0.98, far * 1e-4), far};
}

Camera framingCamera(const AxisBox& box, glm::dvec3 direction, glm::dvec3 up, double aspect, double fovYDegrees) {
    constexpr double kPi = 3.14159265358979323846;
    const glm::dvec3 centre = box.centre();
    const double radius = std::max(0.5 * glm::length(box.hi - box.lo), 1e-6);
    const double halfY = 0.5 * fovYDegrees * kPi / 180.0, halfX = std::atan(std::tan(halfY) * aspect);
    direction = glm::normalize(direction);
    if (glm::length(glm::cross(direction, glm::normalize(up))) < 1e-6) direction = glm::normalize(glm::dvec3(1.0, 0.0, 0.2));
    // The sphere always fits; then move closer until the box's corners (not the sphere) span 90%
    // of the frame (a few steps: the image size of the box scales about as 1 / distance).
    double distance = 1.05 * radius / std::sin(std::min(halfX, halfY));
    const auto at = [&](double d) {
        const glm::dvec3 eye = centre + direction * d;
        const std::optional<ClipRange> clip = clipRangeFor(box, eye, -direction);
        if (!clip) throw Error(ErrorCode::InvalidArgument, "framingCamera: the box is not finite");
        return Camera::perspective(eye, centre, up, fovYDegrees, aspect, clip->near, clip->far);
    };
    for (int step = 0; step < 4; ++step) {
        const Camera camera = at(distance);
        double extent = 0;
        for (int corner = 0; corner < 8; ++corner) {
            const glm::dvec3 p = camera.project(box.corner(corner));
            extent = std::max({extent, std::abs(p.x - 0.5), std::abs(p.y - 0.5)});
        }
        const double scale = std::clamp(extent / 0.45, 0.5, 1.0);
        if (scale > 0.98) break;
        distance = std::max(distance * scale, radius * 1.05);  // never inside the bounding sphere
    }
    return at(distance);
}

Camera lookingAtBox(const AxisBox& box, glm::dvec3 eye, glm::dvec3 target, glm::dvec3 up, double fovYDegrees, double aspect,
                    const std::string& what) {
    const glm::dvec3 forward = target - eye;
    if (!(glm::length(forward) > 0) || !(glm::length(glm::cross(forward, up)) > 1e-9 * glm::length(forward)))
        throw Error(ErrorCode::InvalidArgument, "the eye must differ from the look-at point and not look along the up vector");
    const std::optional<ClipRange> clip = clipRangeFor(box, eye, glm::normalize(forward));
    if (!clip) throw Error(ErrorCode::InvalidArgument, what + " lies entirely behind the camera");
    return Camera::perspective(eye, target, up, fovYDegrees, aspect, clip->near, clip->far);
}

}  // namespace conus
