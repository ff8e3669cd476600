// Where steps in a map's density come from: not the rasterized foci (their density is C2 and sampled
// at >= 12 samples a radius) nor the Poisson solve's boundary (exact Neumann, zero normal flow),
// but fitting the grid to the flow. Moser's flow is injective, but it shears: between two foci the
// context divides between them, and along the divide the nodes' paths fan out so fast that
// bilinear cells fold although the nodes are exact (more integration steps or a finer density
// grid change nothing). The fold used to be repaired by relaxing a growing region of nodes to the
// mean of their neighbours: inside it the density flattened, at its border it jumped (the steps),
// and beside it cells were left barely convex (the channel of almost no samples). Relaxing with a
// smooth weight only spread the damage. So a grid that folds, or has a cell sparser than half the
// lowest target density, is not repaired: the density is tempered (rho^gamma) until the flow's
// own grid is valid and healthy, which keeps the map as smooth as the flow.
//
// buildMapFromDensity: Moser's flow. The Neumann Poisson problem is solved by a DCT on the density
// grid (the only FFTW user in this file); grad(phi) lives on the cell faces (a staggered grid), so
// its discrete divergence is exactly rho - 1 and its normal component is exactly 0 on the border.
//
// The density samples are taken as square, like pixels: the flow runs in that isotropic metric
// (a width/height aspect), not in (u,v), so a focus circular in pixels is magnified equally along
// u and v. det J is the same either way; only the shape of the magnification differs.
#include "conus/codec/builders/density_map.h"

#include "conus/codec/builders/map_measures.h"
#include "density_cells_pvt.h"

#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <string>

#include "conus/core/error.h"
#include "conus/core/map_rules.h"
#include "conus/core/parallel.h"

namespace conus::codec {
namespace {

constexpr double kPi = 3.14159265358979323846;
// When the flow's grid folds the density is tempered to rho^gamma, gamma found by this many
// bisection steps between 0 (the identity, always valid) and 1: the strongest valid map within
// 1/64 in gamma.
constexpr int kTemperingSteps = 6;
// The anisotropy limit is a promise, so it is bisected finer: within 1/256 in gamma.
constexpr int kAnisotropyTemperingSteps = 8;
// No cell may come out sparser than this share of the lowest target density: below it the flow's
// grid is treated as folded.
constexpr double kMinDensityShare = 0.5;

// FFTW's planner is not thread-safe; plans are created and destroyed under this lock.
std::mutex& fftwPlannerMutex() {
    static std::mutex mutex;
    return mutex;
}

// fftw_malloc'ed buffer: FFTW's choice of codelets depends on alignment, and keeping it fixed
// keeps the result bit-for-bit reproducible.
class FftwBuffer {
public:
    explicit FftwBuffer(std::size_t n) : m_data(fftw_alloc_real(n)) {
        if (!m_data) throw Error(ErrorCode::LimitExceeded, "cannot allocate " + std::to_string(n) + " doubles for the DCT");
    }
    ~FftwBuffer() { fftw_free(m_data); }
    FftwBuffer(const FftwBuffer&) = delete;
    FftwBuffer& operator=(const FftwBuffer&) = delete;
    double* data() { return m_data; }

private:
    double* m_data;
};

class Dct2d {
public:
    // kind: FFTW_REDFT10 (DCT-II, forward) or FFTW_REDFT01 (DCT-III, inverse up to 4WH).
    Dct2d(int width, int height, double* in, double* out, fftw_r2r_kind kind) {
        std::lock_guard lock(fftwPlannerMutex());
        m_plan = fftw_plan_r2r_2d(height, width, in, out, kind, kind, FFTW_ESTIMATE);
        if (!m_plan) throw Error(ErrorCode::Unsupported, "FFTW could not plan a " + std::to_string(width) + "x" + std::to_string(height) + " DCT");
    }
    ~Dct2d() {
        std::lock_guard lock(fftwPlannerMutex());
        fftw_destroy_plan(m_plan);
    }
    Dct2d(const Dct2d&) = delete;
    Dct2d& operator=(const Dct2d&) = delete;
    void run() { fftw_execute(m_plan); }

private:
    fftw_plan m_plan = nullptr;
};

// The velocity field's ingredients on the density grid (W x H cells over [0,1]^2).
struct FlowField {
    int width = 0, height = 0;
    std::vector<double> rho;  // W x H, cell centres, mean 1
    // (d phi/du, d phi/dv, rho) at the (W+1) x (H+1) cell corners, so that the flow's inner loop
    // is one bilinear lookup. The gradient is taken on the faces (staggered), then averaged onto
    // the corners: d phi/du is 0 on the left and right edges, d phi/dv on the top and bottom ones.
    std::vector<glm::dvec3> corners;
};

// Solves the 5-point Neumann Poisson problem lap(phi) = rhs exactly on a w x h grid of square
// samples of side 1/h (rhs of mean 0; its eigenvectors are the DCT-II basis); phi has mean 0.
std::vector<double> solvePoisson(int w, int h, const std::vector<double>& rhs) {
    const std::size_t count = std::size_t(w) * h;
    FftwBuffer buffer(count);
    double* a = buffer.data();
    Dct2d forward(w, h, a, a, FFTW_REDFT10);
    Dct2d inverse(w, h, a, a, FFTW_REDFT01);
    for (std::size_t k = 0; k < count; ++k) a[k] = rhs[k];
    forward.run();
    // Square samples of side 1/h: the domain is [0, w/h] x [0, 1] in that metric.
    const double h2 = double(h) * h;
    std::vector<double> lx(w), ly(h);
    for (int i = 0; i < w; ++i) lx[i] = (2.0 * std::cos(kPi * i / w) - 2.0) * h2;
    for (int j = 0; j < h; ++j) ly[j] = (2.0 * std::cos(kPi * j / h) - 2.0) * h2;
    const double norm = 1.0 / (4.0 * double(w) * h);
    for (int j = 0; j < h; ++j) {
        for (int i = 0; i < w; ++i) {
            double& v = a[std::size_t(j) * w + i];
            v = (i == 0 && j == 0) ? 0.0 : v * norm / (lx[i] + ly[j]);
        }
    }
    inverse.run();
    return std::vector<double>(a, a + count);
}

// The gradient of phi (in (u,v) units) and rho at the cell corners: phi differentiated on the
// faces (staggered), averaged onto the corners; d phi/du is 0 on the left and right edges, d phi/dv
// on the top and bottom ones.
void gradientCorners(FlowField& field, const std::vector<double>& potential) {
    const int w = field.width, h = field.height;
    const double h2 = double(h) * h;
    const double* phi = potential.data();
    // The gradient in the square metric, divided by the domain's extent (w/h, 1): velocities in (u,v).
    const double sx = h2 / w, sy = h;
    auto gxFace = [&](int i, int j) { return i > 0 && i < w ? (phi[std::size_t(j) * w + i] - phi[std::size_t(j) * w + i - 1]) * sx : 0.0; };
    auto gyFace = [&](int i, int j) { return j > 0 && j < h ? (phi[std::size_t(j) * w + i] - phi[std::size_t(j - 1) * w + i]) * sy : 0.0; };
    const std::vector<double>& rho = field.rho;
    field.corners.resize(std::size_t(w + 1) * (h + 1));
    for (int j = 0; j <= h; ++j) {
        const int ja = std::max(j - 1, 0), jb = std::min(j, h - 1);
        for (int i = 0; i <= w; ++i) {
            const int ia = std::max(i - 1, 0), ib = std::min(i, w - 1);
            const double gx = 0.5 * (gxFace(i, ja) + gxFace(i, jb));
            const double gy = 0.5 * (gyFace(ia, j) + gyFace(ib, j));
            const double r = 0.25 * (rho[std::size_t(ja) * w + ia] + rho[std::size_t(ja) * w + ib] +
                                     rho[std::size_t(jb) * w + ia] + rho[std::size_t(jb) * w + ib]);
            field.corners[std::size_t(j) * (w + 1) + i] = {gx, gy, r};
        }
    }
}

// Moser's velocity field: lap(phi) = rho - 1.
void solveFlowField(FlowField& field) {
    std::vector<double> rhs(field.rho.size());
    for (std::size_t k = 0; k < rhs.size(); ++k) rhs[k] = field.rho[k] - 1.0;
    gradientCorners(field, solvePoisson(field.width, field.height, rhs));
}

inline glm::dvec2 velocity(const FlowField& f, glm::dvec2 p, double t) {
    const double x = p.x * f.width, y = p.y * f.height;  // p is already clamped to [0,1]^2
    const int i = std::min(static_cast<int>(x), f.width - 1), j = std::min(static_cast<int>(y), f.height - 1);
    const double a = x - i, b = y - j;
    const glm::dvec3* c0 = f.corners.data() + std::size_t(j) * (f.width + 1) + i;
    const glm::dvec3* c1 = c0 + (f.width + 1);
    const glm::dvec3 top = c0[0] + (c0[1] - c0[0]) * a;
    const glm::dvec3 bottom = c1[0] + (c1[1] - c1[0]) * a;
    const glm::dvec3 g = top + (bottom - top) * b;
    const double inv = 1.0 / ((1.0 - t) * g.z + t);
    return {g.x * inv, g.y * inv};
}

inline glm::dvec2 clampUnit(glm::dvec2 p) { return {std::clamp(p.x, 0.0, 1.0), std::clamp(p.y, 0.0, 1.0)}; }

// Moves every node along the flow from t = 0 to 1 (RK4) and puts boundary nodes back on their
// edge exactly (the flow keeps them there up to rounding; V10 is exact).
format::GridNodes integrateNodes(const FlowField& field, const DensityMapOptions& options) {
    const int n = options.columns, m = options.rows, steps = options.steps;
    format::GridNodes grid;
    grid.columns = n;
    grid.rows = m;
    grid.xy.assign(std::size_t(2) * n * m, 0.0f);
    const double dt = 1.0 / steps;
    parallelRows(m, 0, [&](int j0, int j1) {
        // A whole row advances stage by stage: the nodes' RK4 chains are independent, so their
        // lookups and divisions overlap instead of waiting on one another.
        std::vector<glm::dvec2> p(n), k(n), sum(n);
        for (int j = j0; j < j1; ++j) {
            for (int i = 0; i < n; ++i) p[i] = {double(i) / (n - 1), double(j) / (m - 1)};
            for (int s = 0; s < steps; ++s) {
                const double t = s * dt;
                for (int i = 0; i < n; ++i) sum[i] = k[i] = velocity(field, p[i], t);
                for (int i = 0; i < n; ++i) sum[i] += 2.0 * (k[i] = velocity(field, clampUnit(p[i] + 0.5 * dt * k[i]), t + 0.5 * dt));
                for (int i = 0; i < n; ++i) sum[i] += 2.0 * (k[i] = velocity(field, clampUnit(p[i] + 0.5 * dt * k[i]), t + 0.5 * dt));
                for (int i = 0; i < n; ++i) sum[i] += velocity(field, clampUnit(p[i] + dt * k[i]), t + dt);
                for (int i = 0; i < n; ++i) p[i] = clampUnit(p[i] + (dt / 6.0) * sum[i]);
            }
            for (int i = 0; i < n; ++i) {
                glm::dvec2 q = p[i];
                if (i == 0) q.x = 0.0;
                if (i == n - 1) q.x = 1.0;
                if (j == 0) q.y = 0.0;
                if (j == m - 1) q.y = 1.0;
                const std::size_t idx = 2 * (std::size_t(j) * n + i);
                grid.xy[idx] = static_cast<float>(q.x);
                grid.xy[idx + 1] = static_cast<float>(q.y);
            }
        }
    }, 4);
    return grid;
}

double minCellDensityOf(const format::GridNodes& grid) {
    double lowest = HUGE_VAL;
    for (int j = 0; j + 1 < grid.rows; ++j)
        for (int i = 0; i + 1 < grid.columns; ++i) lowest = std::min(lowest, cellDensity({grid.columns, grid.rows, grid.xy.data()}, i, j));
    return lowest;
}

void checkInput(const DensityField& target, const DensityMapOptions& options) {
    if (target.width <= 0 || target.height <= 0 || target.values.size() != std::size_t(target.width) * target.height) {
        throw Error(ErrorCode::InvalidArgument, "density field is " + std::to_string(target.width) + "x" +
                                                    std::to_string(target.height) + " with " +
                                                    std::to_string(target.values.size()) + " values");
    }
    for (std::size_t k = 0; k < target.values.size(); ++k) {
        const float v = target.values[k];
        if (!std::isfinite(v) || !(v > 0.0f)) {
            throw Error(ErrorCode::InvalidArgument, "density value " + std::to_string(v) + " at (" +
                                                        std::to_string(k % target.width) + "," +
                                                        std::to_string(k / target.width) + ") is not finite and > 0");
        }
    }
    if (!(options.maxAnisotropy == 0 || options.maxAnisotropy >= 1.0) || !std::isfinite(options.maxAnisotropy)) {
        throw Error(ErrorCode::InvalidArgument, "max anisotropy " + numberText(options.maxAnisotropy) + " must be >= 1 (or 0: no limit)");
    }
    if (options.columns < 2 || options.rows < 2 || options.columns > kMaxMapSide || options.rows > kMaxMapSide || options.steps < 1) {
        throw Error(ErrorCode::InvalidArgument, "density map options: grid " + std::to_string(options.columns) + "x" +
                                                    std::to_string(options.rows) + " (each in [2," + std::to_string(kMaxMapSide) + "]), steps " +
                                                    std::to_string(options.steps) + " (>= 1)");
    }
}

}  // namespace

SamplingMap buildMapFromDensity(const DensityField& target, const DensityMapOptions& options, DensityMapReport* report) {
    checkInput(target, options);
    switch (options.builder) {
        case DensityBuilder::Flow: return buildFlowMap(target, options, report);
        case DensityBuilder::Transport: return buildTransportMap(target, options, report);
        case DensityBuilder::Bounded: break;
    }
    return buildBoundedMap(target, options, report);
}

SamplingMap buildTransportMap(const DensityField& target, const DensityMapOptions& options, DensityMapReport* report) {
    constexpr int kIterations = 60;
    const int w = target.width, h = target.height;
    const std::size_t count = std::size_t(w) * h;
    FlowField field;
    field.width = w;
    field.height = h;
    field.rho.resize(count);
    double sum = 0.0;
    for (std::size_t k = 0; k < count; ++k) sum += field.rho[k] = target.values[k];
    for (double& r : field.rho) r *= double(count) / sum;
    // Benamou-Froese-Oberman: u = |x|^2 / 2 + psi, lap(u_next) = sqrt((u_xx - u_yy)^2 + 4 u_xy^2 + 4 rho)
    // (the convex root of det D^2 u = rho), psi with zero normal derivative (edges stay on edges).
    std::vector<double> psi(count, 0.0), rhs(count);
    const double h2 = double(h) * h;
    const auto at = [&](int i, int j) { return psi[std::size_t(std::clamp(j, 0, h - 1)) * w + std::clamp(i, 0, w - 1)]; };
    for (int it = 0; it < kIterations; ++it) {
        double mean = 0.0;
        for (int j = 0; j < h; ++j)
            for (int i = 0; i < w; ++i) {
                const double c = at(i, j);
                const double uxx = 1.0 + (at(i + 1, j) - 2.0 * c + at(i - 1, j)) * h2;
                const double uyy = 1.0 + (at(i, j + 1) - 2.0 * c + at(i, j - 1)) * h2;
                const double uxy = 0.25 * (at(i + 1, j + 1) - at(i + 1, j - 1) - at(i - 1, j + 1) + at(i - 1, j - 1)) * h2;
                const double r = std::sqrt((uxx - uyy) * (uxx - uyy) + 4.0 * uxy * uxy + 4.0 * field.rho[std::size_t(j) * w + i]);
                mean += rhs[std::size_t(j) * w + i] = r - 2.0;
            }
        mean /= double(count);
        for (double& r : rhs) r -= mean;
        psi = solvePoisson(w, h, rhs);
    }
    gradientCorners(field, psi);
    const int n = options.columns, m = options.rows;
    format::GridNodes grid;
    grid.columns = n;
    grid.rows = m;
    grid.xy.resize(std::size_t(2) * n * m);
    for (int j = 0; j < m; ++j)
        for (int i = 0; i < n; ++i) {
            const glm::dvec2 p(double(i) / (n - 1), double(j) / (m - 1));
            glm::dvec2 q = clampUnit(p + velocity(field, p, 1.0));
            if (i == 0) q.x = 0.0;
            if (i == n - 1) q.x = 1.0;
            if (j == 0) q.y = 0.0;
            if (j == m - 1) q.y = 1.0;
            grid.xy[2 * (std::size_t(j) * n + i)] = static_cast<float>(q.x);
            grid.xy[2 * (std::size_t(j) * n + i) + 1] = static_cast<float>(q.y);
        }
    // The gradient of a convex potential is monotone, so its grid folds only where the grid cannot
    // follow it; the identity is the answer then (the report shows it).
    const bool valid = map_rules::isValidGrid(grid.columns, grid.rows, grid.xy);
    SamplingMap map = valid ? SamplingMap::fromGrid(grid) : SamplingMap::identity(n, m);
    if (report) {
        *report = {};
        report->gamma = valid ? 1.0 : 0.0;
        compareWithTarget(map, target, buildAspect(target, options), *report);
    }
    return map;
}

SamplingMap buildFlowMap(const DensityField& target, const DensityMapOptions& options, DensityMapReport* report) {
    // Work with log(rho) relative to its maximum so that tempering rho^gamma cannot overflow.
    std::vector<double> logRho(target.values.size());
    double maxLog = -std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < logRho.size(); ++k) {
        logRho[k] = std::log(double(target.values[k]));
        maxLog = std::max(maxLog, logRho[k]);
    }
    FlowField field;
    field.width = target.width;
    field.height = target.height;
    field.rho.resize(logRho.size());
    const double aspect = buildAspect(target, options);
    bool anisotropyBound = false;
    auto attempt = [&](double gamma, format::GridNodes& grid) {
        double sum = 0.0;
        for (std::size_t k = 0; k < logRho.size(); ++k) sum += field.rho[k] = std::exp(gamma * (logRho[k] - maxLog));
        const double mean = sum / double(logRho.size());
        for (double& r : field.rho) r /= mean;
        solveFlowField(field);
        grid = integrateNodes(field, options);
        // Folded, or a cell much sparser than the sparsest density asked for: the grid could not
        // follow the flow here (see the top of this file); a weaker density is tried.
        if (!map_rules::isValidGrid(grid.columns, grid.rows, grid.xy)) return false;
        if (minCellDensityOf(grid) < kMinDensityShare * *std::min_element(field.rho.begin(), field.rho.end())) return false;
        if (options.maxAnisotropy > 0 && measureMap(SamplingMap::fromGrid(grid), aspect).maxAnisotropy > options.maxAnisotropy) {
            anisotropyBound = true;
            return false;
        }
        return true;
    };
    const auto finish = [&](format::GridNodes&& grid, double gamma) {
        SamplingMap map = SamplingMap::fromGrid(grid);
        if (report) {
            *report = {};
            report->gamma = gamma;
            report->anisotropyBound = anisotropyBound;
            report->bound = options.maxAnisotropy;
            compareWithTarget(map, target, aspect, *report);
        }
        return map;
    };
    format::GridNodes grid;
    if (attempt(1.0, grid)) return finish(std::move(grid), 1.0);
    double lo = 0.0, hi = 1.0;
    format::GridNodes best = SamplingMap::identity(options.columns, options.rows).toGrid();
    const int steps = anisotropyBound ? kAnisotropyTemperingSteps : kTemperingSteps;
    for (int step = 0; step < steps; ++step) {
        const double mid = 0.5 * (lo + hi);
        if (attempt(mid, grid)) {
            lo = mid;
            best = std::move(grid);
        } else {
            hi = mid;
        }
    }
    return finish(std::move(best), lo);
}

}  // namespace conus::codec
