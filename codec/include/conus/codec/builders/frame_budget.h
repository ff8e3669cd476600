// What a map costs the rest of the frame, predicted before the real encode, and the context floor
// chosen by a budget on it (`--frame-loss`; foci_budget.h lowers the foci's k by the same prediction).
//
// The prediction is arithmetic on a model of the picture, built once: no trial encode. The picture
// (colour through the display's sRGB curve D, data as stored) is split by a box (Haar) pyramid at
// full resolution into bands j = 0, 1, ...: band j is the energy of level j's 2x2 cells about their
// mean, detail of about 2^(j+1) source pixels. Each tile of max(W, H) / 32 source pixels keeps its
// bands' mean energies E_j. Sampled with a footprint of sigma source pixels along an axis, a tile
// loses about
//   S(sigma) = a * sum_j E_j * R(log2 sigma - j - b),   R a smoothstep from 0 at -c to 1 at c
// (the bands finer than the spacing are lost), and its mean squared error is the mean
// of S over the footprint's two axes (the map's Jacobian's singular values, at a few points of the
// tile), for the CoNUS image (encode, fit, decode) and the uniform image of the same pixel count
// (area downsample, bilinear resize) alike, each with its own a, b (frame_budget.cpp, fitted on
// photographs by bench/budget_check.py). With e_c and e_u those per-tile errors, n the tile's pixels,
//   whole-frame loss = 10 log10((mean e_c + q) / (mean e_u + q))   (dB, > 0: CoNUS worse)
//   ROI gain        = 10 log10(mean_R e_u / mean_R e_c)           (R: importance >= half its peak)
//   rest loss       = the frame's loss over the pixels outside R
//   tile loss       = 10 log10((e_c + f) / (e_u + f)) of each tile touching no part of R, at the
//                     95th percentile; f = (2/255)^2, bench/quality.py's floor on 8-bit sRGB; q the
//                     8-bit rounding's error, (1/255)^2 / 12 (the whole frame's PSNR has no floor);
//                     for data f = q = (1.5/255)^2
// which are bench/quality.py's measures. Every step is continuous in the pixels and the map: a tiny
// change of either changes the prediction a little.
#pragma once

#include <limits>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

#include "conus/codec/builders/auto_map.h"
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

// Where the model takes its errors: on colour as a display shows it (sRGB; alpha and other
// channels as stored), or on the values as stored (data: heights, depth, raw input).
enum class ErrorSpace { Display, Linear };

struct FrameModelOptions {
    ErrorSpace space = ErrorSpace::Display;
    int fitIterations = kDefaultEncodeFitIterations;  // the encode's fit (0: the filtered encode alone, `--fast`)
    double fitHold = kFitHoldLowPass;
    // Whether the budgets confirm their choice by one real encode (FrameErrorModel::confirmed) and
    // choose again on the confirmed model; `--fast` does not.
    bool confirm = true;
    // The foci's budget (fociForFrameLoss): how many confirming encodes each candidate may take.
    // One: the map chosen on the model alone is encoded and the choice made again on the model that
    // encode confirms; where that choice moved (its exponent of k by more than kConfirmedT), the map
    // it moved to is encoded too (the encode the file keeps, which it would take anyway) and of the
    // two the one whose own encode holds the budget is kept (the larger k where both do): what the
    // budget says of the map kept is what its encode measured. Where neither holds, the choice is
    // made once more on the model the second encode confirmed and that map encoded and measured;
    // where it misses too, once more under budgets lowered by what it missed by, on the model its
    // encode confirmed, and that map encoded and measured (the first that holds is kept, else the
    // nearest the budget): every map kept has its losses measured. The importance maps' budget
    // (buildAutoMapForFrameLoss) does the same.
    // More: where neither holds or the one that holds has the smaller k, the search goes on on
    // measured losses alone, each try encoded (regula falsi between the maps encoded, up to this
    // many encodes besides those two), and keeps a map whose own encode holds the budget:
    // a correction measured on one map carries to maps near it only roughly (on the relief tablet's
    // colour, a map a quarter of an octave of k away lost 0.3 dB more outside its focus than the
    // corrected model said), so a budget that must hold to the tenth of a dB confirms more than once.
    int confirmRounds = 1;
    // The encode's kernel and fit method, which the confirming encodes use as the encode will.
    EncodeFilter filter = EncodeFilter::Anisotropic;
    FitMethod fitMethod = FitMethod::LeastSquares;
    // Where set, each confirmed() reports through it from 0 (called as it starts, on its caller's
    // thread) to 1 over its encode, fit and measure (from worker threads too): a caller's progress
    // bar over a budget counts the confirming encodes by their 0.
    ProgressFn confirmProgress{};
};

// How near (in the exponent t of k^t) the map chosen on a confirmed model must be to the map that
// model's encode measured for no further confirming encode to be taken.
inline constexpr double kConfirmedT = 0.02;

// A confirming encode (FrameErrorModel::confirmed): the CoNUS image of the model's picture through
// the map it confirmed, encoded with the model's kernel and fitted as its options say, exactly what
// `encodeImage` then `fitToDecoder` with those options make of that map; a budget that keeps this
// map hands it on so that the encode is not made twice.
struct ModelEncode {
    Image image;     // the CoNUS image, fitted (or filtered alone when the model's fitIterations is 0)
    FitResult fit;   // the fit's report (empty steps when not fitted)
};

class FrameErrorModel {
public:
    // `source` the picture, (width, height) the CoNUS image size (at most the source's), `importance`
    // any size (its region R is where it reaches half its peak; empty: R is the whole frame). Throws
    // conus::Error(InvalidArgument) on an empty source or a size outside 1..source size.
    FrameErrorModel(const Image& source, int width, int height, const Image& importance, const FrameModelOptions& options = {});
    // The same model of a picture kept as 8-bit codes (the same as of linearImage(source)),
    // which cannot be confirmed (confirmed() throws: build the model of linearImage(source) for that).
    FrameErrorModel(const EightBitImage& source, int width, int height, const Image& importance, const FrameModelOptions& options = {});

    // The same model (the same picture's bands, unconfirmed or confirmed alike) with the region of
    // `importance` instead: the picture's pyramid is not taken again.
    FrameErrorModel withRegion(const Image& importance) const;

    // The losses and gain of encoding through `map`, predicted by the model (microseconds).
    FramePrediction predict(const SamplingMap& map) const;
    // The model confirmed by one real encode of the picture it was built from (which must outlive it) through
    // `map`, fitted as options say, decoded at the source's size, and the uniform image's (the
    // identity map through the same encoder, as `conus uniform` makes it, resized bilinearly), their
    // errors taken on 8-bit codes where the model's are shown (ErrorSpace::Display): each tile's
    // footprints then scaled so that `map` predicts what it measured (the tile's effective
    // footprint; what no scale within 3 octaves reaches, added), and the uniform image's errors
    // measured. Other maps are predicted through the footprints so scaled.
    FrameErrorModel confirmed(const SamplingMap& map) const;
    bool isConfirmed() const { return m_confirmed; }
    // The encode a confirmed model measured (null before confirmed()).
    const std::shared_ptr<const ModelEncode>& encode() const { return m_encode; }
    const FrameModelOptions& options() const { return m_options; }
    // The same from each tile's predicted mean squared error of the CoNUS image (tiles row by row,
    // tileColumns() x tileRows()), as predict computes them: what bench and tests compare.
    FramePrediction measure(const std::vector<double>& conusError) const;
    std::vector<double> tileErrors(const SamplingMap& map) const;  // e_c of each tile
    const std::vector<double>& uniformErrors() const { return m_uniformError; }
    int tileColumns() const { return m_columns; }
    int tileRows() const { return m_rows; }
    int tileSide() const { return m_tile; }

    struct BandFit;

private:
    FrameErrorModel(const Image& source, const EightBitImage* codes, int width, int height, const Image& importance,
                    const FrameModelOptions& options);
    // S of the footprint of axes sigma1 >= sigma2 (source pixels) on `tile`, with `fit`'s constants.
    double tileError(std::size_t tile, double sigma1, double sigma2, const BandFit& fit) const;
    // Measured, per tile: the view of `conus` through `map` at the source's size and (where given)
    // the uniform image's bilinear view, each against the source; neither view is kept. `progress`
    // (where set) from 0 to 1 over the rows of tiles.
    std::pair<std::vector<double>, std::vector<double>> shownTileErrors(const Image& source, const Image& conus,
                                                                        const SamplingMap& map, const Image* uniform,
                                                                        const ProgressFn& progress = {}) const;
    // The footprint's axes (source pixels, largest first) at a few points of each tile, tile by tile.
    std::vector<std::pair<double, double>> footprints(const SamplingMap& map) const;
    // A tile's error from its points' axes, each scaled by 2^shift.
    double footprintError(std::size_t tile, const std::pair<double, double>* axes, double shift) const;
    void setRegion(const Image& importance);  // m_roi and m_touches

    FrameModelOptions m_options;
    const Image* m_source = nullptr;    // for confirmed()
    int m_sourceWidth = 1, m_sourceHeight = 1, m_conusWidth = 1, m_conusHeight = 1;
    int m_tile = 1, m_columns = 1, m_rows = 1, m_levels = 0;
    double m_floor = 0;                 // f, of the space the errors are taken in (the tiles')
    double m_frameFloor = 0;            // the whole frame's and the rest's
    std::vector<double> m_bands;        // per tile, m_levels band energies E_j
    std::vector<double> m_pixels;       // per tile: its source pixels
    std::vector<double> m_uniformError; // per tile: e_u
    std::vector<double> m_roi;          // per tile: the share of its pixels in R
    std::vector<unsigned char> m_touches;  // per tile: touches R
    std::vector<double> m_shift;        // per tile: octaves confirmed() scales the footprints by
    std::vector<double> m_residual;     // per tile: what confirmed() measured that no shift gives (added)
    bool m_confirmed = false;
    std::shared_ptr<const ModelEncode> m_encode;  // confirmed(): the encode measured
    // What every confirmed() of this model or of any copy (the same picture and size) shares: the
    // uniform image's errors, measured by the first, and the picture's encode pyramid, built once.
    struct Confirming;
    std::shared_ptr<Confirming> m_confirming;
};

struct BudgetResult {
    SamplingMap map;
    double minDensity = 0;          // the context floor chosen
    FramePrediction predicted;      // of `map` itself
    bool budgetBinds = true;        // false: even the lowest floor and the highest cap stay under the budget
    double maxDensity = 0;          // the density cap the map was built with (raised by a budget the lowest floor holds)
    // The encode of `map` itself where the budget's confirming encode was of the map kept (its
    // `predicted` then what that encode measured); null otherwise.
    std::shared_ptr<const ModelEncode> encode{};
};

// The automatic map (buildAutoMap with `options`, its minDensity replaced) with the lowest context
// floor in [0.02, 0.99] (to 0.2%, by regula falsi, a map built for each try) whose own predicted
// whole-frame loss stays within `frameLossDb` and tile loss within `tileLossDb` (infinity: no tile
// budget): the most ROI gain the budget allows; where even the lowest floor holds the budget, the
// density cap is raised (up to 256, regula falsi in log cap) until it binds. The map is built without refusing
// density bounds (the budget, not the floor, is the promise). Throws conus::Error(InvalidArgument) for a budget that is not finite
// and >= 0.
BudgetResult buildAutoMapForFrameLoss(const Image& importance, const FrameErrorModel& model, double frameLossDb,
                                      AutoMapOptions options = {}, double tileLossDb = std::numeric_limits<double>::infinity());

// The automatic map (buildAutoMap with `options`, its minDensity replaced) whose context floor in
// [0.25, 0.85] (golden-section search, about 10 maps built) the model predicts loses least over the
// whole frame (the most whole-frame gain), each dB of tile loss over `tileLossDb` counted as 4 dB of
// frame loss (budgetBinds false when the tiles still lose more): what `encode` makes of the picture's own detail
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
// The same on a model of the picture already built with `detail` as its region (a model whose
// pyramid the caller then reuses through withRegion).
DensityField ownDetailContext(const FrameErrorModel& model, const Image& detail, const AutoMapOptions& options = {});
// The same two of a picture kept as 8-bit codes (FrameErrorModel's own, unconfirmed: `model.confirm` off).
BudgetResult buildOwnDetailMap(const EightBitImage& source, const Image& detail, int width, int height,
                               const AutoMapOptions& options = {}, const FrameModelOptions& model = {});
DensityField ownDetailContext(const EightBitImage& source, const Image& detail, int width, int height,
                              const AutoMapOptions& options = {}, const FrameModelOptions& model = {});

}  // namespace conus::codec
