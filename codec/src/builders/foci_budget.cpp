// The pixel budget of foci: their share of the samples, and the k a budget allows (foci_budget.h).
#include "conus/codec/builders/foci_budget.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "conus/core/error.h"
#include "budget_search_pvt.h"

namespace conus::codec {
namespace {

// Samples along the share grid's longer side, and at least this many across the smallest radius.
constexpr int kShareSide = 512;
constexpr double kShareSamplesPerRadius = 8.0;
constexpr int kMaxShareSide = 2048;
// Halvings of the exponent t of k^t without a picture: t to within 1/1024 (k = 4: to 0.14%).
constexpr int kBisectionSteps = 10;
// With a picture: the search for t stops within kTolerance of t, or within kToleranceDb under the
// budget, or after kSearchSteps maps built.
constexpr double kTolerance = 1.0 / 1024, kToleranceDb = 0.01;
constexpr int kSearchSteps = 12;
// A choice within this of the t measured before it is that map again.
constexpr double kSameT = 1e-6;
// The rounds of confirming encodes (FrameModelOptions::confirmRounds) stop within this of the budget.
constexpr double kMeasuredToleranceDb = 0.05;

bool inDisc(const Focus& f, double aspect, double u, double v) {
    const double dx = u - f.u, dy = (v - f.v) / aspect;
    return dx * dx + dy * dy <= f.r * f.r;
}

std::vector<Focus> powered(std::span<const Focus> foci, double t) {
    std::vector<Focus> out(foci.begin(), foci.end());
    for (Focus& f : out) f.k = std::pow(f.k, t);
    return out;
}

// Each focus records what `map` reaches where that is below half its extra magnification (a grid
// too coarse for it): the file must not record a magnification its map does not have.
bool recordReached(const SamplingMap& map, std::vector<Focus>& foci) {
    const std::vector<double> reached = reachedMagnification(map, foci);
    bool limited = false;
    for (std::size_t i = 0; i < foci.size(); ++i)
        if (reached[i] < 1.0 + 0.5 * (foci[i].k - 1.0)) {
            foci[i].k = std::clamp(reached[i], 1.0, foci[i].k);
            limited = true;
        }
    return limited;
}

// The largest t in [0, 1] (to 1/64) for which holds(t); holds(0) is taken as true.
double largestHolding(const std::function<bool(double)>& holds) {
    if (holds(1.0)) return 1.0;
    double lo = 0.0, hi = 1.0;
    for (int i = 0; i < kBisectionSteps; ++i) {
        const double mid = 0.5 * (lo + hi);
        (holds(mid) ? lo : hi) = mid;
    }
    return lo;
}

}  // namespace

FociShare fociShare(std::span<const Focus> foci, double aspect, const FociFalloff& falloff) {
    FociShare out;
    if (foci.empty()) return out;
    double rMin = 1.0;
    for (const Focus& f : foci) rMin = std::min(rMin, f.r);
    // Pixel-isotropic samples (the width is `aspect` times the height), fine enough for every disc.
    const int longSide = std::clamp(static_cast<int>(std::ceil(kShareSamplesPerRadius / rMin * std::max(1.0, 1.0 / aspect))),
                                    kShareSide, kMaxShareSide);
    const int w = aspect >= 1 ? longSide : std::max(8, static_cast<int>(std::lround(longSide * aspect)));
    const int h = aspect >= 1 ? std::max(8, static_cast<int>(std::lround(longSide / aspect))) : longSide;
    double total = 0, discs = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const double u = (x + 0.5) / w, v = (y + 0.5) / h;
            const double d = fociDensity(foci, aspect, u, v, falloff);
            total += d;
            if (std::any_of(foci.begin(), foci.end(), [&](const Focus& f) { return inDisc(f, aspect, u, v); })) discs += d;
        }
    const double samples = double(w) * h;
    out.contextDensity = samples / total;
    out.share = discs / total;
    out.ask = discs / samples;
    return out;
}

double contextDownscale(const FociShare& share, int width, int height, int sourceWidth, int sourceHeight) {
    const double rate = std::sqrt(double(width) * height / (double(sourceWidth) * sourceHeight) * share.contextDensity);
    return 1.0 / std::max(rate, 1e-12);
}

Image fociImportance(std::span<const Focus> foci, double aspect, int width, int height) {
    Image image = makeImage(width, height, {"Y"});
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const double u = (x + 0.5) / width, v = (y + 0.5) / height;
            image.at(x, y) = std::any_of(foci.begin(), foci.end(), [&](const Focus& f) { return inDisc(f, aspect, u, v); }) ? 1.0f : 0.0f;
        }
    return image;
}

FociBudget fociForFrameLoss(std::span<const Focus> foci, const FociOptions& options, const FrameErrorModel& model,
                            double frameLossDb, bool exactK, double tileLossDb, double restLossDb) {
    if (!(frameLossDb >= 0) || !std::isfinite(frameLossDb))
        throw Error(ErrorCode::InvalidArgument, "the frame-loss budget " + std::to_string(frameLossDb) + " dB must be finite and >= 0");
    if (!(tileLossDb >= 0))  // NaN fails; infinity: no tile budget
        throw Error(ErrorCode::InvalidArgument, "the tile-loss budget " + std::to_string(tileLossDb) + " dB must be >= 0");
    struct Try {
        double t;
        std::vector<Focus> given;
        SamplingMap map;
        FociReport report;
        FramePrediction predicted;
        std::shared_ptr<const ModelEncode> encode{};  // this map's own encode, where one was made
        const DensityField* context = nullptr;         // the context it was built on
    };
    // The maps built, by t and context: a map depends on them alone, not on the model that judges
    // it, and every search (on the model, on a confirmed model) starts at t = 1 and t = 0.
    std::vector<Try> built;
    const auto attempt = [&](const FrameErrorModel& m, double t, const FociOptions& o) {
        for (const Try& b : built)
            if (b.t == t && b.context == o.context) {
                Try x = b;
                x.predicted = m.predict(x.map);
                return x;
            }
        Try x{t, powered(foci, t), SamplingMap::identity(2, 2), {}, {}, {}, o.context};
        x.map = buildFociMap(x.given, o, &x.report);
        x.predicted = m.predict(x.map);
        built.push_back(x);
        return x;
    };
    // How far a try is over the budget (dB, <= 0: within): continuous in t, as the model is. `margin`
    // lowers every budget alike (a last search after a confirmed model's choice missed).
    double margin = 0.0;
    const auto over = [&](const Try& x) {
        const FramePrediction& p = x.predicted;
        return margin + std::max({p.frameLoss - frameLossDb, p.tileLoss - tileLossDb,
                                  std::isfinite(restLossDb) ? p.restLoss - restLossDb : -1e9});
    };
    // A lower k leaves the context more samples: the loss falls with t. The largest t within the
    // budget: regula falsi (Illinois) on over(t) between t = 0 (k = 1) and 1, to kTolerance in t,
    // each step a map built and predicted; the t chosen is a continuous function of the picture.
    struct Search {
        Try chosen, asked;
    };
    const auto search = [&](const FrameErrorModel& m, const FociOptions& o) {
        Try hi = attempt(m, 1.0, o);
        if (exactK || over(hi) <= 0) return Search{hi, hi};
        Try lo = attempt(m, 0.0, o);
        if (over(lo) > 0) return Search{std::move(lo), std::move(hi)};  // even k = 1 loses more: the closest to the budget there is
        Try within = detail::searchWithin(std::move(lo), 0.0, hi, 1.0, [&](double t) { return attempt(m, t, o); }, over, kSearchSteps,
                                          kTolerance, kToleranceDb);
        return Search{std::move(within), std::move(hi)};
    };
    // A context that follows the picture usually lets the foci keep more k; where it does not (a
    // focus on a softer part of the picture than the rest, or a context that alone loses the
    // budget), or where it crowds a few tiles (small features on a flat ground), the foci on a
    // uniform context are kept (keepsContext).
    const bool compare = !exactK && options.context != nullptr;
    FociOptions uniform = options;
    uniform.context = nullptr;
    const auto takesPlain = [&](const Search& own, const Search& other) {
        return (over(own.chosen) > 0 && over(other.chosen) <= 0) || !keepsContext(own.chosen.predicted, other.chosen.predicted);
    };
    Search chosen = search(model, options);
    std::optional<Search> plain;
    if (model.options().confirm && !model.isConfirmed()) {
        // A real encode of the candidate's map, and the candidate searched again on the model that
        // encode confirms (the model alone can be off by dB in either direction). Where the choice
        // stays next to the map encoded (kConfirmedT in t) and that map holds the budget as
        // measured, it is kept with its encode, which the caller then need not make again; what the
        // block prints is then what that encode measured.
        const auto confirm = [&](Search s, const FociOptions& o) {
            // A try at t with its own encode: its losses what that encode measured (`last`: the
            // model that encode confirmed).
            std::optional<FrameErrorModel> last;
            const auto measured = [&](double t) {
                Try x = attempt(model, t, o);
                last.emplace(model.confirmed(x.map));
                x.predicted = last->predict(x.map);
                x.encode = last->encode();
                return x;
            };
            Try encoded = s.chosen;
            FrameErrorModel confirmed = model.confirmed(encoded.map);
            encoded.predicted = confirmed.predict(encoded.map);
            encoded.encode = confirmed.encode();
            s = search(confirmed, o);
            const bool near = std::abs(s.chosen.t - encoded.t) <= kConfirmedT;
            if (exactK || (near && (over(encoded) <= 0 || over(s.chosen) > 0))) {
                s.chosen = std::move(encoded);
                return std::pair{std::move(s), std::move(confirmed)};
            }
            // The choice moved (or stayed next to a map encoded that misses, and is predicted to
            // hold): the map it moved to is encoded (the encode the file then keeps, as
            // it would be encoded anyway) and measured, so that what is kept is a map whose own
            // encode measured its losses: of the two, the one that holds the budget (the larger k
            // where both do; where neither does, a third choice on the second's model). The confirmed model's
            // prediction of a map it was not measured on is off by up to a dB on photographs
            // (bench/notes/2026-12-07-budget-check.md); a measure is not.
            const int rounds = model.options().confirmRounds - 1;
            Try next = measured(s.chosen.t);
            const bool nextHolds = over(next) <= 0, encodedHolds = over(encoded) <= 0;
            if (nextHolds && encodedHolds) {  // both hold: the larger k
                s.chosen = std::move(next.t >= encoded.t ? next : encoded);
            } else if (nextHolds != encodedHolds && (rounds <= 0 || (nextHolds ? next.t > encoded.t : encoded.t > next.t))) {
                s.chosen = std::move(nextHolds ? next : encoded);  // the one that holds
            } else if (rounds <= 0) {
                // Neither holds: the choice made once more on the model the second encode confirmed,
                // and that map encoded and measured too (the encode the file keeps, made anyway).
                // Where its encode still misses, one last choice on the model the third encode
                // confirms, under budgets lowered by what the third missed by
                // (detail::loweredBudget), encoded and measured. The first of the two that holds
                // the budget is kept, else the nearest the budget of the maps measured: what is
                // said of it is what its own encode measured (as frame_budget_search.cpp does).
                const Try guess = search(*last, o).chosen;
                if (std::abs(guess.t - next.t) <= kSameT) {
                    s.chosen = std::move(over(next) <= over(encoded) ? next : encoded);  // nothing nearer to be had
                } else {
                    const double promised = over(next) - over(guess);  // the fall in loss the model said
                    Try third = measured(guess.t);
                    const double missed = over(third);
                    Try* kept = &third;
                    std::optional<Try> fourth;
                    if (missed > 0) {
                        margin = detail::loweredBudget(missed, (over(next) - missed) / std::max(promised, 1e-9));
                        const double t = search(*last, o).chosen.t;
                        margin = 0.0;
                        if (std::abs(t - third.t) > kSameT) fourth = measured(t);
                        if (fourth && over(*fourth) <= 0) {
                            kept = &*fourth;
                        } else {
                            for (Try* x : {&encoded, &next})
                                if (over(*x) < over(*kept)) kept = x;
                            if (fourth && over(*fourth) < over(*kept)) kept = &*fourth;
                        }
                    }
                    s.chosen = std::move(*kept);
                }
            } else {
                // Further rounds: the same regula falsi on t, each try's losses measured by its own
                // encode, between a try that misses the budget and, at a smaller t, one that holds it
                // (k = 1 where both miss): the map kept holds the budget as measured.
                Try beyond = std::move(!nextHolds && (encodedHolds || next.t < encoded.t) ? next : encoded);
                Try within = nextHolds ? std::move(next) : encodedHolds ? std::move(encoded) : measured(0.0);
                if (over(within) > 0) {  // even k = 1 misses: the closest there is
                    s.chosen = std::move(within);
                } else {
                    const double a = within.t, b = beyond.t;
                    s.chosen = detail::searchWithin(std::move(within), a, std::move(beyond), b, measured, over,
                                                    std::max(0, rounds - 1), kConfirmedT, kMeasuredToleranceDb);
                }
            }
            return std::pair{std::move(s), std::move(confirmed)};
        };
        // The candidate on the picture's own detail is encoded first; the uniform context's is
        // searched on the model that encode confirms, and gets its own confirming encode (and the
        // two are compared on what their encodes measured) only where that model says it may be
        // kept. On photographs that model gives the uniform context's map more ROI gain than its
        // own encode measures (0.1 to 1.8 dB more on five unseen photographs,
        // bench/notes/2026-12-07-default-encode.md), so where it still keeps the own-detail map, a
        // second encode would keep it too. The model alone, unconfirmed, is no judge between the
        // two: it chose the uniform context on four of those five, their encodes the own detail's.
        auto [own, ownModel] = confirm(std::move(chosen), options);
        chosen = std::move(own);
        if (compare) {
            Search cross = search(ownModel, uniform);
            if (takesPlain(chosen, cross)) plain = confirm(std::move(cross), uniform).first;
        }
    } else if (compare) {
        plain = search(model, uniform);
    }
    if (plain && takesPlain(chosen, *plain)) chosen = std::move(*plain);
    std::shared_ptr<const ModelEncode> encode = chosen.chosen.encode;
    const Try& asked = chosen.asked;
    Try& given = chosen.chosen;
    FociBudget out{std::vector<Focus>(foci.begin(), foci.end()), std::move(given.given), std::move(given.map), {}, {},
                   given.predicted, asked.predicted, given.report.transition, false, false, std::move(given.report.notes)};
    out.encode = std::move(encode);
    out.lowered = given.t < 1.0;
    out.gridLimited = recordReached(out.map, out.given);
    out.share = fociShare(out.given, options.aspect, options.falloff);
    out.askedShare = out.lowered || out.gridLimited ? fociShare(out.asked, options.aspect, options.falloff) : out.share;
    out.overBudget = exactK && (out.predicted.frameLoss > frameLossDb || out.predicted.tileLoss > tileLossDb);
    return out;
}

namespace {

// budgetedFociMap of a picture as floats or as 8-bit codes (FrameErrorModel takes either).
template <class Picture>
FociMap budgeted(const Picture& picture, std::span<const Focus> foci, int width, int height, const FociMapRequest& request) {
    FociOptions options = request.options;
    options.aspect = double(picture.width) / picture.height;
    const Image region = fociImportance(foci, options.aspect, kFociImportanceSide,
                                        std::max(1, static_cast<int>(kFociImportanceSide / options.aspect)));
    DensityField context;
    std::optional<FrameErrorModel> model;
    if (request.detail) {
        // One model of the picture (its pyramid taken once): its region the detail's for the
        // context, then the foci's for their budget.
        const FrameErrorModel own(picture, width, height, *request.detail, request.model);
        context = ownDetailContext(own, *request.detail, request.contextOptions);
        options.context = &context;
        model.emplace(own.withRegion(region));
    } else {
        model.emplace(picture, width, height, region, request.model);
    }
    FociMap out{fociForFrameLoss(foci, options, *model, request.frameLoss, request.exactK, request.tileLoss, request.restLoss), {}};
    out.analytic = toAnalytic(out.budget.given, options.composition, recordedFalloff(out.budget, options.falloff));
    return out;
}

}  // namespace

FociMap budgetedFociMap(const Image& picture, std::span<const Focus> foci, int width, int height, const FociMapRequest& request) {
    return budgeted(picture, foci, width, height, request);
}

FociMap budgetedFociMap(const EightBitImage& picture, std::span<const Focus> foci, int width, int height, const FociMapRequest& request) {
    FociMapRequest unconfirmed = request;
    unconfirmed.model.confirm = false;  // a model of codes cannot be confirmed by an encode (frame_budget.h)
    return budgeted(picture, foci, width, height, unconfirmed);
}

FociBudget fociForContextFloor(std::span<const Focus> foci, const FociOptions& options, double floor, bool exactK) {
    FociBudget out{std::vector<Focus>(foci.begin(), foci.end()), {}, SamplingMap::identity(2, 2), {}, {}, {}, {}, {}, false, false, {}};
    const double t = exactK ? 1.0 : largestHolding([&](double t) {
        return fociShare(powered(foci, t), options.aspect, options.falloff).contextDensity >= floor;
    });
    out.given = powered(foci, t);
    out.lowered = t < 1.0;
    FociReport report;
    out.map = buildFociMap(out.given, options, &report);
    out.builderNotes = std::move(report.notes);
    out.transition = report.transition;
    out.gridLimited = recordReached(out.map, out.given);
    out.share = fociShare(out.given, options.aspect, options.falloff);
    out.askedShare = out.lowered || out.gridLimited ? fociShare(out.asked, options.aspect, options.falloff) : out.share;
    return out;
}

}  // namespace conus::codec
