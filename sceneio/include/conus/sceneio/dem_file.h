// Digital elevation models read into a height image: image files through imageio (16-bit PNG /
// TIFF read as [0,1], float EXR as is), NumPy .npy arrays and .npz archives (libzip, inside
// sceneio/src/dem_file.cpp only; the first 2-D array, "elevation" when present, as in matplotlib's
// jacksboro_fault_dem.npz). Row 0 is the field's far edge (codec/depth/heightfield.h).
// Errors are one-line conus::Error naming the file and the problem: Io (missing, not a regular
// file, unreadable), Corrupt (a malformed array or archive, a height that is not finite),
// LimitExceeded (past kMaxDemSamples, checked before the data is read), Unsupported.
#pragma once

#include <string>

#include <glm/glm.hpp>

#include "conus/core/image.h"

namespace conus::sceneio {

struct Dem {
    Image heights;  // one channel "Z", already multiplied by the height scale
    glm::dvec2 cellMetres{0.0, 0.0};  // sample spacing (x, y) when the file says, else 0
    std::string description;          // for messages: "jacksboro_fault_dem.npz elevation 403x344 int16"
};

// `heightScale` multiplies every value (images in [0,1] need the full range in metres); it must be
// finite and non-zero (InvalidArgument).
Dem readDem(const std::string& path, double heightScale = 1.0);

// Heights made in memory (a procedural terrain) held to the rules a file's are: `heightScale`
// checked and applied, every height finite afterwards.
Dem demFromHeights(Image heights, double heightScale, std::string description);

}  // namespace conus::sceneio
