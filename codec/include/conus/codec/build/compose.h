// Composition of sampling maps (paper section 3.1, Figure 9): maps are combined through their
// distortion vector fields D(p) = SM(p) - p (p undistorted, SM Eq. 1). A map can be translated,
// scaled about a centre, and several maps added with per-input weights.
//
// Rules shared by every function below:
// - Each returns a ComposeResult: a valid map (rules V7..V11) and the global factor `scale` in
//   [0,1] that was applied to the combined displacement field. The rule is the same everywhere
//   (fitDisplacement): output node = p + scale * D(p), with scale = 1 when that map is valid,
//   otherwise the largest valid factor found by bisection on [0,1] (24 halvings). scale = 0 is the
//   identity, which is always valid, so a valid map always comes back and nothing throws for a
//   combination that folds.
// - Boundary nodes keep only the tangential part of their displacement (the normal part is
//   dropped) so they stay exactly on their edge; corners stay fixed.
// - Displacement fetched from outside [0,1]^2 (translation, scaling) is zero. So that a moved or
//   scaled pattern has no seam, its displacement fades to zero over a band inside each edge of
//   its square that lands inside the output (a tenth of the pattern, at least two cells), and its
//   normal part fades to zero over a band inside each output edge that cuts it (a quarter of the
//   frame or more, so that the fade changes the density by at most a half). Density is continuous across both.
#pragma once

#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "conus/codec/map/sampling_map.h"

namespace conus::codec {

struct ComposeResult {
    SamplingMap map;
    double scale = 1.0;  // factor applied to all displacement vectors; 1: none needed
};

// True when `nodes` (columns x rows, row-major) form a valid map (rules V8..V11): the test of
// core/map_rules.h, which format::validateGrid words.
bool isValidGrid(int columns, int rows, std::span<const glm::vec2> nodes);

// The shared rule above: node (i,j) = p + scale * displacement[j*columns+i]. Throws
// conus::Error(InvalidArgument) for a grid smaller than 2x2 or a span of the wrong size.
ComposeResult fitDisplacement(int columns, int rows, std::span<const glm::dvec2> displacement);

// Moves the distortion pattern by `offset`: D'(p) = D(p - offset), zero where p - offset leaves
// the unit square, faded at the cuts (above). Same grid as the input.
ComposeResult translateMap(const SamplingMap& map, glm::dvec2 offset);

// Scales the pattern about `centre` by `factor` > 0: D'(p) = factor * D(c + (p - c) / factor), so
// the density pattern is the same one, `factor` times as large, faded at the cuts (above). Same
// grid as the input.
ComposeResult scaleMap(const SamplingMap& map, double factor, glm::dvec2 centre = {0.5, 0.5});

// The paper's addition: node = p + sum_i w_i D_i(p) on a columns x rows grid. `weights` is empty
// (all 1) or holds one finite weight per map. An empty `maps` gives the identity.
ComposeResult addMaps(std::span<const SamplingMap> maps, int columns, int rows, std::span<const double> weights = {});

}  // namespace conus::codec
