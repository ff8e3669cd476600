// The pixel budget of foci: what share of a CoNUS image's samples the foci take, what the context
// is left with, and the magnification a budget allows (what `encode --focus`, `map foci`, `bake
// relief --focus` and conus.encode(foci=...) do by default).
//
// A focus of magnification k asks k^2 times the context's density over its disc; the map spends a
// fixed count of samples, so foci that ask much leave the context sparse. By default k is lowered,
// every focus by the same power (k_i^t, t in [0, 1]: their ratios in log kept), to the largest t
// whose map holds the budget:
// - with the picture: the whole-frame loss that FrameErrorModel predicts for the built map
//   (frame_budget.h; kDefaultFrameLoss dB against the uniform image of the same pixel count), and
//   its loss in the tiles outside the foci (kDefaultTileLoss dB at the 95th percentile): a frame
//   can hold its mean while the context beside a focus is crushed; k is searched continuously (a
//   tiny change of the picture changes k a little), each try a map built and predicted;
// - without one (`map foci`): the context's density, at least kDefaultContextFloor.
// The foci then record the k they were given. An explicit choice (`--exact-k`) keeps k as asked.
#pragma once

#include <algorithm>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "conus/codec/builders/foci.h"
#include "conus/codec/builders/frame_budget.h"
#include "conus/codec/map/sampling_map.h"

namespace conus::codec {

// The least context density the defaults keep when no picture is given: half the linear rate of
// the uniform image (the automatic maps' default floor).
inline constexpr double kDefaultContextFloor = 0.25;

struct FociShare {
    double share = 0;           // share of the map's samples inside the foci's discs (0..1)
    double contextDensity = 1;  // density far from every focus, relative to the uniform image
    double ask = 0;             // the discs' samples at k^2 the uniform image's density, over all the samples
};

// From the foci's target density (fociDensity, normalized to a mean of 1 over the frame), on a grid
// fine enough for the smallest focus. No foci: share 0, context density 1.
FociShare fociShare(std::span<const Focus> foci, double aspect, const FociFalloff& falloff = {});

// The linear downscale the context is sampled like: a CoNUS image of `width` x `height` from a
// source of `sourceWidth` x `sourceHeight` samples the context like a uniform downscale by this
// factor (> 1: fewer samples than the source).
double contextDownscale(const FociShare& share, int width, int height, int sourceWidth, int sourceHeight);

struct FociBudget {
    std::vector<Focus> asked, given;  // given: k lowered by the budget, or to what the map reaches
    SamplingMap map;
    FociShare share, askedShare;      // of the foci given, and of those asked
    FramePrediction predicted;        // with a picture; zeros without
    FramePrediction askedPredicted;   // the same for the map of k as asked (what --exact-k would hold)
    std::vector<double> transition;   // per focus: where its transition ends, in radii (widened or as asked)
    bool lowered = false;             // the budget lowered k
    bool gridLimited = false;         // the grid held less than half a focus's extra magnification
    // What the builder gave way on to keep the anisotropy bound (FociReport::notes: a transition
    // widened, a grid refined, a k not reached), one line each with numbers.
    std::vector<std::string> builderNotes{};
    // The encode of `map` where the budget's confirming encode was of the map kept (FrameErrorModel::
    // confirmed; `predicted` is then what it measured); null otherwise.
    std::shared_ptr<const ModelEncode> encode{};
    // With a picture and an explicit k (exactK): the map's predicted whole-frame or tile loss is
    // past the budget, which callers warn of.
    bool overBudget = false;
};

// The falloff the file records for a budget's map: `asked`, its width the widest transition the
// builder gave a focus (FociReport::transition: widened to keep an anisotropy bound), so that the
// file says what the map holds.
inline FociFalloff recordedFalloff(const FociBudget& budget, const FociFalloff& asked) {
    FociFalloff out = asked;
    for (double w : budget.transition) out.width = std::clamp(w, out.width, std::max(out.width, 8.0));  // the format's (1, 8]
    return out;
}

// An importance image that is 1 on the foci's discs and 0 elsewhere (w x h), the region a
// FrameErrorModel of foci measures the gain on.
Image fociImportance(std::span<const Focus> foci, double aspect, int width, int height);

// The map of `foci` (buildFociMap with `options`) with k lowered to hold `frameLossDb` of predicted
// whole-frame loss, `tileLossDb` of tile loss and `restLossDb` of loss outside the foci (model: the
// picture at the CoNUS size, its region fociImportance), or as asked when `exactK`; then each focus
// records what the map reaches where that is below half its extra magnification. Throws what
// buildFociMap throws, and conus::Error(InvalidArgument) for a budget that is not finite and >= 0.
FociBudget fociForFrameLoss(std::span<const Focus> foci, const FociOptions& options, const FrameErrorModel& model,
                            double frameLossDb = kDefaultFrameLoss, bool exactK = false, double tileLossDb = kDefaultTileLoss,
                            double restLossDb = std::numeric_limits<double>::infinity());
// The side, along the picture's width, of the fociImportance image a picture's foci budget measures
// its region on (its height: this over the aspect, at least 1).
// (fine enough that the tiles it marks as touching a focus are, to a pixel or two, those a focus's
// disc touches on a picture 1280 pixels wide).
inline constexpr int kFociImportanceSide = 1024;

// What an encode of foci asks (`encode --focus`, `bake relief --focus`, `demo`, conus.encode(foci=)).
struct FociMapRequest {
    FociOptions options;                   // grid, composition, falloff, anisotropy bound (aspect and context: set by the call)
    FrameModelOptions model;               // the encode the budget predicts, and confirms (keeping that encode)
    double frameLoss = kDefaultFrameLoss;  // the budget, as fociForFrameLoss takes it
    double tileLoss = kDefaultTileLoss;
    double restLoss = std::numeric_limits<double>::infinity();
    bool exactK = false;
    // The picture's own detail (its ImportanceRule::Detail as a display shows it, any size): away
    // from the foci the samples follow it (ownDetailContext with `contextOptions`), as an encode
    // with no focus samples the frame. Null: the foci sit on a uniform context.
    const Image* detail = nullptr;
    AutoMapOptions contextOptions{};
};

// The map a budget gives, its analytic form as the file records it (the foci given, the
// composition, the falloff the map holds) and the budget's findings (budget: the k given, shares,
// predictions, the builder's notes, the kept encode, overBudget).
struct FociMap {
    FociBudget budget;
    format::AnalyticMap analytic;
};

// The one call from a picture and its foci to the map of a width x height CoNUS image of it: the
// foci on the picture's own detail (or a uniform context), the budget's model of that picture
// (one pyramid for the context and the foci's region, kFociImportanceSide), fociForFrameLoss.
// Throws what fociForFrameLoss and FrameErrorModel throw.
FociMap budgetedFociMap(const Image& picture, std::span<const Focus> foci, int width, int height, const FociMapRequest& request);
// The same of a picture kept as 8-bit codes: its model is never confirmed (`request.model.confirm`
// is taken as off).
FociMap budgetedFociMap(const EightBitImage& picture, std::span<const Focus> foci, int width, int height, const FociMapRequest& request);

// The same without a picture: k lowered until the context's target density is at least `floor`.
FociBudget fociForContextFloor(std::span<const Focus> foci, const FociOptions& options,
                               double floor = kDefaultContextFloor, bool exactK = false);

}  // namespace conus::codec
