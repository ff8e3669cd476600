#include "conus/core/bounds.h"

#include <limits>

namespace conus {
namespace {

template <class Point>
AxisBox boundsOfPoints(std::span<const Point> points) {
    AxisBox box{glm::dvec3(std::numeric_limits<double>::max()), glm::dvec3(std::numeric_limits<double>::lowest())};
    for (const Point& p : points) {
        box.lo = glm::min(box.lo, glm::dvec3(p));
        box.hi = glm::max(box.hi, glm::dvec3(p));
    }
    return box;
}

}  // namespace

AxisBox boundsOf(std::span<const glm::vec3> points) { return boundsOfPoints(points); }
AxisBox boundsOf(std::span<const glm::dvec3> points) { return boundsOfPoints(points); }

}  // namespace conus
