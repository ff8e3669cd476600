// The bounded-distortion builder (density_map.h, DensityBuilder::Bounded): the grid's nodes are
// the unknowns of one energy, minimised directly.
//
// In the pixel metric (u scaled by the field's aspect, so that anisotropy is measured as
// map_measures.h measures it), each cell's bilinear patch has four corner Jacobians, one per pair
// of its edges (a quadrature of the patch; positive determinants at the four corners is V11). Each
// corner contributes, per unit of undistorted area and weighted by rho (errors count per CoNUS
// pixel, so dense regions come first),
//   w_c (c - 1) + kDensity (log det J - log rho)^2 + barrier(c),
//   c = |J|_F^2 / (2 det J) = (K + 1/K) / 2,  K the ratio of J's singular values,
// rho the target's mean over the cell, normalized to mean 1, w_c = kConformal (rho / min rho)^1.5.
// The density term pulls det J to the target, the small conformal term chooses, among maps of that
// density, the least anisotropic (growing with density, so a focus stays round),
// and the barrier grows without bound as K reaches the bound: an iterate with a corner at or past
// the bound, or folded, has infinite energy and is never accepted. K <= bound at the corners
// holds for the whole patch: the matrices with K <= bound form a convex cone and the patch's
// Jacobian anywhere (its cell mean included) is a convex combination of its corners'.
//
// Minimised by L-BFGS with a backtracking line search, coarse to fine: on a grid of about 9 nodes
// a side first, each level's result prolonged bilinearly to the next (the sub-patches of a patch
// are its own bilinear restriction, so a feasible coarse map gives a feasible fine start) until the
// grid asked for. Boundary nodes slide along their edge, corners stay. Deterministic: one thread,
// a fixed order of operations.
#include "conus/codec/builders/density_map.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "conus/codec/builders/map_measures.h"
#include "conus/core/error.h"
#include "conus/core/map_rules.h"
#include "density_cells_pvt.h"

namespace conus::codec {
namespace {

constexpr double kConformal = 0.01;
// The conformal weight grows as (rho / lowest rho)^kConformalGrowth: a dense region keeps its
// shape (a focus stays round) where the frame's shape would shear it.
constexpr double kConformalGrowth = 1.5;
constexpr double kDensity = 1.0;
// The penalty on a corner's log density below DensityMapOptions::minDensity, per unit squared.
constexpr double kFloor = 50.0;
// The barrier starts at this share of the way from K = 1 to the bound (in c), and weighs this much.
constexpr double kBarrierKnee = 0.8;
constexpr double kBarrier = 1.0;
// A corner this close to degenerate is infeasible (the density term keeps iterates far above it).
constexpr double kMinDet = 1e-6;
constexpr int kCoarsestSide = 9;
constexpr int kMemory = 8;
// Iterations on the coarsest level (cheap: solved to convergence), the levels between, and the
// grid asked for (each level's start is the last one's answer, so a few suffice; more buy a few
// percent of magnification at a proportional cost).
constexpr int kCoarseIterations = 400;
constexpr int kMidIterations = 60;
constexpr int kFineIterations = 30;
// A step moves no node further than this many cells.
constexpr double kMaxStepCells = 1.0;

struct Level {
    int n = 0, m = 0;
    double hx = 0, hy = 0;        // cell size in the pixel metric
    std::vector<double> logRho;   // per cell, row-major
    std::vector<double> weight;     // per cell: its target density (its share of the CoNUS image's pixels)
    std::vector<double> conformal;  // per cell: the conformal term's weight
};

double conformalOf(double anisotropy) { return 0.5 * (anisotropy + 1.0 / anisotropy); }

struct Energy {
    const Level& level;
    double cMax = 0, cKnee = 0;
    double floor = 0, logFloor = 0;  // DensityMapOptions::minDensity (0: none) and its log

    // One corner with Jacobian columns a = d/du, b = d/dv: its energy density in *e and gradient
    // in ga, gb; false when infeasible.
    bool corner(glm::dvec2 a, glm::dvec2 b, double logRho, double conformal, double& e, glm::dvec2& ga, glm::dvec2& gb) const {
        const double det = a.x * b.y - a.y * b.x;
        if (!(det > kMinDet)) return false;
        const double inv = 1.0 / det;
        const double c = 0.5 * (glm::dot(a, a) + glm::dot(b, b)) * inv;
        if (!(c < cMax)) return false;
        const double l = std::log(det) - logRho;
        double coefC = conformal;
        e = conformal * (c - 1.0) + kDensity * l * l;
        double coefDet = 2.0 * kDensity * l * inv;
        if (det < floor) {
            const double under = logFloor - std::log(det);
            e += kFloor * under * under;
            coefDet -= 2.0 * kFloor * under * inv;
        }
        if (c > cKnee) {
            const double t = c - cKnee, gap = cMax - c;
            e += kBarrier * t * t / gap;
            coefC += kBarrier * (2.0 * t / gap + t * t / (gap * gap));
        }
        const glm::dvec2 dDetA(b.y, -b.x), dDetB(-a.y, a.x);
        ga = coefC * inv * (a - c * dDetA) + coefDet * dDetA;
        gb = coefC * inv * (b - c * dDetB) + coefDet * dDetB;
        return true;
    }

    // Total energy of nodes x (interleaved X, Y in pixels); infinity when infeasible. With `grad`,
    // its gradient (every component, fixed ones included).
    double operator()(const std::vector<double>& x, std::vector<double>* grad) const {
        const int n = level.n, m = level.m;
        const double hx = level.hx, hy = level.hy, w = 0.25 * hx * hy;
        if (grad) std::fill(grad->begin(), grad->end(), 0.0);
        double total = 0.0;
        const auto at = [&](std::size_t k) { return glm::dvec2(x[2 * k], x[2 * k + 1]); };
        for (int j = 0; j + 1 < m; ++j) {
            for (int i = 0; i + 1 < n; ++i) {
                const std::size_t k00 = std::size_t(j) * n + i, k10 = k00 + 1, k01 = k00 + n, k11 = k01 + 1;
                const glm::dvec2 p00 = at(k00), p10 = at(k10), p01 = at(k01), p11 = at(k11);
                const glm::dvec2 eb = (p10 - p00) / hx, et = (p11 - p01) / hx;
                const glm::dvec2 el = (p01 - p00) / hy, er = (p11 - p10) / hy;
                const double logRho = level.logRho[std::size_t(j) * (n - 1) + i];
                const double conformal = level.conformal[std::size_t(j) * (n - 1) + i];
                double e[4];
                glm::dvec2 ga[4], gb[4];
                if (!corner(eb, el, logRho, conformal, e[0], ga[0], gb[0]) || !corner(eb, er, logRho, conformal, e[1], ga[1], gb[1]) ||
                    !corner(et, er, logRho, conformal, e[2], ga[2], gb[2]) || !corner(et, el, logRho, conformal, e[3], ga[3], gb[3]))
                    return HUGE_VAL;
                const double wc = w * level.weight[std::size_t(j) * (n - 1) + i];
                total += wc * (e[0] + e[1] + e[2] + e[3]);
                if (!grad) continue;
                const glm::dvec2 gEb = (wc / hx) * (ga[0] + ga[1]), gEt = (wc / hx) * (ga[2] + ga[3]);
                const glm::dvec2 gEl = (wc / hy) * (gb[0] + gb[3]), gEr = (wc / hy) * (gb[1] + gb[2]);
                const auto add = [&](std::size_t k, glm::dvec2 g) {
                    (*grad)[2 * k] += g.x;
                    (*grad)[2 * k + 1] += g.y;
                };
                add(k10, gEb - gEr);
                add(k00, -gEb - gEl);
                add(k11, gEt + gEr);
                add(k01, -gEt + gEl);
            }
        }
        return total;
    }
};

double dot(const std::vector<double>& a, const std::vector<double>& b) {
    double s = 0.0;
    for (std::size_t k = 0; k < a.size(); ++k) s += a[k] * b[k];
    return s;
}

// L-BFGS from a feasible x; fixed components never move. Returns the iterations taken.
int minimise(const Energy& energy, std::vector<double>& x, const std::vector<unsigned char>& fixed, int maxIterations) {
    const std::size_t size = x.size();
    const double maxStep = kMaxStepCells * std::min(energy.level.hx, energy.level.hy);
    std::vector<double> g(size), gNew(size), d(size), xNew(size);
    const auto mask = [&](std::vector<double>& v) {
        for (std::size_t k = 0; k < size; ++k)
            if (fixed[k]) v[k] = 0.0;
    };
    double f = energy(x, &g);
    if (!std::isfinite(f)) return 0;
    mask(g);
    std::vector<std::vector<double>> s(kMemory, std::vector<double>(size)), y(kMemory, std::vector<double>(size));
    std::vector<double> rho(kMemory), alpha(kMemory);
    int stored = 0, head = 0, stall = 0, iteration = 0;
    for (; iteration < maxIterations; ++iteration) {
        // Two-loop recursion: d = -H g.
        for (std::size_t k = 0; k < size; ++k) d[k] = -g[k];
        for (int c = 0; c < stored; ++c) {
            const int idx = (head - 1 - c + kMemory) % kMemory;
            alpha[idx] = rho[idx] * dot(s[idx], d);
            for (std::size_t k = 0; k < size; ++k) d[k] -= alpha[idx] * y[idx][k];
        }
        if (stored > 0) {
            const int last = (head - 1 + kMemory) % kMemory;
            const double scale = 1.0 / (rho[last] * dot(y[last], y[last]));
            for (double& v : d) v *= scale;
        }
        for (int c = stored - 1; c >= 0; --c) {
            const int idx = (head - 1 - c + kMemory) % kMemory;
            const double beta = rho[idx] * dot(y[idx], d);
            for (std::size_t k = 0; k < size; ++k) d[k] += (alpha[idx] - beta) * s[idx][k];
        }
        double gd = dot(g, d);
        if (!(gd < 0.0)) {
            stored = 0;
            for (std::size_t k = 0; k < size; ++k) d[k] = -g[k];
            gd = dot(g, d);
        }
        if (!(gd < 0.0)) break;  // a zero gradient: done
        double largest = 0.0;
        for (std::size_t k = 0; k < size; ++k) largest = std::max(largest, std::abs(d[k]));
        double t = std::min(1.0, maxStep / largest);
        if (stored == 0) t = std::min(t, 0.25 * maxStep / largest);
        bool accepted = false;
        double fNew = f;
        for (int tries = 0; tries < 40; ++tries) {
            for (std::size_t k = 0; k < size; ++k) xNew[k] = x[k] + t * d[k];
            fNew = energy(xNew, &gNew);
            if (fNew <= f + 1e-4 * t * gd) {
                accepted = true;
                break;
            }
            t *= std::isfinite(fNew) ? 0.5 : 0.25;
        }
        if (!accepted) {
            if (stored == 0) break;
            stored = 0;
            continue;
        }
        mask(gNew);
        for (std::size_t k = 0; k < size; ++k) {
            s[head][k] = xNew[k] - x[k];
            y[head][k] = gNew[k] - g[k];
        }
        const double sy = dot(s[head], y[head]);
        if (sy > 1e-300) {
            rho[head] = 1.0 / sy;
            head = (head + 1) % kMemory;
            stored = std::min(stored + 1, kMemory);
        }
        stall = (f - fNew <= 1e-9 * std::max(1e-3, std::abs(f))) ? stall + 1 : 0;
        x.swap(xNew);
        g.swap(gNew);
        f = fNew;
        if (stall >= 5) break;
    }
    return iteration;
}

Level makeLevel(const DensityField& target, int n, int m, double aspect) {
    Level level;
    level.n = n;
    level.m = m;
    level.hx = aspect / (n - 1);
    level.hy = 1.0 / (m - 1);
    level.logRho = cellTargets(target, n, m);
    level.weight = level.logRho;
    const double lowest = *std::min_element(level.logRho.begin(), level.logRho.end());
    level.conformal = level.logRho;
    for (double& c : level.conformal) c = kConformal * std::pow(c / lowest, kConformalGrowth);
    for (double& r : level.logRho) r = std::log(r);
    return level;
}

std::vector<double> identityNodes(int n, int m, double aspect) {
    std::vector<double> x(std::size_t(2) * n * m);
    for (int j = 0; j < m; ++j)
        for (int i = 0; i < n; ++i) {
            x[2 * (std::size_t(j) * n + i)] = aspect * i / (n - 1);
            x[2 * (std::size_t(j) * n + i) + 1] = double(j) / (m - 1);
        }
    return x;
}

// The coarse level's map (Eq. 1 on its nodes) at the fine level's nodes, boundary exact.
std::vector<double> prolong(const std::vector<double>& coarse, int cn, int cm, int n, int m, double aspect) {
    std::vector<double> x(std::size_t(2) * n * m);
    for (int j = 0; j < m; ++j) {
        const double t = double(j) / (m - 1) * (cm - 1);
        const int cj = std::min(static_cast<int>(t), cm - 2);
        const double b = t - cj;
        for (int i = 0; i < n; ++i) {
            const double s = double(i) / (n - 1) * (cn - 1);
            const int ci = std::min(static_cast<int>(s), cn - 2);
            const double a = s - ci;
            for (int c = 0; c < 2; ++c) {
                const auto node = [&](int di, int dj) { return coarse[2 * (std::size_t(cj + dj) * cn + ci + di) + c]; };
                x[2 * (std::size_t(j) * n + i) + c] =
                    (1 - a) * (1 - b) * node(0, 0) + a * (1 - b) * node(1, 0) + (1 - a) * b * node(0, 1) + a * b * node(1, 1);
            }
            if (i == 0) x[2 * (std::size_t(j) * n + i)] = 0.0;
            if (i == n - 1) x[2 * (std::size_t(j) * n + i)] = aspect;
            if (j == 0) x[2 * (std::size_t(j) * n + i) + 1] = 0.0;
            if (j == m - 1) x[2 * (std::size_t(j) * n + i) + 1] = 1.0;
        }
    }
    return x;
}

std::vector<unsigned char> fixedComponents(int n, int m) {
    std::vector<unsigned char> fixed(std::size_t(2) * n * m, 0);
    for (int j = 0; j < m; ++j)
        for (int i = 0; i < n; ++i) {
            const std::size_t k = std::size_t(j) * n + i;
            if (i == 0 || i == n - 1) fixed[2 * k] = 1;
            if (j == 0 || j == m - 1) fixed[2 * k + 1] = 1;
        }
    return fixed;
}

}  // namespace

std::vector<double> cellTargets(const DensityField& target, int columns, int rows) {
    const int cw = columns - 1, ch = rows - 1, fw = target.width, fh = target.height;
    // Enough samples a cell that every field sample is seen, bilinear between them.
    const int sx = std::clamp((fw + cw - 1) / cw + 1, 2, 16), sy = std::clamp((fh + ch - 1) / ch + 1, 2, 16);
    const auto value = [&](int x, int y) { return double(target.values[std::size_t(std::clamp(y, 0, fh - 1)) * fw + std::clamp(x, 0, fw - 1)]); };
    std::vector<double> cells(std::size_t(cw) * ch);
    double sum = 0.0;
    for (int j = 0; j < ch; ++j)
        for (int i = 0; i < cw; ++i) {
            double acc = 0.0;
            for (int b = 0; b < sy; ++b)
                for (int a = 0; a < sx; ++a) {
                    const double fx = (i + (a + 0.5) / sx) / cw * fw - 0.5, fy = (j + (b + 0.5) / sy) / ch * fh - 0.5;
                    const int x0 = static_cast<int>(std::floor(fx)), y0 = static_cast<int>(std::floor(fy));
                    const double tx = fx - x0, ty = fy - y0;
                    acc += (1 - tx) * (1 - ty) * value(x0, y0) + tx * (1 - ty) * value(x0 + 1, y0) +
                           (1 - tx) * ty * value(x0, y0 + 1) + tx * ty * value(x0 + 1, y0 + 1);
                }
            cells[std::size_t(j) * cw + i] = acc / (sx * sy);
            sum += cells[std::size_t(j) * cw + i];
        }
    const double mean = sum / double(cells.size());
    for (double& c : cells) c /= mean;
    return cells;
}

void compareWithTarget(const SamplingMap& map, const DensityField& target, double aspect, DensityMapReport& report) {
    const int n = map.columns(), m = map.rows();
    const std::vector<double> cells = cellTargets(target, n, m);
    const map_rules::GridView grid{n, m, &map.nodes().front().x};
    report.lowestRatio = HUGE_VAL;
    report.highestRatio = 0.0;
    double peak = 0.0;
    for (int j = 0; j + 1 < m; ++j)
        for (int i = 0; i + 1 < n; ++i) {
            const double wanted = cells[std::size_t(j) * (n - 1) + i];
            const double ratio = cellDensity(grid, i, j) / wanted;
            report.lowestRatio = std::min(report.lowestRatio, ratio);
            report.highestRatio = std::max(report.highestRatio, ratio);
            if (wanted > peak) {
                peak = wanted;
                report.peakRatio = ratio;
            }
        }
    report.maxAnisotropy = measureMap(map, aspect).maxAnisotropy;
}

SamplingMap buildBoundedMap(const DensityField& target, const DensityMapOptions& options, DensityMapReport* report) {
    const double aspect = buildAspect(target, options);
    const double bound = options.maxAnisotropy > 0 ? options.maxAnisotropy : map_rules::kMaxAnisotropy;
    // Coarse to fine: the grids, coarsest first.
    std::vector<std::pair<int, int>> sides{{options.columns, options.rows}};
    while (std::min(sides.back().first, sides.back().second) > kCoarsestSide)
        sides.push_back({(sides.back().first + 1) / 2, (sides.back().second + 1) / 2});
    std::reverse(sides.begin(), sides.end());
    const double cMax = conformalOf(bound);
    std::vector<double> x;
    int iterations = 0, previousN = 0, previousM = 0;
    for (std::size_t l = 0; l < sides.size(); ++l) {
        const auto [n, m] = sides[l];
        const Level level = makeLevel(target, n, m, aspect);
        const double floor = options.minDensity > 0 ? options.minDensity : 0.0;
        const Energy energy{level, cMax, 1.0 + kBarrierKnee * (cMax - 1.0), floor, floor > 0 ? std::log(floor) : 0.0};
        x = l == 0 ? identityNodes(n, m, aspect) : prolong(x, previousN, previousM, n, m, aspect);
        // A prolongation across misaligned grids could leave the feasible set; start afresh then.
        if (!std::isfinite(energy(x, nullptr))) x = identityNodes(n, m, aspect);
        iterations += minimise(energy, x, fixedComponents(n, m),
                               l == 0 ? kCoarseIterations : l + 1 == sides.size() ? kFineIterations : kMidIterations);
        previousN = n;
        previousM = m;
    }
    const int n = options.columns, m = options.rows;
    std::vector<glm::vec2> nodes(std::size_t(n) * m);
    for (int j = 0; j < m; ++j)
        for (int i = 0; i < n; ++i) {
            const std::size_t k = std::size_t(j) * n + i;
            glm::vec2 p(static_cast<float>(std::clamp(x[2 * k] / aspect, 0.0, 1.0)), static_cast<float>(std::clamp(x[2 * k + 1], 0.0, 1.0)));
            if (i == 0) p.x = 0.0f;
            if (i == n - 1) p.x = 1.0f;
            if (j == 0) p.y = 0.0f;
            if (j == m - 1) p.y = 1.0f;
            nodes[k] = p;
        }
    // Every accepted iterate is feasible, so this holds but for float rounding of a barely convex
    // cell, which the barrier keeps far away; the identity is the safe answer then.
    if (!map_rules::isValidGrid({n, m, &nodes.front().x})) nodes = SamplingMap::identity(n, m).nodes();
    SamplingMap map(n, m, std::move(nodes));
    if (report) {
        *report = {};
        report->bound = bound;
        report->iterations = iterations;
        compareWithTarget(map, target, aspect, *report);
    }
    return map;
}

}  // namespace conus::codec
