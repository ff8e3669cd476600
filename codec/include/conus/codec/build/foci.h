// Circular focus maps (spec/ "foci"): a focus u,v,r,k magnifies a disc of radius r (a fraction of
// the image width, circular in pixels) so that the linear sampling rate at its centre is k times
// the rate far from every focus. Density inside the disc is k^2 times the context density and
// falls smoothly to it between r and 2r.
//
// Two ways to build several foci:
// - Density (default): one map from the joint density of all foci (density_map.h); the region
//   between foci is squeezed least.
// - Add: the paper's composition: each focus's own map, displacement vectors added; if the sum
//   folds, displacements are scaled down until every cell is valid.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "conus/codec/map/sampling_map.h"
#include "conus/format/container.h"
#include "conus/core/map_rules.h"

namespace conus::codec {

struct Focus {
    double u = 0.5, v = 0.5, r = 0.1, k = 2;
};

enum class FociComposition { Density, Add };

struct FociOptions {
    int columns = map_rules::kDefaultSide, rows = map_rules::kDefaultSide;  // grid of the built map
    double aspect = 1.0;          // image width / height: makes a focus circular in pixels
    FociComposition composition = FociComposition::Density;
    double maxAnisotropy = 0;     // density composition: DensityMapOptions::maxAnisotropy (0: none)
};

// Throws conus::Error(InvalidArgument) for a focus outside [0,1]^2, r outside (0, 1] or k outside
// [1, 64] (NaN fails): what every builder of foci asks of a focus.
void checkFocus(const Focus& focus);

// Throws conus::Error(InvalidArgument) for a focus outside [0,1]^2, r <= 0 or k < 1 or k > 64.
SamplingMap buildFociMap(std::span<const Focus> foci, const FociOptions& options = {});

// The linear magnification `map` reaches at each focus centre: the square root of its density
// there over its lowest density (which stands for "far from every focus"). 1 for the identity.
std::vector<double> reachedMagnification(const SamplingMap& map, std::span<const Focus> foci);

// Throws conus::Error(InvalidArgument) when `map` (built for `foci` with `options`) reaches less
// than half of some focus's extra magnification (below 1 + (k - 1) / 2), naming the smallest grid
// of 2^j + 1 nodes a side (up to 257) that does: a grid too coarse for a focus ignores it (a 2x2
// grid is always the identity), and a file would record a focus its map does not have.
void checkFociHeld(const SamplingMap& map, std::span<const Focus> foci, const FociOptions& options);

// The target density (before normalization) of a set of foci at undistorted p.
double fociDensity(std::span<const Focus> foci, double aspect, double u, double v);

// "u,v,r,k" -> Focus; throws conus::Error(InvalidArgument) with the reason.
Focus parseFocus(const std::string& text);

// Analytic parameters for the file: kind "foci", the foci and how they were composed.
format::AnalyticMap toAnalytic(std::span<const Focus> foci, FociComposition composition);

}  // namespace conus::codec
