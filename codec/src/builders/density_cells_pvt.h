// What the density builders share inside codec: a target density averaged over each grid cell, and
// the comparison of a built map with its target (DensityMapReport).
#pragma once

#include <vector>

#include "conus/codec/builders/density_map.h"

namespace conus::codec {

// The target's mean over each cell of a columns x rows node grid (row-major, (columns-1) x
// (rows-1) cells), normalized to mean 1 over the cells.
std::vector<double> cellTargets(const DensityField& target, int columns, int rows);

// Fills report.maxAnisotropy (in pixels of `aspect`) and the achieved / target density ratios of `map`.
void compareWithTarget(const SamplingMap& map, const DensityField& target, double aspect, DensityMapReport& report);

}  // namespace conus::codec
