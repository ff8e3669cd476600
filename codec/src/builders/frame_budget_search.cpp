// The frame-loss budget's searches over the model (frame_budget.h): the lowest context floor (or,
// once it is at its lowest, the highest density cap) within a loss budget, confirmed by a real
// encode; the floor that loses least over the whole frame; and the own-detail map and context
// built on them. The model they search is frame_budget.cpp's.
#include "conus/codec/builders/frame_budget.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <utility>

#include "conus/core/error.h"
#include "budget_search_pvt.h"

namespace conus::codec {
namespace {

constexpr double kLowestFloor = 0.02, kHighestFloor = 0.99;
// The budget's search for the floor stops within kFloorTolerance of log floor, or within
// kToleranceDb under the budget, or after kSearchSteps maps built (each a map build and
// microseconds of prediction).
constexpr double kFloorTolerance = 0.002, kToleranceDb = 0.01;
constexpr int kSearchSteps = 12;
// The own-detail map's floor: searched in [kBestLowest, kBestHighest] (half the uniform rate to
// nearly uniform) by kGoldenSteps golden sections (the interval shrunk to 0.618^8 = 2% of its log).
constexpr double kBestLowest = 0.25, kBestHighest = 0.85;
// The highest density cap a frame-loss budget raises an importance map's to, once its floor is at
// the lowest (16x the uniform density: 4x the linear rate, as the default cap; this, 16x it).
constexpr double kHighestCap = 256.0;
constexpr int kGoldenSteps = 8;
// How near (in log floor and log cap) the map chosen on a confirmed model must be to the map whose
// encode confirmed it for that map and its encode to be kept instead of a second encode.
constexpr double kNearEncoded = 0.02;
// A choice within this (log floor and log cap) of the map measured before it is that map again.
constexpr double kSameMap = 1e-6;
constexpr double kTilePenalty = 4.0;  // dB of frame loss per dB of tile loss over its budget

[[noreturn]] void invalid(const std::string& what) { throw Error(ErrorCode::InvalidArgument, what); }

// The map of `importance` at the context floor `floor` (options.minDensity set to it, its cap
// options.maxDensity), with the model's prediction for it.
BudgetResult buildAtFloor(const Image& importance, const FrameErrorModel& model, AutoMapOptions& options, double floor) {
    options.minDensity = floor;
    BudgetResult r{buildAutoMap(importance, options), floor, {}, true, options.maxDensity};
    r.predicted = model.predict(r.map);
    return r;
}

}  // namespace

BudgetResult buildAutoMapForFrameLoss(const Image& importance, const FrameErrorModel& model, double frameLossDb,
                                      AutoMapOptions options, double tileLossDb) {
    if (!(frameLossDb >= 0) || !std::isfinite(frameLossDb))
        invalid("the frame-loss budget " + std::to_string(frameLossDb) + " dB must be finite and >= 0");
    // A higher floor leaves the context more samples: the loss falls as the floor rises. The lowest
    // floor within the budget, by regula falsi (Illinois) in log floor on how far each built map is
    // predicted to be over it: a continuous function of the picture.
    options.refuseBounds = false;
    const auto build = [&](double floor) { return buildAtFloor(importance, model, options, floor); };
    const auto over = [&](const BudgetResult& r) { return std::max(r.predicted.frameLoss - frameLossDb, r.predicted.tileLoss - tileLossDb); };
    const double cap = options.maxDensity;
    const auto search = [&]() {
        BudgetResult low = build(kLowestFloor);
        if (over(low) <= 0) {
            // The lowest floor holds the budget (a map that follows the picture's detail often gains
            // over the whole frame): the rest is spent by raising the density cap, in log cap by
            // regula falsi between the cap given and kHighestCap, as continuous as the floor's.
            options.maxDensity = kHighestCap;
            BudgetResult top = build(kLowestFloor);
            options.maxDensity = cap;
            if (over(top) <= 0 || cap >= kHighestCap) {
                (over(top) <= 0 ? top : low).budgetBinds = false;
                return over(top) <= 0 ? top : low;
            }
            const auto withCap = [&](double logCap) {
                options.maxDensity = std::exp(logCap);
                BudgetResult r = build(kLowestFloor);
                options.maxDensity = cap;
                return r;
            };
            return detail::searchWithin(std::move(low), std::log(cap), std::move(top), std::log(kHighestCap), withCap, over, kSearchSteps,
                                        kFloorTolerance, kToleranceDb);
        }
        BudgetResult high = build(kHighestFloor);
        if (over(high) > 0) return high;  // the closest to the budget there is
        return detail::searchWithin(std::move(high), std::log(kHighestFloor), std::move(low), std::log(kLowestFloor),
                                    [&](double logFloor) { return build(std::exp(logFloor)); }, over, kSearchSteps, kFloorTolerance,
                                    kToleranceDb);
    };
    BudgetResult chosen = search();
    if (const DensityField* context = options.context) {
        // As for foci (foci_budget.cpp): where the context that follows the picture gives the region
        // less (a region softer than the rest, whose factor the max density caps; a context that
        // alone loses the budget) or crowds a few tiles (keepsContext), the uniform context's map is kept.
        options.context = nullptr;
        BudgetResult plain = search();
        if ((over(plain) <= 0 && over(chosen) > 0) || ((over(plain) <= 0) == (over(chosen) <= 0) && !keepsContext(chosen.predicted, plain.predicted)))
            chosen = std::move(plain);
        else
            options.context = context;
    }
    if (model.options().confirm && !model.isConfirmed()) {
        // One real encode of the map chosen, and the choice made again on the model it confirms
        // (the context kept as chosen). A map measured takes its encode and what that encode
        // measured (`confirmedOnIt`: the model its encode confirms).
        const auto measuredBy = [](BudgetResult& r, const FrameErrorModel& confirmedOnIt) {
            r.predicted = confirmedOnIt.predict(r.map);
            r.encode = confirmedOnIt.encode();
        };
        // Whether two maps lie within `tolerance` of each other in log floor and log cap.
        const auto near = [](const BudgetResult& a, const BudgetResult& b, double tolerance) {
            return std::abs(std::log(a.minDensity / b.minDensity)) <= tolerance && std::abs(std::log(a.maxDensity / b.maxDensity)) <= tolerance;
        };
        const FrameErrorModel confirmed = model.confirmed(chosen.map);
        BudgetResult again = buildAutoMapForFrameLoss(importance, confirmed, frameLossDb, options, tileLossDb);
        // Where that choice is next to the map encoded (kNearEncoded in log floor and log cap) and
        // the encoded map holds the budget as measured (or neither does), the map encoded is kept,
        // with its encode and what it measured: the encode is then not made again.
        measuredBy(chosen, confirmed);
        if (near(again, chosen, kNearEncoded) && (over(chosen) <= 0 || over(again) > 0)) return chosen;
        // The choice moved: the map it moved to is encoded (the encode the file then keeps) and
        // measured, and of the two the one whose own encode holds the budget is kept (the more ROI
        // gain where both do, the nearer the budget where neither): what is said of the map kept
        // is what its encode measured.
        const FrameErrorModel moved = model.confirmed(again.map);
        measuredBy(again, moved);
        const bool againHolds = over(again) <= 0, chosenHolds = over(chosen) <= 0;
        if (againHolds != chosenHolds) return againHolds ? again : chosen;
        if (againHolds) return again.predicted.roiGain >= chosen.predicted.roiGain ? again : chosen;
        // Neither holds: the choice made once more on the model the second encode confirms, and that
        // map encoded and measured too (the encode the file keeps, made anyway). Where its encode
        // still misses (the model's carry from the map it measured to a map near it is off by tenths
        // of a dB), one more choice on the model the third encode confirms, under budgets lowered
        // by what the third missed by (detail::loweredBudget), encoded and measured, and where that
        // misses too, one nearer the uniform context (below). The first whose encode holds the
        // budget is kept, else the nearest the budget of the maps measured: what is said of the
        // map kept is what its own encode measured. Where a choice stays at the map measured
        // before it (the highest floor, which still misses), nothing nearer is to be had.
        BudgetResult third = buildAutoMapForFrameLoss(importance, moved, frameLossDb, options, tileLossDb);
        if (near(third, again, kSameMap)) return again;
        const double promised = over(again) - over(third);  // the fall in loss the model said
        const FrameErrorModel thirdModel = model.confirmed(third.map);
        measuredBy(third, thirdModel);
        const double missed = over(third);
        if (missed <= 0) return third;
        const double margin = detail::loweredBudget(missed, (over(again) - missed) / std::max(promised, 1e-9));
        BudgetResult fourth = buildAutoMapForFrameLoss(importance, thirdModel, std::max(0.0, frameLossDb - margin), options,
                                                       std::max(0.0, tileLossDb - margin));
        if (!near(fourth, third, kSameMap)) {
            measuredBy(fourth, model.confirmed(fourth.map));
            if (over(fourth) <= 0) return fourth;
        }
        // Still none: the model led astray (the p95 tile loss is not monotone in the floor where
        // the fit and the region's cap meet; on nuthatch the floors 0.65, 0.77, 0.61 and 0.72 missed
        // by 1.1, 0.26, 0.13 and 0.55 dB). One map halfway (in log) from the highest floor measured
        // to the highest there is, nearer the uniform context, encoded and measured.
        double highest = 0;
        for (const BudgetResult* r : {&chosen, &again, &third, &fourth})
            if (r->encode) highest = std::max(highest, r->minDensity);
        std::optional<BudgetResult> fifth;
        if (highest < kHighestFloor) {
            fifth = buildAtFloor(importance, model, options, std::sqrt(highest * kHighestFloor));
            measuredBy(*fifth, model.confirmed(fifth->map));
            if (over(*fifth) <= 0) return std::move(*fifth);
        }
        BudgetResult* nearest = &third;
        for (BudgetResult* r : {&chosen, &again, &fourth, fifth ? &*fifth : &third})
            if (r->encode && over(*r) < over(*nearest)) nearest = r;
        return std::move(*nearest);
    }
    return chosen;
}

BudgetResult buildAutoMapForBestFrame(const Image& importance, const FrameErrorModel& model, double tileLossDb,
                                      AutoMapOptions options) {
    // The whole-frame loss is not monotone in the floor (too low starves the flat parts, too high
    // leaves the detail nothing): golden-section search in log floor over [kBestLowest, kBestHighest]
    // for the least of the frame's loss plus kTilePenalty per dB the tiles lose over their budget
    // (a continuous objective: a tiny change of the picture moves the floor a little).
    options.refuseBounds = false;
    const auto build = [&](double floor) { return buildAtFloor(importance, model, options, floor); };
    const auto cost = [&](const BudgetResult& r) {
        return r.predicted.frameLoss + kTilePenalty * std::max(0.0, r.predicted.tileLoss - tileLossDb);
    };
    const double g = 0.5 * (std::sqrt(5.0) - 1.0);
    double a = std::log(kBestLowest), b = std::log(kBestHighest);
    double c = b - g * (b - a), d = a + g * (b - a);
    BudgetResult rc = build(std::exp(c)), rd = build(std::exp(d));
    for (int i = 0; i < kGoldenSteps; ++i) {
        if (cost(rc) <= cost(rd)) {
            b = d;
            d = c;
            rd = std::move(rc);
            c = b - g * (b - a);
            rc = build(std::exp(c));
        } else {
            a = c;
            c = d;
            rc = std::move(rd);
            d = a + g * (b - a);
            rd = build(std::exp(d));
        }
    }
    BudgetResult best = cost(rc) <= cost(rd) ? std::move(rc) : std::move(rd);
    best.budgetBinds = best.predicted.tileLoss <= tileLossDb;
    return best;
}

BudgetResult buildOwnDetailMap(const Image& source, const Image& detail, int width, int height, const AutoMapOptions& options,
                               const FrameModelOptions& model) {
    const FrameErrorModel trials(source, width, height, detail, model);
    return buildAutoMapForBestFrame(detail, trials, kOwnDetailTileLoss, options);
}

DensityField ownDetailContext(const Image& source, const Image& detail, int width, int height, const AutoMapOptions& options,
                              const FrameModelOptions& model) {
    return ownDetailContext(FrameErrorModel(source, width, height, detail, model), detail, options);
}

DensityField ownDetailContext(const FrameErrorModel& model, const Image& detail, const AutoMapOptions& options) {
    AutoMapOptions at = options;
    at.minDensity = buildAutoMapForBestFrame(detail, model, kOwnDetailTileLoss, options).minDensity;
    return importanceToDensity(detail, at);
}

BudgetResult buildOwnDetailMap(const EightBitImage& source, const Image& detail, int width, int height,
                               const AutoMapOptions& options, const FrameModelOptions& model) {
    const FrameErrorModel trials(source, width, height, detail, model);
    return buildAutoMapForBestFrame(detail, trials, kOwnDetailTileLoss, options);
}

DensityField ownDetailContext(const EightBitImage& source, const Image& detail, int width, int height,
                              const AutoMapOptions& options, const FrameModelOptions& model) {
    AutoMapOptions at = options;
    at.minDensity = buildOwnDetailMap(source, detail, width, height, options, model).minDensity;
    return importanceToDensity(detail, at);
}

}  // namespace conus::codec
