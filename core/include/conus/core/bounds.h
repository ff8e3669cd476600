// Axis-aligned bounding boxes of points in world space: what frames a camera on a scene (camera.h's
// clipRangeFor, framingCamera), what a reflector's far plane must reach, the viewer's orbit sphere.
#pragma once

#include <span>

#include <glm/glm.hpp>

namespace conus {

struct AxisBox {
    glm::dvec3 lo{0.0}, hi{0.0};
    glm::dvec3 centre() const { return 0.5 * (lo + hi); }
    // The box's corner `index` (0..7): bit 0 picks hi.x, bit 1 hi.y, bit 2 hi.z.
    glm::dvec3 corner(int index) const {
        return {(index & 1) ? hi.x : lo.x, (index & 2) ? hi.y : lo.y, (index & 4) ? hi.z : lo.z};
    }
};

// The smallest box that holds every point. With no points, lo is the largest double and hi the
// lowest: a box that holds nothing (lo > hi on every axis).
AxisBox boundsOf(std::span<const glm::vec3> points);
AxisBox boundsOf(std::span<const glm::dvec3> points);

}  // namespace conus
