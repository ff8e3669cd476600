// Circular focus maps (spec/ "foci"): a focus u,v,r,k magnifies a disc of radius r (a fraction of
// the image width, circular in pixels) so that the linear sampling rate at its centre is k times
// the rate far from every focus. Density inside the disc is k^2 times the context density and
// falls smoothly to it between r and w·r (the falloff: w = 2 and a smoothstep of the density by
// default; FociFalloff).
//
// Two ways to build several foci:
// - Density (default): one map from the joint density of all foci (density_map.h); the region
//   between foci is squeezed least. With the bounded builder (the default) each focus's
//   transition is first widened where its falloff is too steep for the anisotropy bound (below),
//   so the map reaches k with every cell's anisotropy under the bound.
// - Add: the paper's composition: each focus's own map, displacement vectors added; if the sum
//   folds, displacements are scaled down until every cell is valid.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "conus/codec/builders/density_map.h"
#include "conus/codec/map/sampling_map.h"
#include "conus/format/container.h"
#include "conus/core/map_rules.h"

namespace conus::codec {

struct Focus {
    double u = 0.5, v = 0.5, r = 0.1, k = 2;
};

// The composition and the falloff shape are the container's enumerations (format/names.h), which
// records them.
using format::FociComposition;
using format::FociFalloffShape;

// The transition from a focus's disc (density k^2) to the context (density 1), over the radii
// s = distance / r in [1, width], with t = smoothstep(width - s over width - 1) (quintic, C2):
// - Density: density 1 + (k^2 - 1) t (the default shape);
// - LogDensity: density k^(2 t): the same ends, sparser in the outer part of the ring;
// - LogRadius: density k^(2 t') with t' the smoothstep of log(width / s) over log(width): log
//   density falls most steeply near the disc, as the least anisotropic radial focus does.
// The default width is narrow: the bounded builder widens a transition only as far as its
// anisotropy bound needs, and a narrow ring costs the context fewer samples than the old 2 r, so
// the same budget gives the focus more k at less loss outside it, with a ring that combs no more
// than the uniform image (bench/notes/2026-11-27-narrow-transitions.md; tests/codec/image/comb_test.cpp).
struct FociFalloff {
    double width = 1.25;  // outer radius of the transition over r: in (1, 8]
    FociFalloffShape shape = FociFalloffShape::Density;
};
// What a file's foci without the falloff scalars had (spec/ "Analytic-map parameters"): r..2r, the
// density smoothstepped. Older writers' default; toAnalytic leaves the scalars out only for it.
inline constexpr FociFalloff kFormatFalloff{2.0, FociFalloffShape::Density};

// Throws conus::Error(InvalidArgument) for a width outside (1, 8] (NaN fails).
void checkFalloff(const FociFalloff& falloff);
// "2", "1.5,log", "3,logr" (a width, then optionally density | log | logr) -> FociFalloff; throws
// conus::Error(InvalidArgument) with the reason.
FociFalloff parseFalloff(const std::string& text);
// The inverse of parseFalloff ("1.25,density" for the default).
std::string falloffText(const FociFalloff& falloff);

struct FociOptions {
    // Grid of the built map; the bounded builder refines it (2n - 1 nodes a side, up to
    // kMaxRefinedSide) while a focus smaller than a few cells misses its k (FociReport says so).
    int columns = map_rules::kDefaultSide, rows = map_rules::kDefaultSide;
    double aspect = 1.0;          // image width / height: makes a focus circular in pixels
    FociComposition composition = FociComposition::Density;
    // Density composition: DensityMapOptions::maxAnisotropy (0: the builder's default, which for
    // the bounded builder is map_rules::kMaxAnisotropy and for Flow none).
    double maxAnisotropy = 0;
    FociFalloff falloff = {};     // how each focus's density falls to the context's (`= {}`: no -Wextra warning)
    DensityBuilder builder = DensityBuilder::Bounded;
    // Density composition: the density the frame has away from the foci (> 0, any size, about 1
    // on average; under `encode` the picture's own detail, frame_budget.h's ownDetailContext),
    // which the foci's profiles multiply: a focus is k times the context's linear rate where it
    // lies. Null: 1 everywhere.
    const DensityField* context = nullptr;
};

// The largest grid the foci builder refines to on its own (nodes a side).
inline constexpr int kMaxRefinedSide = 257;

// What a foci map reached, and what gave way (bounded builder; Flow and Add fill what they can).
struct FociReport {
    int columns = 0, rows = 0;          // the grid built: finer than asked when a focus needed it
    double bound = 0;                   // the anisotropy bound applied (0: none)
    double maxAnisotropy = 1;           // the map's largest cell anisotropy, in pixels
    std::vector<double> reached;        // per focus: reachedMagnification
    std::vector<double> transition;     // per focus: where its widened transition ends, in radii
    // One line per thing that gave way, with numbers (a transition widened, a grid refined, a k
    // not reached); empty when the map is what was asked.
    std::vector<std::string> notes;
};

// Throws conus::Error(InvalidArgument) for a focus outside [0,1]^2, r outside (0, 1] or k outside
// [1, 64] (NaN fails): what every builder of foci asks of a focus (map_rules::isValidFocus, V12).
void checkFocus(const Focus& focus);

// The region an importance map (any size) finds most important: the bounding square, in the pixels
// of a width x height image, of the importance at or above half its peak, as a focus (centre; r
// the half side as a fraction of the width, at least 8 pixels; k 1). A map with no positive value
// gives the centre (r 0.1). What `conus demo` shows magnified.
Focus hottestRegion(const Image& importance, int width, int height);

// Throws conus::Error(InvalidArgument) for a focus outside [0,1]^2, r <= 0 or k < 1 or k > 64.
// Never for a grid too coarse: the bounded builder refines it (FociOptions::columns).
SamplingMap buildFociMap(std::span<const Focus> foci, const FociOptions& options = {});
SamplingMap buildFociMap(std::span<const Focus> foci, const FociOptions& options, FociReport* report);

// A focus's density profile once its transition is widened for the anisotropy bound `bound`:
// over s = distance / r, k^2 inside the disc, 1 from end() on (falloff.width when the falloff is
// gentle enough). It is the smallest density above the falloff's for which the radial map of this
// focus alone in the plane has anisotropy at most K = kTransitionShare * bound: the density mass
// M(s) within s radii then obeys M(s) <= K s^2 d(s), i.e. d(s) = max(falloff density, M(s) / (K s^2)).
// The share leaves room for the frame's edges and neighbouring foci. Tabulated once (512 steps a
// radius, up to 64 radii: a bound near 1 allows almost no change of density, and its transition
// is cut there); throws conus::Error(InvalidArgument) for a bad falloff.
inline constexpr double kTransitionShare = 0.7;
class WidenedFocus {
public:
    WidenedFocus(double k, const FociFalloff& falloff, double bound);
    double end() const { return m_end; }
    double density(double s) const;

private:
    std::vector<double> m_density;  // at s = i * kStep
    double m_end = 1.0;
};

// The linear magnification `map` reaches at each focus centre: the square root of its density
// there over its lowest density (which stands for "far from every focus"). 1 for the identity.
std::vector<double> reachedMagnification(const SamplingMap& map, std::span<const Focus> foci);

// Throws conus::Error(InvalidArgument) when `map` (built for `foci` with `options`) reaches less
// than half of some focus's extra magnification (below 1 + (k - 1) / 2), naming the smallest grid
// of 2^j + 1 nodes a side (up to 257) that does: a grid too coarse for a focus ignores it (a 2x2
// grid is always the identity), and a file would record a focus its map does not have. A map of
// the bounded builder has refined its grid already, so this holds for it but in the extreme
// (a focus under a cell of a 257-node grid).
void checkFociHeld(const SamplingMap& map, std::span<const Focus> foci, const FociOptions& options);

// The target density (before normalization) of a set of foci at undistorted p.
double fociDensity(std::span<const Focus> foci, double aspect, double u, double v, const FociFalloff& falloff = {});

// "u,v,r,k" -> Focus; throws conus::Error(InvalidArgument) with the reason.
Focus parseFocus(const std::string& text);

// Analytic parameters for the file: kind "foci", the foci and how they were composed; a falloff
// other than kFormatFalloff as the scalars falloffWidth and falloffShape (0 Density, 1 LogDensity,
// 2 LogRadius; spec/ "Analytic-map parameters").
format::AnalyticMap toAnalytic(std::span<const Focus> foci, FociComposition composition, const FociFalloff& falloff = {});

}  // namespace conus::codec
