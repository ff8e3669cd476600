// Building a sampling map whose density follows a target: the map sends undistorted p to distorted
// p' with det(J) = target(p) / mean(target). Used by the foci builder (joint density of all foci)
// and by automatic maps from importance.
//
// Method (Moser's flow): with rho the target normalized to mean 1, solve the Neumann Poisson
// problem lap(phi) = rho - 1 and move every node along v_t = grad(phi) / ((1-t) rho + t) for t in
// [0,1]. The flow of a smooth field is injective and its normal velocity is zero on the boundary,
// so edge nodes stay on their edges and corners stay put: valid by construction (and checked).
#pragma once

#include <vector>

#include "conus/codec/map/sampling_map.h"
#include "conus/core/map_rules.h"

namespace conus::codec {

struct DensityField {
    int width = 0, height = 0;   // samples over [0,1]^2, cell-centred like pixels
    std::vector<float> values;   // > 0 everywhere, finite
};

struct DensityMapOptions {
    int columns = map_rules::kDefaultSide, rows = map_rules::kDefaultSide;  // map grid size
    int steps = 48;               // flow integration steps (RK4)
};

SamplingMap buildMapFromDensity(const DensityField& target, const DensityMapOptions& options = {});

}  // namespace conus::codec
