// A scalar volume as CoNUS holds one in memory: dense float samples on a regular grid, x fastest,
// then y, then z; what volume files are read into (OpenVDB, NRRD, raw, at the edge) and what the
// volume renderers cast CoNUS rays through. Plain data.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace conus {

struct Volume {
    int width = 0, height = 0, depth = 0;  // samples along x, y, z
    glm::dvec3 spacing{1.0, 1.0, 1.0};      // world units between neighbouring samples
    std::vector<float> values;              // width * height * depth, x fastest

    std::size_t index(int x, int y, int z) const {
        return (static_cast<std::size_t>(z) * height + y) * static_cast<std::size_t>(width) + x;
    }
    float at(int x, int y, int z) const { return values[index(x, y, z)]; }
    // The world size of the box the samples span (sample centres at i * spacing).
    glm::dvec3 extent() const { return glm::dvec3(width - 1, height - 1, depth - 1) * spacing; }
};

// Throws conus::Error, naming `what`, unless `volume` is well formed: every side at least 2, one
// value per sample, positive finite spacing (InvalidArgument), every value finite (Corrupt, naming
// the first sample that is not). Every reader and renderer of a Volume starts with it.
void checkVolume(const Volume& volume, const std::string& what);

}  // namespace conus
