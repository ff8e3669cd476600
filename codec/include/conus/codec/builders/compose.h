// Composition of sampling maps (paper section 3.1, Figure 9): maps are combined through their
// distortion vector fields D(p) = SM(p) - p (p undistorted, SM Eq. 1). A map can be translated,
// scaled about a centre, and several maps added with per-input weights.
//
// Rules shared by translateMap, scaleMap and addMaps:
// - The displacement rule first (fitDisplacement): output node = p + scale * D(p), scale = 1 when
//   that map is valid, otherwise the largest valid factor found by bisection on [0,1].
// - Each also has a target density, the density the composition stands for: the input's density
//   pattern moved or scaled (translate, scale), or 1 + sum_i w_i (d_i / c_i - 1) for a sum, d_i
//   the density of input i and c_i its lowest (its context), floored at kComposeFloor. When the
//   displacement rule had to scale (it folds), or left a cell sparser than half the target's
//   lowest density (normalized to mean 1), or a cell more anisotropic than the bound
//   (map_rules::kMaxAnisotropy, in pixels of the given aspect), the map is built from the target
//   density instead (buildMapFromDensity, the bounded builder): adding displacements that fold
//   leaves bands of almost no samples, which no global factor repairs.
// - So every result is a valid map (rules V7..V11), none sparser than half the target's lowest
//   density nor more anisotropic than the bound where the builder could hold them (its report
//   says), and nothing throws for a combination that folds.
// - Boundary nodes keep only the tangential part of their displacement (the normal part is
//   dropped) so they stay exactly on their edge; corners stay fixed.
// - Displacement fetched from outside [0,1]^2 (translation, scaling) is zero, and so that a moved
//   or scaled pattern has no seam, it fades to zero over a band inside each edge of its square
//   that lands inside the output (a tenth of the pattern, at least two cells), and its normal
//   part fades to zero over a band inside each output edge that cuts it (a quarter of the frame or
//   more). The target density outside the pattern's square is its edge's, continued.
#pragma once

#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "conus/codec/builders/density_map.h"
#include "conus/codec/map/sampling_map.h"

namespace conus::codec {

// The lowest relative density a sum's target density is floored at (1 is the context's).
inline constexpr double kComposeFloor = 1.0 / 64.0;

struct ComposeResult {
    SamplingMap map;
    double scale = 1.0;     // factor applied to all displacement vectors; 1: none needed
    bool rebuilt = false;   // built from the target density (the rules above)
    DensityMapReport report = {};  // of the rebuild: what the builder held
};

// The shared rule above: node (i,j) = p + scale * displacement[j*columns+i]. Throws
// conus::Error(InvalidArgument) for a grid smaller than 2x2 or a span of the wrong size.
ComposeResult fitDisplacement(int columns, int rows, std::span<const glm::dvec2> displacement);

// Moves the distortion pattern by `offset`: D'(p) = D(p - offset), zero where p - offset leaves
// the unit square, faded at the cuts (above). Same grid as the input. `aspect`: the image's
// width / height, for the anisotropy bound.
ComposeResult translateMap(const SamplingMap& map, glm::dvec2 offset, double aspect = 1.0);

// Scales the pattern about `centre` by `factor` > 0: D'(p) = factor * D(c + (p - c) / factor), so
// the density pattern is the same one, `factor` times as large, faded at the cuts (above). Same
// grid as the input.
ComposeResult scaleMap(const SamplingMap& map, double factor, glm::dvec2 centre = {0.5, 0.5}, double aspect = 1.0);

// The paper's addition: node = p + sum_i w_i D_i(p) on a columns x rows grid. `weights` is empty
// (all 1) or holds one finite weight per map. An empty `maps` gives the identity.
ComposeResult addMaps(std::span<const SamplingMap> maps, int columns, int rows, std::span<const double> weights = {},
                      double aspect = 1.0);

}  // namespace conus::codec
