// Focus-plus-context sequences (paper section 6, Figure 7): each frame's foci follow chosen moving
// objects (the city's cars) by projecting their centres through the camera, and each frame's map is
// built from those foci, so the magnified regions ride along with the objects.
//
// Continuity is the rule: nothing may jump from one frame to the next. A focus whose object nears
// the frame's border keeps its centre clamped to the frame and fades out (its magnification falls
// linearly to 1 as the projected centre goes from the border to one radius beyond it; a radius is
// measured in widths, as Focus::r), and an object at or behind the camera's near plane has no focus.
// Two foci that pass each other merge and separate smoothly because the map of a set of foci is a
// continuous function of their parameters (codec/builders/frame_foci.h).
#pragma once

#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "conus/codec/builders/foci.h"
#include "conus/codec/map/sampling_map.h"
#include "conus/core/camera.h"

namespace conus::codec {

struct TrackOptions {
    double radius = 0.08;  // each focus's radius, a fraction of the image width
    double k = 4;          // each focus's magnification (linear, at its centre)
};

// The foci of `points` (world) seen by `camera` in an image of `aspect` = width / height, by the
// rule above; those that faded out entirely are left out.
std::vector<Focus> trackedFoci(const Camera& camera, std::span<const glm::dvec3> points, double aspect,
                                      const TrackOptions& options = {});

// One frame's map. The add composition (the animation's, the paper's) is built in closed form by
// buildFrameFociMap, microseconds a frame; the density composition by buildFociMap.
// The identity of the same grid when there are no foci.
SamplingMap frameMap(std::span<const Focus> foci, const FociOptions& options);

// The largest distance any node moved between two maps of the same grid (normalized units).
double largestNodeStep(const SamplingMap& from, const SamplingMap& to);

}  // namespace conus::codec
