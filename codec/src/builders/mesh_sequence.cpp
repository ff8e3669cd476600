#include "conus/codec/builders/mesh_sequence.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "conus/codec/builders/frame_foci.h"
#include "conus/core/error.h"

namespace conus::codec {

std::vector<Focus> trackedFoci(const Camera& camera, std::span<const glm::dvec3> points, double aspect,
                                      const TrackOptions& options) {
    if (!(options.radius > 0) || !(options.k >= 1) || !(aspect > 0) || !std::isfinite(aspect))
        throw Error(ErrorCode::InvalidArgument, "trackedFoci: radius " + std::to_string(options.radius) + ", k " +
                                                    std::to_string(options.k) + ", aspect " + std::to_string(aspect));
    std::vector<Focus> foci;
    for (const glm::dvec3& point : points) {
        const glm::dvec3 p = camera.project(point);
        if (!(p.z > camera.near()) || !std::isfinite(p.x) || !std::isfinite(p.y)) continue;
        const glm::dvec2 centre = glm::clamp(glm::dvec2(p), glm::dvec2(0.0), glm::dvec2(1.0));
        // How far outside the frame, in widths (v is in heights: a height is 1/aspect widths).
        const glm::dvec2 outside = glm::dvec2(p) - centre;
        const double beyond = std::hypot(outside.x, outside.y / aspect);
        const double weight = 1.0 - beyond / options.radius;
        if (weight <= 0) continue;
        const double k = 1.0 + (options.k - 1.0) * weight;
        if (k <= 1.0) continue;
        foci.push_back({centre.x, centre.y, options.radius, k});
    }
    return foci;
}

SamplingMap frameMap(std::span<const Focus> foci, const FociOptions& options) {
    if (options.composition == FociComposition::Add) return buildFrameFociMap(foci, options);
    if (foci.empty()) return SamplingMap::identity(options.columns, options.rows);
    return buildFociMap(foci, options);
}

double largestNodeStep(const SamplingMap& from, const SamplingMap& to) {
    if (from.columns() != to.columns() || from.rows() != to.rows())
        throw Error(ErrorCode::InvalidArgument, "largestNodeStep: maps of " + std::to_string(from.columns()) + "x" +
                                                    std::to_string(from.rows()) + " and " + std::to_string(to.columns()) +
                                                    "x" + std::to_string(to.rows()) + " nodes");
    double largest = 0;
    for (std::size_t i = 0; i < from.nodes().size(); ++i)
        largest = std::max(largest, static_cast<double>(glm::distance(from.nodes()[i], to.nodes()[i])));
    return largest;
}

}  // namespace conus::codec
