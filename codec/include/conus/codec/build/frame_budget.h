// What a map costs the rest of the frame, predicted before the real encode, and the context floor
// chosen by a budget on it (`--frame-loss`; foci_budget.h lowers the foci's k by the same prediction).
//
// The prediction is a trial: the picture, reduced to at most 1024 px a side, is encoded through the
// map at the same relative size, fitted as the encode will fit it, decoded at its own size by the
// CPU decoder, and compared with the uniform image of the same pixel count (area downsample,
// bilinear resize) on the values a user looks at: colour through the display's sRGB curve (D),
// data as stored. With e_c and e_u the per-pixel squared errors of the two (mean over channels),
//   whole-frame loss = 10 log10((mean e_c + f) / (mean e_u + f))   (dB, > 0: CoNUS worse)
//   ROI gain        = 10 log10(mean_R e_u / mean_R e_c)           (R: importance >= half its peak)
//   rest loss       = the frame's loss over the pixels outside R
//   tile loss       = the frame's loss over each tile of max(W, H) / 32 touching no part of R, at
//                     the 95th percentile; f = (2/255)^2, bench/quality.py's floor on 8-bit sRGB
//                     ((1.5/255)^2 for data)
// which are bench/quality.py's measures, on the reduced picture. (A model of the errors at each
// sampling rate, the uniform image's at the map's local rates, was 1-6 dB pessimistic about tiles:
// it missed the fit, the encoder's filter and how little an anisotropic footprint loses across its
// short axis; bench/notes/2026-11-27-narrow-transitions.md.)
#pragma once

#include <limits>
#include <vector>

#include "conus/codec/build/auto_map.h"
#include "conus/codec/image/encode.h"
#include "conus/codec/image/fit.h"
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
    double restLoss = 0;   // dB: over every pixel outside the region, as the whole frame's (f added)
    double tileLoss99 = 0; // dB: those tiles' loss at the 99th percentile (their worst few)
};

// Where the trials take their errors: on colour as a display shows it (sRGB; alpha and other
// channels as stored), or on the values as stored (data: heights, depth, raw input).
enum class ErrorSpace { Display, Linear };

struct FrameModelOptions {
    ErrorSpace space = ErrorSpace::Display;
    int fitIterations = kDefaultEncodeFitIterations;  // the encode's fit (0: the filtered encode alone, `--fast`)
    double fitHold = kFitHoldLowPass;
};

class FrameErrorModel {
public:
    // `source` the picture, (width, height) the CoNUS image size (at most the source's), `importance`
    // any size (its region R is where it reaches half its peak; empty: R is the whole frame). Throws
    // conus::Error(InvalidArgument) on an empty source or a size outside 1..source size.
    FrameErrorModel(const Image& source, int width, int height, const Image& importance, const FrameModelOptions& options = {});

    // The losses and gain of encoding through `map`, measured on a trial encode (about 60 ms at 1024 px).
    FramePrediction predict(const SamplingMap& map) const;

private:
    std::vector<float> shownValues(const Image& image) const;  // D on the colour channels
    std::vector<float> errors(const Image& view) const;        // per pixel, against the picture
    FramePrediction measure(const std::vector<float>& mapped) const;

    FrameModelOptions m_options;
    Image m_picture;                    // the source, at most 1024 px a side
    int m_conusWidth = 1, m_conusHeight = 1;  // the CoNUS size at the picture's scale
    double m_floor = 0;                 // f, of the space the errors are taken in
    std::vector<bool> m_shown;          // per channel: through D
    std::vector<float> m_reference;     // the picture's values as shown
    std::vector<float> m_uniformError;  // per pixel: the uniform image's
    std::vector<unsigned char> m_roi;   // per pixel: in R
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

// How much more ROI gain (predicted, dB) a budget's map on a uniform context must give to be kept
// over the one on the picture's own detail (FociOptions::context, AutoMapOptions::context): a
// margin, so that a picture and its 8-bit rounding choose alike.
inline constexpr double kContextMarginDb = 0.5;
// And how much more its worst few tiles (tileLoss99) may lose than the uniform context's: a context
// that follows the picture can crowd small isolated features (text, small objects on a flat ground)
// into a few tiles that lose much, which the 95th percentile does not see. (The single worst tile
// is too noisy a judge: on the photographs it refused contexts that the bench measured better.)
inline constexpr double kContextWorstTileDb = 1.5;
// Whether the budget's map on the picture's own detail is kept over the one on a uniform context.
inline bool keepsContext(const FramePrediction& context, const FramePrediction& uniform) {
    return context.roiGain + kContextMarginDb >= uniform.roiGain && context.tileLoss99 <= uniform.tileLoss99 + kContextWorstTileDb;
}

// The predicted tile loss (dB) the map of the picture's own detail keeps to.
inline constexpr double kOwnDetailTileLoss = 2.0;

// What `conus encode` and Python's conus.encode make when given no focus, map or importance: the
// samples follow the picture's own detail (`detail`: importance.h's detail rule on `source` as a
// display shows it), the context floor buildAutoMapForBestFrame's within kOwnDetailTileLoss for a
// CoNUS image of width x height.
BudgetResult buildOwnDetailMap(const Image& source, const Image& detail, int width, int height,
                               const AutoMapOptions& options = {}, const FrameModelOptions& model = {});

// The density the picture's own detail asks for (importanceToDensity of `detail` at the context
// floor buildOwnDetailMap chooses): the context that `encode`'s foci multiply (FociOptions::context),
// so that the frame outside them is sampled as the no-focus default would sample it.
DensityField ownDetailContext(const Image& source, const Image& detail, int width, int height,
                              const AutoMapOptions& options = {}, const FrameModelOptions& model = {});

}  // namespace conus::codec
