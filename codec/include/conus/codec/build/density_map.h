// Building a sampling map whose density follows a target: the map sends undistorted p to distorted
// p' with det(J) = target(p) / mean(target). Used by the foci builder (joint density of all foci)
// and by automatic maps from importance.
//
// Method (Moser's flow): with rho the target normalized to mean 1, solve the Neumann Poisson
// problem lap(phi) = rho - 1 and move every node along v_t = grad(phi) / ((1-t) rho + t) for t in
// [0,1]. The flow of a smooth field is injective and its normal velocity is zero on the boundary,
// so edge nodes stay on their edges and corners stay put: valid by construction (and checked).
// Where the grid cannot follow the flow (a cell folds or comes out sparser than half the lowest
// target density), or the anisotropy limit is exceeded, the density is
// tempered to target^gamma, the largest gamma found by bisection that gives a valid map within the
// limit (gamma = 0 is the identity).
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
    // Largest ratio of the Jacobian's singular values allowed anywhere (map_measures.h, in the
    // pixel units of the density field, whose samples are square); 0: no limit. Met by tempering
    // the density (below), so a tight limit costs magnification.
    double maxAnisotropy = 0;
};

// What the builder had to give up: the density it followed is target^gamma (gamma = 1: the target
// itself; < 1 where the grid folded beyond repair or the anisotropy limit bound).
struct DensityMapReport {
    double gamma = 1;
    bool anisotropyBound = false;  // the limit, not folding, set gamma
};

// The aspect (width / height) of the pixels the density field's samples stand for: its own.
inline double fieldAspect(const DensityField& field) { return double(field.width) / field.height; }

SamplingMap buildMapFromDensity(const DensityField& target, const DensityMapOptions& options = {},
                                DensityMapReport* report = nullptr);

}  // namespace conus::codec
