// Building a sampling map whose density follows a target: the map sends undistorted p to distorted
// p' with det(J) = target(p) / mean(target). Used by the foci builder (joint density of all foci),
// by automatic maps from importance and by composition.
//
// Two builders (DensityBuilder):
// - Bounded (default, bounded_map.h): the grid's nodes are optimised directly for the density
//   with every cell's anisotropy under a bound (map_rules::kMaxAnisotropy unless asked otherwise).
//   Where the target cannot be followed within the bound, the density gives way, not the bound,
//   and the report says by how much.
// - Flow (Moser's flow): with rho the target normalized to mean 1, solve the Neumann Poisson
//   problem lap(phi) = rho - 1 and move every node along v_t = grad(phi) / ((1-t) rho + t) for t in
//   [0,1]. The flow of a smooth field is injective and its normal velocity is zero on the boundary,
//   so edge nodes stay on their edges and corners stay put: valid by construction (and checked).
//   It shears: thin strips of the border are pulled far into a dense region (anisotropy in the
//   hundreds). Where the grid cannot follow the flow (a cell folds or comes out sparser than half
//   the lowest target density), or the anisotropy limit is exceeded, the density is tempered to
//   target^gamma, the largest gamma found by bisection that gives a valid map within the limit
//   (gamma = 0 is the identity). Kept for comparison (bench/notes).
// - Transport: the optimal-transport (Brenier) map of the same density, the gradient of a convex
//   potential u with det D^2 u = rho, by the Benamou-Froese-Oberman iteration (a Neumann Poisson
//   solve per step, so edges stay on their edges). It moves points least and is curl-free, but
//   nothing bounds its anisotropy. For comparison only (bench/notes).
#pragma once

#include <algorithm>
#include <vector>

#include "conus/codec/map/sampling_map.h"
#include "conus/core/map_rules.h"

namespace conus::codec {

struct DensityField {
    int width = 0, height = 0;   // samples over [0,1]^2, cell-centred like pixels
    std::vector<float> values;   // > 0 everywhere, finite
};

// The field's sample whose cell holds p = (u, v) in [0,1]^2 (nearest; outside, the border's).
inline float densityAt(const DensityField& field, double u, double v) {
    const int x = std::clamp(static_cast<int>(u * field.width), 0, field.width - 1);
    const int y = std::clamp(static_cast<int>(v * field.height), 0, field.height - 1);
    return field.values[std::size_t(y) * field.width + x];
}

enum class DensityBuilder { Bounded, Flow, Transport };

struct DensityMapOptions {
    int columns = map_rules::kDefaultSide, rows = map_rules::kDefaultSide;  // map grid size
    int steps = 48;               // Flow: integration steps (RK4)
    // Largest ratio of the Jacobian's singular values allowed anywhere (map_measures.h, in the
    // pixel units of the density field, whose samples are square). 0: map_rules::kMaxAnisotropy
    // for Bounded, no limit for Flow. Flow meets it by tempering the density (below), so a tight
    // limit costs magnification everywhere; Bounded lets the density give way only where needed.
    double maxAnisotropy = 0;
    DensityBuilder builder = DensityBuilder::Bounded;
    // Width / height of the picture, for the anisotropy in pixels; 0: the field's (fieldAspect),
    // which rounding of its sample counts may leave a little off.
    double aspect = 0;
    // Bounded: the lowest density a cell should keep (the target normalized to mean 1), held by a
    // steep penalty: where the target cannot be followed within the bound, the peaks give way
    // instead of the context. 0: none.
    double minDensity = 0;
};

// What the builder had to give up, measured on the map it returns.
struct DensityMapReport {
    // Flow: the density it followed is target^gamma (gamma = 1: the target itself; < 1 where the
    // grid folded beyond repair or the anisotropy limit bound). Bounded: always 1.
    double gamma = 1;
    bool anisotropyBound = false;  // Flow: the limit, not folding, set gamma
    double bound = 0;              // the anisotropy bound applied (0: none)
    double maxAnisotropy = 1;      // the map's largest cell anisotropy (map_measures.h)
    // Achieved over target cell density (both normalized to mean 1), at its lowest and highest
    // over the cells: 1 and 1 when the map follows the target exactly.
    double lowestRatio = 1, highestRatio = 1;
    double peakRatio = 1;          // the same ratio at the cell of the highest target density
    int iterations = 0;            // Bounded: optimiser iterations over all levels
};

// The aspect (width / height) of the pixels the density field's samples stand for: its own.
inline double fieldAspect(const DensityField& field) { return double(field.width) / field.height; }
// The aspect a build uses: options.aspect, or the field's.
inline double buildAspect(const DensityField& field, const DensityMapOptions& options) {
    return options.aspect > 0 ? options.aspect : fieldAspect(field);
}

// Builds with options.builder; throws conus::Error(InvalidArgument) for a field with a value that
// is not finite and > 0, or bad options.
SamplingMap buildMapFromDensity(const DensityField& target, const DensityMapOptions& options = {},
                                DensityMapReport* report = nullptr);

// The two builders themselves (buildMapFromDensity dispatches; these skip its input checks).
SamplingMap buildFlowMap(const DensityField& target, const DensityMapOptions& options, DensityMapReport* report);
SamplingMap buildBoundedMap(const DensityField& target, const DensityMapOptions& options, DensityMapReport* report);
SamplingMap buildTransportMap(const DensityField& target, const DensityMapOptions& options, DensityMapReport* report);

}  // namespace conus::codec
