// Digital elevation models for `conus heightfield`: image files through OpenImageIO (16-bit PNG /
// TIFF read as [0,1], float EXR as is), NumPy .npy arrays and .npz archives (libzip; the first
// 2-D array, "elevation" when present, as in matplotlib's jacksboro_fault_dem.npz), and the
// built-in procedural terrain `procedural[:SIZE[:SEED]]`. Row 0 is the field's far edge.
// Errors are conus::Error (Io, InvalidArgument, Unsupported) naming the file and the problem.
#pragma once

#include <string>

#include <glm/glm.hpp>

#include "conus/core/image.h"

namespace conus::cli {

struct Dem {
    Image heights;  // one channel "Z", already multiplied by the height scale
    glm::dvec2 cellMetres{0.0, 0.0};  // sample spacing (x, y) when the file says, else 0
    std::string description;          // for messages: "jacksboro_fault_dem.npz elevation 403x344 int16"
};

// `heightScale` multiplies every value (images in [0,1] need the full range in metres).
Dem readDem(const std::string& source, double heightScale = 1.0);

}  // namespace conus::cli
