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

}  // namespace conus::codec::detail
