// Depth images in conus-view (Z mode, the inspector's 3-D point), without GL: a CoNUS file's `Z`
// channel as a picture, and the world point a CoNUS pixel of a depth image saw.
#pragma once

#include <optional>

#include <glm/glm.hpp>

#include "conus/codec/map/sampling_map.h"
#include "conus/core/image.h"
#include "conus/format/container.h"

namespace conus::viewer {

// The depths a picture spans: the smallest and largest valid Z of the file (a valid Z is finite,
// inside the file's declared [near, far) when it declares one, and covered where there is an A
// channel), so the ramp uses its whole length on what the image holds.
struct DepthSpan {
    double nearest = 0, farthest = 0;
    bool empty() const { return !(farthest >= nearest); }
};

// True when the file has a `Z` channel.
bool hasDepth(const format::ConusFile& file);
// Whether pixel (x, y) of the file's image holds a surface (not background or a miss).
bool validDepth(const format::ConusFile& file, int x, int y);
DepthSpan depthSpan(const format::ConusFile& file);

// The background colour of the Z picture (linear light): a slate blue, a hue the ramp never takes.
inline constexpr float kDepthBackground[3] = {0.03f, 0.08f, 0.22f};

// The file with its image replaced by R, G, B = the density ramp (core/display.h, inferno) of the
// depth, bright near and dark far, as linear light (the display curve gives back the ramp's
// colours); background pixels kDepthBackground. Same map, size and camera: the viewer decodes it
// like any image. conus::Error(InvalidArgument) when the file has no Z channel.
format::ConusFile depthPicture(const format::ConusFile& file);

// The 3-D point a depth image's CoNUS pixel saw: the pixel centre undistorted by the map's exact
// inverse, the file's camera ray through it, the pixel's camera depth. nullopt when the file is not
// a camera-depth image with a camera, or the pixel holds no surface.
std::optional<glm::dvec3> worldPoint(const format::ConusFile& file, const codec::SamplingMap& map, glm::ivec2 conusPixel);

}  // namespace conus::viewer
