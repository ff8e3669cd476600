// Automatic sampling maps from an importance image (the paper's future work): higher importance
// gets more samples, with a floor so context keeps a minimum rate.
//
// The target density is rho = clamp(s * I, minDensity, maxDensity), I the importance smoothed on a
// grid of at most 256 cells a side, and s chosen so that rho has mean 1 (the CoNUS image has as
// many pixels as a uniform one): so `minDensity` is exactly the density context gets, and
// `maxDensity` caps the magnification (density 16 = linear rate 4). Two methods build the map:
// - Flow (default): a true 2-D map whose Jacobian determinant follows rho (density_map.h), built
//   by `builder`: the bounded builder by default (every cell's anisotropy under the bound, the
//   density giving way where the importance rises too steeply for it), or Moser's flow.
// - Separable: the baseline; u and v are warped independently by the cumulative marginals of rho,
//   so density is the product of the marginals (bands through every hot spot).
// Flow matches the target far better (tests and bench/notes/2026-11-22-suite-figures.md give the figures), so it is the
// default. Every result is a valid map; all-zero importance gives the identity.
#pragma once

#include "conus/codec/builders/density_map.h"
#include "conus/codec/builders/importance.h"  // importance from the picture itself
#include "conus/codec/map/sampling_map.h"
#include "conus/core/image.h"
#include "conus/core/enum_names.h"
#include "conus/core/map_rules.h"

namespace conus::codec {

enum class AutoMethod { Flow, Separable };
constexpr auto enumNameTable(AutoMethod) {
    return makeEnumNameTable<AutoMethod>("method", {{AutoMethod::Flow, "flow"}, {AutoMethod::Separable, "separable"}});
}

struct AutoMapOptions {
    int columns = map_rules::kDefaultSide, rows = map_rules::kDefaultSide;  // map grid
    double minDensity = 0.25;     // context density (0 < minDensity < 1)
    double maxDensity = 16.0;     // cap of the density (> 1)
    double smoothing = 0.01;      // blur radius as a fraction of the image width
    AutoMethod method = AutoMethod::Flow;
    double maxAnisotropy = 0;     // flow: DensityMapOptions::maxAnisotropy (0: the builder's default)
    DensityBuilder builder = DensityBuilder::Bounded;  // flow: which 2-D builder
    bool refuseBounds = true;     // false: return the map closest to the bounds instead of refusing
    // The density the frame has apart from the importance (> 0, any size, about 1 on average; under
    // `encode` the picture's own detail, frame_budget.h's ownDetailContext), which the importance's
    // density multiplies: minDensity and maxDensity then bound that factor, not the cells, which
    // are not pushed towards them. Null: 1 everywhere.
    const DensityField* context = nullptr;
};

// How far the achieved cell density (map_measures.h) may stray outside [minDensity, maxDensity]:
// the promise of `--min-density` and `--max-density`.
inline constexpr double kDensityBoundTolerance = 0.05;

// The target density field for an importance image (one channel, or the mean of R,G,B); throws
// conus::Error(InvalidArgument) on NaN/Inf or negative importance, or bad options.
DensityField importanceToDensity(const Image& importance, const AutoMapOptions& options = {});

// The flow map follows the target, corrected (a few multiplicative rounds) until its cell density
// lies within kDensityBoundTolerance of [minDensity, maxDensity]. Throws conus::Error
// (InvalidArgument) naming the bounds this importance and grid can reach when it cannot.
SamplingMap buildAutoMap(const Image& importance, const AutoMapOptions& options = {});
SamplingMap buildSeparableMap(const DensityField& target, int columns, int rows);

// Pearson correlation between the density a map achieves and a target field (both sampled at the
// field's cell centres): 1 means the map follows the target exactly (up to scale).
double densityCorrelation(const SamplingMap& map, const DensityField& target);

}  // namespace conus::codec
