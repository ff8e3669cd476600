// What a built map achieves, measured on the map itself (not on the target it was built from):
// - cell density: the area of each distorted grid cell over the area of its undistorted cell, the
//   mean of det J over the cell. It is the density "on the map's own grid", the one that
//   `--min-density` and `--max-density` promise.
// - anisotropy: the ratio of the Jacobian's singular values, in pixel units (the CoNUS image and
//   the source share an aspect, so a circle of source pixels stays a circle when it is 1). A CoNUS
//   pixel's footprint in the source is an ellipse this elongated: the encode filter must low-pass
//   along its long axis and the decode stretches a sample along it.
#pragma once

#include <glm/glm.hpp>

#include "conus/codec/map/sampling_map.h"
#include "conus/core/map_rules.h"

namespace conus::codec {

// The area of distorted cell (i,j) over its undistorted area: its mean density (for a convex cell,
// half the cross product of its diagonals).
double cellDensity(const map_rules::GridView& grid, int i, int j);
// The same for the cell of `map` that holds undistorted p.
double cellDensityAt(const SamplingMap& map, glm::dvec2 p);

// The mean Jacobian of the cell of `map` that holds undistorted p: a bilinear map's Jacobian is
// linear along each axis, so its mean over a cell is its value at the centre.
glm::dmat2 cellJacobianAt(const SamplingMap& map, glm::dvec2 p);

// Singular value ratio (>= 1) of J in pixel units; `aspect` is the image's width / height.
double anisotropy(const glm::dmat2& jacobian, double aspect);

struct MapMeasures {
    double minCellDensity = 1, maxCellDensity = 1;  // over the map's cells
    double maxAnisotropy = 1;                         // of every cell's mean Jacobian
    glm::dvec2 mostAnisotropic{0.5, 0.5};             // undistorted point where it is reached
};

MapMeasures measureMap(const SamplingMap& map, double aspect = 1.0);

}  // namespace conus::codec
