// What the density builders share inside codec: a target density averaged over each grid cell, the
// importance's scale, and the comparison of a built map with its target (DensityMapReport).
#pragma once

#include <vector>

#include "conus/codec/builders/density_map.h"

namespace conus::codec {

// The target's mean over each cell of a columns x rows node grid (row-major, (columns-1) x
// (rows-1) cells), normalized to mean 1 over the cells.
std::vector<double> cellTargets(const DensityField& target, int columns, int rows);

// The scale importanceToDensity puts on the importance `field` (its cells' `context` weights):
// the least s (a double) with mean(context * clamp(s * field, floor, cap)) >= 1, the mean taken
// in index order, given that s = sMax reaches it; what bisecting [0, sMax] finds, in a tenth of
// the passes.
double leastScaleForMeanOne(const std::vector<double>& field, const std::vector<double>& context, double floor, double cap,
                            double sMax);

// Fills report.maxAnisotropy (in pixels of `aspect`) and the achieved / target density ratios of `map`.
void compareWithTarget(const SamplingMap& map, const DensityField& target, double aspect, DensityMapReport& report);

}  // namespace conus::codec
