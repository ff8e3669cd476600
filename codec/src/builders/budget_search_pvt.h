// The budgets' one-dimensional search (foci_budget.cpp, frame_budget.cpp): regula falsi, Illinois
// variant, between a try within the budget and one beyond it, on how far each is over (dB, a
// continuous function of the parameter): the choice is continuous in the picture.
#pragma once

#include <algorithm>
#include <cmath>
#include <utility>

namespace conus::codec::detail {

// `within` (over <= 0) at parameter a, `beyond` (over > 0) at b; build(x) makes the try at x and
// over(try) says how far it is over. Returns the try within the budget closest to it: stops within
// `tolerance` of x, within `toleranceDb` under the budget, or after `steps` tries.
template <class Try, class Build, class Over>
Try searchWithin(Try within, double a, Try beyond, double b, const Build& build, const Over& over, int steps, double tolerance,
                 double toleranceDb) {
    double fa = over(within), fb = over(beyond);
    int side = 0;
    for (int i = 0; i < steps && std::abs(b - a) > tolerance; ++i) {
        double x = (a * fb - b * fa) / (fb - fa);
        const double lo = std::min(a, b), hi = std::max(a, b);
        x = std::clamp(x, lo + 0.01 * (hi - lo), hi - 0.01 * (hi - lo));
        Try mid = build(x);
        const double f = over(mid);
        if (f <= 0 && f > -toleranceDb) return mid;
        if (f <= 0) {
            within = std::move(mid);
            a = x;
            fa = f;
            if (side == -1) fb *= 0.5;
            side = -1;
        } else {
            beyond = std::move(mid);
            b = x;
            fb = f;
            if (side == 1) fa *= 0.5;
            side = 1;
        }
    }
    return within;
}

// After a confirmed model's choice missed the budget by `missed` dB as its own encode measured: how
// far to lower the budget for one last choice on the model that encode confirms. The last move
// fell short of the model's word by `carried` (the share of the predicted fall in loss the
// measure showed, clamped to [1/4, 1]), so the next is asked for the miss over that share, and half
// as much again: a correction measured on one map carries to maps near it only in part, and the
// share falls as the maps near the uniform one (0.52 then 0.42 on frame_budget_test's picture).
inline double loweredBudget(double missed, double carried) {
    constexpr double kSafety = 1.5;
    return missed * (kSafety / std::clamp(carried, 0.25, 1.0) - 1.0);
}

}  // namespace conus::codec::detail
