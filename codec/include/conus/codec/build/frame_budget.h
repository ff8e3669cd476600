// What a map costs the rest of the frame, predicted before encoding, and the context floor chosen
// by a budget on it (`--frame-loss`; foci_budget.h lowers the foci's k by the same prediction).
//
// The prediction: a picture sampled at linear rate s (samples per source pixel along each axis)
// loses at each pixel about what the uniform image of that rate loses there, e(x, s) =
// |source - bilinear(area(source, s))|^2 (mean over channels). The model holds e at rates half an
// octave apart and interpolates in log rate; e = 0 at s >= 1. A map of density d samples at
// s0 sqrt(d), s0 the rate of the uniform image of the CoNUS pixel count; a map samples at s0 times
// its Jacobian's singular values along its footprint's axes, and loses the mean of the two. Then
//   whole-frame loss = 10 log10((mean_x e(x, s0 sqrt d) + f) / (mean_x e(x, s0) + f))   (dB, > 0: CoNUS worse)
//   ROI gain        = 10 log10(mean_R e(x, s0) / mean_R e(x, s0 sqrt d))     (R: importance >= half its peak)
//   tile loss       = the same as the frame's over each tile of max(W, H) / 32 touching no part of R,
//                     at the 95th percentile; f = (1.5/255)^2, about bench/quality.py's floor (2/255)^2 of
//                     8-bit sRGB near mid-grey, in linear light
// e is measured on the source reduced to at most 1024 px a side (or twice the CoNUS side) and
// pooled into blocks of at most 256 a side, where the map's rates are taken at each block's centre.
// Otherwise it takes the encode and decode to be the area downsample and bilinear of the uniform
// image (bench/quality.py sets it beside measured figures).
#pragma once

#include <functional>
#include <limits>
#include <vector>

#include <glm/glm.hpp>

#include "conus/codec/build/auto_map.h"
#include "conus/codec/map/sampling_map.h"
#include "conus/core/image.h"

namespace conus::codec {

// The budgets of the defaults (dB, predicted, against the uniform image of the same pixel count):
// the whole frame's loss, and the 95th percentile of the tiles' outside the region of interest.
inline constexpr double kDefaultFrameLoss = 1.5;
inline constexpr double kDefaultTileLoss = 4.0;

struct FramePrediction {
    double frameLoss = 0;  // dB
    double roiGain = 0;    // dB
    double tileLoss = 0;   // dB: the 95th percentile over tiles of max(W, H) / 32 touching no region
};

class FrameErrorModel {
public:
    // `source` the picture, (width, height) the CoNUS image size (at most the source's), `importance`
    // any size (its region R is where it reaches half its peak; empty: R is the whole frame). Throws
    // conus::Error(InvalidArgument) on an empty source or a size outside 1..source size.
    FrameErrorModel(const Image& source, int width, int height, const Image& importance);

    // For a density at undistorted p in [0,1]^2 (density(p) > 0).
    FramePrediction predict(const std::function<double(double u, double v)>& density) const;
    FramePrediction predict(const SamplingMap& map) const;
    FramePrediction predict(const DensityField& field) const;
    // For the linear rates along two axes at p, relative to the uniform image's (a density d is
    // sqrt(d) along both; a map's are its Jacobian's singular values in pixels).
    FramePrediction predictAxes(const std::function<glm::dvec2(double u, double v)>& scales) const;

private:
    int m_width = 0, m_height = 0;  // of the pooled blocks (at most 256 a side)
    double m_aspect = 1;            // the source's width over its height
    double m_baseRate = 1;          // s0, in pixels of the grid the errors are measured on
    std::vector<double> m_logRates;                // ascending, the last one log(1) = 0
    std::vector<std::vector<float>> m_error;       // per rate, per block: the sum of its pixels' errors
    std::vector<std::vector<float>> m_roiError;    // the same over the region's pixels only
    std::vector<float> m_count;                    // pixels per block
    std::vector<unsigned char> m_roiAny;           // the block holds a pixel of the region
};

struct BudgetResult {
    SamplingMap map;
    double minDensity = 0;          // the context floor chosen
    FramePrediction predicted;      // of `map` itself
    bool budgetBinds = true;        // false: even the lowest floor stays under the budget
};

// The automatic map (buildAutoMap with `options`, its minDensity replaced) with the lowest context
// floor in [0.02, 0.99] (to 1.5%, by bisection, a map built for each try) whose own predicted
// whole-frame loss stays within `frameLossDb` and tile loss within `tileLossDb` (infinity: no tile
// budget): the most ROI gain the budget allows. The map is built without refusing
// density bounds (the budget, not the floor, is the promise). Throws conus::Error(InvalidArgument) for a budget that is not finite
// and >= 0.
BudgetResult buildAutoMapForFrameLoss(const Image& importance, const FrameErrorModel& model, double frameLossDb,
                                      AutoMapOptions options = {}, double tileLossDb = std::numeric_limits<double>::infinity());

// The automatic map (buildAutoMap with `options`, its minDensity replaced) whose context floor,
// among a few from 0.25 to 0.85, the model predicts loses least over the whole frame (the most
// whole-frame gain) while its tile loss stays within `tileLossDb` (or, when none does, the one with
// the least tile loss; budgetBinds then false): what `encode` makes of the picture's own detail
// when it is given no focus, map or importance.
BudgetResult buildAutoMapForBestFrame(const Image& importance, const FrameErrorModel& model, double tileLossDb,
                                      AutoMapOptions options = {});

// The predicted tile loss (dB) the map of the picture's own detail keeps to.
inline constexpr double kOwnDetailTileLoss = 2.0;

// What `conus encode` and Python's conus.encode make when given no focus, map or importance: the
// samples follow the picture's own detail (`detail`: importance.h's detail rule on `source` as a
// display shows it), the context floor buildAutoMapForBestFrame's within kOwnDetailTileLoss for a
// CoNUS image of width x height.
BudgetResult buildOwnDetailMap(const Image& source, const Image& detail, int width, int height,
                               const AutoMapOptions& options = {});

}  // namespace conus::codec
