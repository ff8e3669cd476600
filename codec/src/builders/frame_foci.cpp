// Closed-form per-frame focus maps: lenses evaluated at the nodes, displacements added, one fold
// factor for the sum (frame_foci.h).
#include "conus/codec/builders/frame_foci.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "conus/core/error.h"
#include "conus/core/limits.h"
#include "conus/core/map_rules.h"

namespace conus::codec {
namespace {

// h(x) / x - 1 for x in [0, 1): the factor a node's offset from the lens centre grows by.
double lensGain(double x, double k) {
    const double rest = 1.0 - x, knee = kFalloffRadii * (k - 1.0) * x;
    return (k - 1.0) * rest * rest / std::sqrt(std::sqrt(1.0 + knee * knee * knee * knee));
}

// The smallest s in (0, limit] where a + b s + c s^2 reaches 0, given a > 0; `limit` when none.
double firstRoot(double a, double b, double c, double limit) {
    double root = limit;
    const auto take = [&](double s) {
        if (s > 0.0 && s < root) root = s;
    };
    if (c == 0.0) {
        if (b < 0.0) take(-a / b);
        return root;
    }
    const double disc = b * b - 4.0 * a * c;
    if (disc < 0.0) return root;  // a > 0 and no real root: positive for every s
    // The cancellation-free pair of roots.
    const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
    if (q != 0.0) {
        take(q / c);
        take(a / q);
    }
    return root;
}

}  // namespace

double lensProfile(double x, double k) {
    if (!(x >= 0.0 && x < 1.0)) return x;
    return x * (1.0 + lensGain(x, k));
}

SamplingMap buildFrameFociMap(std::span<const Focus> foci, const FociOptions& options) {
    if (!(options.aspect > 0.0) || !std::isfinite(options.aspect))
        throw Error(ErrorCode::InvalidArgument, "aspect " + numberText(options.aspect) + " is not finite and > 0");
    if (options.columns < kMinMapSide || options.rows < kMinMapSide || options.columns > kMaxMapSide ||
        options.rows > kMaxMapSide)
        throw Error(ErrorCode::InvalidArgument, "frame map grid " + std::to_string(options.columns) + "x" +
                                                    std::to_string(options.rows) + " is outside " +
                                                    std::to_string(kMinMapSide) + ".." + std::to_string(kMaxMapSide) +
                                                    " nodes a side");
    for (const Focus& f : foci) checkFocus(f);
    const int columns = options.columns, rows = options.rows;
    if (foci.empty()) return SamplingMap::identity(columns, rows);

    const std::size_t count = std::size_t(columns) * rows;
    const double du = 1.0 / (columns - 1), dv = 1.0 / (rows - 1);
    std::vector<double> base(2 * count), shift(2 * count, 0.0);
    for (int j = 0; j < rows; ++j)
        for (int i = 0; i < columns; ++i) {
            const std::size_t n = 2 * (std::size_t(j) * columns + i);
            base[n] = (i == columns - 1) ? 1.0 : i * du;
            base[n + 1] = (j == rows - 1) ? 1.0 : j * dv;
        }

    // Each lens touches only the nodes inside its falloff disc (an ellipse in u, v).
    const double aspect = options.aspect;
    for (const Focus& f : foci) {
        if (f.k == 1.0) continue;
        const double radius = kFalloffRadii * f.r;  // widths
        const int i0 = std::max(0, static_cast<int>(std::floor((f.u - radius) / du)));
        const int i1 = std::min(columns - 1, static_cast<int>(std::ceil((f.u + radius) / du)));
        const int j0 = std::max(0, static_cast<int>(std::floor((f.v - radius * aspect) / dv)));
        const int j1 = std::min(rows - 1, static_cast<int>(std::ceil((f.v + radius * aspect) / dv)));
        for (int j = j0; j <= j1; ++j)
            for (int i = i0; i <= i1; ++i) {
                const std::size_t n = 2 * (std::size_t(j) * columns + i);
                const double x = base[n] - f.u, y = (base[n + 1] - f.v) / aspect;  // widths
                const double reach = std::sqrt(x * x + y * y) / radius;
                if (reach >= 1.0) continue;
                const double gain = lensGain(reach, f.k);
                shift[n] += x * gain;
                shift[n + 1] += y * gain * aspect;
            }
    }
    // Boundary nodes slide along their edge only (V10).
    for (int j = 0; j < rows; ++j) {
        shift[2 * (std::size_t(j) * columns)] = 0.0;
        shift[2 * (std::size_t(j) * columns + columns - 1)] = 0.0;
    }
    for (int i = 0; i < columns; ++i) {
        shift[2 * std::size_t(i) + 1] = 0.0;
        shift[2 * (std::size_t(rows - 1) * columns + i) + 1] = 0.0;
    }

    // The fold factor: the first s at which a node leaves [0,1]^2 or a cell corner's cross product
    // (V11's measure, quadratic in s) reaches 0. Only factors up to 1 / kFoldMargin matter.
    const double limit = 1.0 / kFoldMargin;
    double fold = limit;
    for (std::size_t n = 0; n < 2 * count; ++n) {
        if (shift[n] > 0.0) fold = std::min(fold, (1.0 - base[n]) / shift[n]);
        else if (shift[n] < 0.0) fold = std::min(fold, -base[n] / shift[n]);
    }
    const auto at = [&](int i, int j) { return 2 * (std::size_t(j) * columns + i); };
    for (int j = 0; j + 1 < rows; ++j)
        for (int i = 0; i + 1 < columns; ++i) {
            std::size_t corner[4];
            bool moved = false;
            for (int c = 0; c < 4; ++c) {
                corner[c] = at(i + map_rules::kCornerDi[c], j + map_rules::kCornerDj[c]);
                moved = moved || shift[corner[c]] != 0.0 || shift[corner[c] + 1] != 0.0;
            }
            if (!moved) continue;  // an identity cell stays valid at every s
            for (int c = 0; c < 4; ++c) {
                const std::size_t p = corner[(c + 3) & 3], m = corner[c], q = corner[(c + 1) & 3];
                // Incoming edge e = m - p and outgoing edge g = q - m, each base + s * shift.
                const double eu = base[m] - base[p], ev = base[m + 1] - base[p + 1];
                const double gu = base[q] - base[m], gv = base[q + 1] - base[m + 1];
                const double seu = shift[m] - shift[p], sev = shift[m + 1] - shift[p + 1];
                const double sgu = shift[q] - shift[m], sgv = shift[q + 1] - shift[m + 1];
                const double a = eu * gv - ev * gu;
                const double b = eu * sgv - ev * sgu + seu * gv - sev * gu;
                const double c2 = seu * sgv - sev * sgu;
                fold = std::min(fold, firstRoot(a, b, c2, limit));
            }
        }

    // The anisotropy factor: the first s at which a cell's mean Jacobian, in pixels I + s S, reaches
    // the bound K. With S's conformal part c and anticonformal part a (as vectors), K holds while
    // |s a| <= q |(1, 0) + s c|, q = (K - 1) / (K + 1): a quadratic in s, positive at 0.
    const double bound = options.maxAnisotropy > 0 ? options.maxAnisotropy : map_rules::kMaxAnisotropy;
    const double q = (bound - 1.0) / (bound + 1.0);
    double stretch = 1.0 / kAnisotropyMargin;
    for (int j = 0; j + 1 < rows; ++j)
        for (int i = 0; i + 1 < columns; ++i) {
            const std::size_t n00 = at(i, j), n10 = at(i + 1, j), n01 = at(i, j + 1), n11 = at(i + 1, j + 1);
            // Mean d shift / du and d shift / dv over the cell, then in pixels (x = aspect * u).
            const double su_u = 0.5 * (shift[n10] - shift[n00] + shift[n11] - shift[n01]) / du;
            const double sv_u = 0.5 * (shift[n10 + 1] - shift[n00 + 1] + shift[n11 + 1] - shift[n01 + 1]) / du;
            const double su_v = 0.5 * (shift[n01] - shift[n00] + shift[n11] - shift[n10]) / dv;
            const double sv_v = 0.5 * (shift[n01 + 1] - shift[n00 + 1] + shift[n11 + 1] - shift[n10 + 1]) / dv;
            const double m00 = su_u, m01 = su_v * aspect, m10 = sv_u / aspect, m11 = sv_v;
            const double cx = 0.5 * (m00 + m11), cy = 0.5 * (m10 - m01), ax = 0.5 * (m00 - m11), ay = 0.5 * (m10 + m01);
            if (ax == 0.0 && ay == 0.0) continue;
            stretch = std::min(stretch, firstRoot(q * q, 2.0 * q * q * cx, q * q * (cx * cx + cy * cy) - (ax * ax + ay * ay), stretch));
        }

    // The nodes at s; single-precision rounding can still break a cell squeezed to V11's limit,
    // which the rules' own check catches, and a smaller s then mends.
    double s = std::min({1.0, kFoldMargin * fold, kAnisotropyMargin * stretch});
    std::vector<glm::vec2> nodes(count);
    for (int attempt = 0;; ++attempt) {
        for (std::size_t n = 0; n < count; ++n)
            nodes[n] = glm::vec2(static_cast<float>(std::clamp(base[2 * n] + s * shift[2 * n], 0.0, 1.0)),
                                 static_cast<float>(std::clamp(base[2 * n + 1] + s * shift[2 * n + 1], 0.0, 1.0)));
        if (map_rules::isValidGrid(columns, rows, nodes) || attempt == 64) break;
        s *= 0.5;
    }
    return SamplingMap(columns, rows, std::move(nodes));
}

}  // namespace conus::codec
