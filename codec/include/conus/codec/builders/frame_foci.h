// Closed-form per-frame focus maps (paper sections 3.1 and 6): each focus is a canonical circular
// lens, a radial displacement with linear magnification k at its centre, falling smoothly to the
// identity at a falloff radius, and the lenses' displacement vectors are added at every node (the
// paper's composition). Built by evaluating the nodes directly, with no density grid, so a 65x65 map
// of 8 foci takes microseconds: the paper rebuilds the map every frame.
//
// The lens of focus (u,v,r,k): at distance d from its centre (in widths, so it is circular in
// pixels given the aspect), with x = d / R and R = c r (c = kFalloffRadii), a node moves radially to
//   R h(x),  h(x) = x (1 + (k - 1) (1 - x)^2 / (1 + (c (k - 1) x)^4)^(1/4))   for x < 1,
// and stays beyond. h(0) = 0, h'(0) = k, h(1) = 1, h'(1) = 1 (the lens joins the identity without
// a kink), and h is strictly increasing for every k in [1, 64] (its slope stays above 0.2), so one
// lens never folds. The magnification holds near k out to x ~ 1 / (c (k - 1)), which the lens shows
// as a disc of radius ~ r k / (k - 1): r is the radius of the magnified disc in the CoNUS image. Boundary nodes keep only the
// component along their edge. A sum of lenses can fold, leave the frame or stretch a cell past the
// anisotropy bound (options.maxAnisotropy, 0: map_rules::kMaxAnisotropy; overlapping lenses and
// lenses cut by the frame's edge do); the summed displacement is then scaled by one factor s in
// (0, 1], s = min(1, kFoldMargin * s_fold, kAnisotropyMargin * s_bound), where s_fold is the exact
// factor at which the first cell stops passing V11 (map_rules.h) or a node leaves [0,1]^2 and
// s_bound the exact factor at which a cell's mean Jacobian reaches the bound (both roots of
// quadratics in s). Both are continuous functions of the foci, so frames built from moving foci do
// not jump.
#pragma once

#include <span>

#include "conus/codec/builders/foci.h"
#include "conus/codec/map/sampling_map.h"

namespace conus::codec {

// The falloff radius of a lens in multiples of its focus's r; also where its magnified core ends
// (above), so that the core is shown about r wide whatever k.
inline constexpr double kFalloffRadii = 2.5;
// The share of the fold factor a folding sum is scaled to, keeping every cell clear of V11's limit.
inline constexpr double kFoldMargin = 0.9;
// The share of the bound's factor it is scaled to (rounding to float stays under the bound).
inline constexpr double kAnisotropyMargin = 0.999;

// The lens profile h(x) above, for x in [0, 1]; x outside is returned unchanged.
double lensProfile(double x, double k);

// The map of `foci` on options.columns x options.rows nodes with options.aspect and
// options.maxAnisotropy; options.composition and builder are ignored (this is always the additive
// composition of lenses). No foci: the identity. Throws conus::Error(InvalidArgument) for a focus outside [0,1]^2, r <= 0 or k outside
// [1, 64], or a grid under 2x2.
SamplingMap buildFrameFociMap(std::span<const Focus> foci, const FociOptions& options = {});

}  // namespace conus::codec
