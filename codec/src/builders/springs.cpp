// The mass-spring brush system: structure-of-arrays particles, springs by index arithmetic,
// symplectic Euler, and a guard that keeps every cell strictly convex after every step.
#include "conus/codec/builders/springs.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <utility>

#include <nlohmann/json.hpp>

#include "conus/codec/builders/compose.h"
#include "conus/core/map_rules.h"

namespace conus::codec {
namespace {

// Where node (i, j) of an outColumns x outRows grid over the unit square falls in a columns x rows
// grid over the same square, and the bilinear interpolation of that grid's values there: how the
// particle grid is resampled (coarse to fine in the warm start, particles to map nodes in toMap).
struct GridPoint {
    std::size_t k = 0;  // the enclosing cell's top-left value
    int stride = 0;     // values per row
    double tx = 0, ty = 0;

    double interpolate(const std::vector<float>& a) const {
        const std::size_t k2 = k + stride;
        return (1 - ty) * ((1 - tx) * double(a[k]) + tx * double(a[k + 1])) +
               ty * ((1 - tx) * double(a[k2]) + tx * double(a[k2 + 1]));
    }
};

GridPoint gridPoint(int columns, int rows, int outColumns, int outRows, int i, int j) {
    const double gx = double(i) * (columns - 1) / (outColumns - 1);
    const double gy = double(j) * (rows - 1) / (outRows - 1);
    const int ci = std::min(int(gx), columns - 2), cj = std::min(int(gy), rows - 2);
    return {std::size_t(cj) * columns + ci, columns, gx - ci, gy - cj};
}

// Brush falloff exp(-kFalloff s^2), shifted and rescaled to reach exactly 0 at the rim.
constexpr double kFalloff = 4.0;
// The guard keeps every corner cross product above this fraction of its rest value (hx * hy), so
// cells never get close to degenerate (well above float rounding and rule V11's 1e-12).
constexpr double kGuardMargin = 1e-3;
// Automatic damping: c / m = kDampingPerMode * w_max * pi / N, N the longer side: about critical
// damping for the longest-wavelength modes, which settle slowest (measured on 129^2 and 257^2 with
// one stroke, factors 1, 2, 4, 6: 1 reaches the stable state in the fewest steps).
constexpr double kDampingPerMode = 1.0;
// runUntilStable's warm start recurses while both sides are at least twice this.
constexpr int kCoarsestSide = 33;
// runUntilStable's time step, in units of 1 / w_max (step() uses 1).
constexpr double kRelaxStep = 1.9;
constexpr double kMaxStrength = 1000.0, kMaxRadius = 2.0, kMaxDuration = 3600.0, kDefaultDuration = 0.5;

[[noreturn]] void fail(const std::string& message) { throw Error(ErrorCode::InvalidArgument, message); }

// The guard's test of one row of cells (corners in rows y0/x0 and y1/x1, as displacements from
// the rest grid): worst[i] = the smallest of cell i's four corner cross products, so a cell passes
// when worst[i] > minCross. The arithmetic is SpringSystem::cellOk's, operation for operation (the
// decisions are the same to the bit), in a branch-free loop of doubles the compiler vectorizes:
// half of every step was this scan, one cellOk call per cell.
void cellRowWorst(const float* __restrict x0, const float* __restrict y0, const float* __restrict x1,
                  const float* __restrict y1, int cells, double hx, double hy, double* __restrict worst) {
    for (int i = 0; i < cells; ++i) {
        const double px0 = x0[i], px1 = hx + x0[i + 1], px2 = hx + x1[i + 1], px3 = x1[i];
        const double py0 = y0[i], py1 = y0[i + 1], py2 = hy + y1[i + 1], py3 = hy + y1[i];
        const double c0 = (px0 - px3) * (py1 - py0) - (py0 - py3) * (px1 - px0);
        const double c1 = (px1 - px0) * (py2 - py1) - (py1 - py0) * (px2 - px1);
        const double c2 = (px2 - px1) * (py3 - py2) - (py2 - py1) * (px3 - px2);
        const double c3 = (px3 - px2) * (py0 - py3) - (py3 - py2) * (px0 - px3);
        const double a = c1 < c0 ? c1 : c0, b = c3 < c2 ? c3 : c2;
        worst[i] = b < a ? b : a;
    }
}

double brushWeight(double s) {
    if (!(s < 1.0)) return 0.0;
    static const double rim = std::exp(-kFalloff);
    return (std::exp(-kFalloff * s * s) - rim) / (1.0 - rim);
}

void checkStrokeFields(const Stroke& s, const std::string& where) {
    // Negated comparisons so that NaN fails every check.
    if (!(s.u >= 0.0 && s.u <= 1.0)) fail(where + "u = " + numberText(s.u) + " is outside [0, 1]");
    if (!(s.v >= 0.0 && s.v <= 1.0)) fail(where + "v = " + numberText(s.v) + " is outside [0, 1]");
    if (!(s.radius > 0.0 && s.radius <= kMaxRadius)) fail(where + "radius = " + numberText(s.radius) + " is outside (0, 2]");
    if (!(s.strength >= 0.0 && s.strength <= kMaxStrength)) {
        fail(where + "strength = " + numberText(s.strength) + " is outside [0, 1000]");
    }
    if (!(s.duration >= 0.0 && s.duration <= kMaxDuration)) {
        fail(where + "duration = " + numberText(s.duration) + " is outside [0, 3600] seconds");
    }
}

}  // namespace

void checkStroke(const Stroke& stroke) { checkStrokeFields(stroke, "stroke: "); }

std::vector<Stroke> parseStrokes(const std::string& jsonText) {
    nlohmann::json doc;
    try {
        doc = nlohmann::json::parse(jsonText);
    } catch (const nlohmann::json::exception& e) {
        fail(std::string("strokes: bad JSON: ") + e.what());
    }
    if (!doc.is_array()) {
        fail(std::string("strokes: expected a JSON list [{\"u\":..,\"v\":..,\"radius\":..,\"strength\":..,\"duration\":..}, ...], got ") +
             doc.type_name());
    }
    std::vector<Stroke> strokes;
    for (std::size_t n = 0; n < doc.size(); ++n) {
        const nlohmann::json& item = doc[n];
        const std::string where = "stroke " + std::to_string(n) + ": ";
        if (!item.is_object()) fail(where + "expected an object, got " + item.type_name());
        Stroke s;
        s.duration = kDefaultDuration;
        for (const auto& [key, value] : item.items()) {
            double* field = key == "u"          ? &s.u
                            : key == "v"        ? &s.v
                            : key == "radius"   ? &s.radius
                            : key == "strength" ? &s.strength
                            : key == "duration" ? &s.duration
                                                : nullptr;
            if (!field) fail(where + "unknown key \"" + key + "\" (expected u, v, radius, strength, duration)");
            if (!value.is_number()) fail(where + "\"" + key + "\" must be a number, got " + value.type_name());
            *field = value.get<double>();
        }
        for (const char* required : {"u", "v", "radius", "strength"}) {
            if (!item.contains(required)) fail(where + "missing \"" + required + "\"");
        }
        checkStrokeFields(s, where);
        strokes.push_back(s);
    }
    return strokes;
}

SpringSystem::SpringSystem(int columns, int rows, const SpringOptions& options)
    : m_columns(columns), m_rows(rows), m_options(options) {
    if (columns < 2 || rows < 2 || columns > kMaxMapSide || rows > kMaxMapSide) {
        fail("spring system of " + std::to_string(columns) + "x" + std::to_string(rows) +
             " particles; each side must be in [2, " + std::to_string(kMaxMapSide) + "]");
    }
    const SpringOptions& o = options;
    if (!(o.stiffness > 0.0) || !std::isfinite(o.stiffness)) fail("spring stiffness " + numberText(o.stiffness) + " is not finite and > 0");
    if (!(o.mass > 0.0) || !std::isfinite(o.mass)) fail("particle mass " + numberText(o.mass) + " is not finite and > 0");
    if (!(o.restFraction >= 0.0 && o.restFraction < 1.0)) fail("rest fraction " + numberText(o.restFraction) + " is outside [0, 1)");
    if (!(o.timeStep >= 0.0) || !std::isfinite(o.timeStep)) fail("time step " + numberText(o.timeStep) + " is not finite and >= 0");
    if (!std::isfinite(o.damping)) fail("damping " + numberText(o.damping) + " is not finite");
    if (!(o.speedTolerance > 0.0) || !(o.forceTolerance > 0.0)) fail("stability tolerances must be > 0");

    const double omegaMax = std::sqrt(8.0 * o.stiffness / o.mass);
    // Symplectic Euler is stable for omega dt < 2; half of that leaves room for the brush forces.
    m_dt = o.timeStep > 0.0 ? o.timeStep : 1.0 / omegaMax;
    m_damping = o.damping >= 0.0 ? o.damping
                                 : o.mass * kDampingPerMode * omegaMax * 3.14159265358979 / std::max(columns, rows);

    // runUntilStable() only wants the equilibrium: symplectic Euler is stable up to
    // w_max dt = 2 (the brush pushes are constant along a spring and the transverse stiffness
    // T / len never exceeds k, so w_max stays sqrt(8 k / m)); kRelaxStep of it, with the same
    // critical damping of the slowest mode, settles the long waves kRelaxStep times faster.
    m_relaxDt = o.timeStep > 0.0 || !o.multilevel ? m_dt : kRelaxStep / omegaMax;
    m_relaxDamping = m_damping;

    m_hx = 1.0f / float(columns - 1);
    m_hy = 1.0f / float(rows - 1);
    m_minCross = std::max(kGuardMargin * double(m_hx) * double(m_hy), 1e-11);

    const std::size_t n = std::size_t(columns) * rows;
    m_x.assign(n, 0.0f);
    m_y.assign(n, 0.0f);
    m_nx = m_x;
    m_ny = m_y;
    m_vx.assign(n, 0.0f);
    m_vy.assign(n, 0.0f);
    m_fx.assign(n, 0.0f);
    m_fy.assign(n, 0.0f);
    const std::size_t horizontal = std::size_t(columns - 1) * rows, vertical = std::size_t(columns) * (rows - 1);
    m_sx.assign(horizontal + vertical, 0.0f);
    m_sy.assign(horizontal + vertical, 0.0f);
    m_repH.assign(horizontal, 0.0f);
    m_repV.assign(vertical, 0.0f);
    m_heldFlag.assign(n, 0);
    m_held.reserve(1024);
    m_work.reserve(1024);
    m_next.reserve(1024);
}

void SpringSystem::addStroke(const Stroke& stroke) {
    checkStroke(stroke);
    m_strokes.push_back({stroke, m_time});
    m_allStrokes.push_back(stroke);
    m_warmDone = false;
}

// finish: deposit what is left of every stroke at once (the equilibrium depends only on the
// total, not on how it was painted in).
void SpringSystem::depositStrokes(double dt, bool finish) {
    const double t0 = m_time, t1 = finish ? std::numeric_limits<double>::infinity() : m_time + dt;
    const int c = m_columns, r = m_rows;
    for (const ActiveStroke& a : m_strokes) {
        const Stroke& s = a.stroke;
        // The part of the stroke painted during [t0, t1], as a difference of painted fractions so
        // that the fractions sum to exactly 1 over the stroke's life.
        auto painted = [&](double t) { return s.duration > 0.0 ? std::clamp((t - a.start) / s.duration, 0.0, 1.0) : 1.0; };
        const double amount = s.strength * (painted(t1) - (s.duration > 0.0 ? painted(t0) : 0.0));
        if (amount == 0.0) continue;
        const double hx = m_hx, hy = m_hy;
        // Horizontal springs: midpoint ((i + 0.5) hx, j hy).
        const int i0 = std::max(0, int(std::floor((s.u - s.radius) / hx - 0.5)));
        const int i1 = std::min(c - 2, int(std::ceil((s.u + s.radius) / hx - 0.5)));
        const int j0 = std::max(0, int(std::floor((s.v - s.radius) / hy)));
        const int j1 = std::min(r - 1, int(std::ceil((s.v + s.radius) / hy)));
        for (int j = j0; j <= j1; ++j) {
            for (int i = i0; i <= i1; ++i) {
                const double d = std::hypot((i + 0.5) * hx - s.u, j * hy - s.v) / s.radius;
                if (d < 1.0) m_repH[std::size_t(j) * (c - 1) + i] += float(amount * brushWeight(d));
            }
        }
        // Vertical springs: midpoint (i hx, (j + 0.5) hy).
        const int k0 = std::max(0, int(std::floor((s.u - s.radius) / hx)));
        const int k1 = std::min(c - 1, int(std::ceil((s.u + s.radius) / hx)));
        const int l0 = std::max(0, int(std::floor((s.v - s.radius) / hy - 0.5)));
        const int l1 = std::min(r - 2, int(std::ceil((s.v + s.radius) / hy - 0.5)));
        for (int j = l0; j <= l1; ++j) {
            for (int i = k0; i <= k1; ++i) {
                const double d = std::hypot(i * hx - s.u, (j + 0.5) * hy - s.v) / s.radius;
                if (d < 1.0) m_repV[std::size_t(j) * c + i] += float(amount * brushWeight(d));
            }
        }
    }
    std::erase_if(m_strokes, [&](const ActiveStroke& a) { return a.start + a.stroke.duration <= t1; });
}

// Spring forces first (one value per spring, independent, so the loops vectorize), then each
// particle sums its up to four springs: no scattered writes.
void SpringSystem::computeForces() {
    const int c = m_columns, r = m_rows;
    const float k = float(m_options.stiffness);
    const float restX = float(m_options.restFraction) * m_hx, restY = float(m_options.restFraction) * m_hy;
    const float pushX = k * m_hx, pushY = k * m_hy;
    const float hx = m_hx, hy = m_hy;
    const float* __restrict x = m_x.data();
    const float* __restrict y = m_y.data();
    float* __restrict sx = m_sx.data();
    float* __restrict sy = m_sy.data();
    const std::size_t horizontal = std::size_t(c - 1) * r;
    {
        const float* __restrict rep = m_repH.data();
        for (int j = 0; j < r; ++j) {
            const float* xr = x + std::size_t(j) * c;
            const float* yr = y + std::size_t(j) * c;
            float* sxr = sx + std::size_t(j) * (c - 1);
            float* syr = sy + std::size_t(j) * (c - 1);
            const float* repr = rep + std::size_t(j) * (c - 1);
            for (int i = 0; i < c - 1; ++i) {
                const float dx = hx + (xr[i + 1] - xr[i]), dy = yr[i + 1] - yr[i];
                const float len = std::sqrt(dx * dx + dy * dy);  // > 0: the guard keeps cells convex
                const float tension = k * (len - restX) - pushX * repr[i];
                const float f = tension / len;
                sxr[i] = f * dx;
                syr[i] = f * dy;
            }
        }
    }
    {
        const float* __restrict rep = m_repV.data();
        float* __restrict vx = sx + horizontal;
        float* __restrict vy = sy + horizontal;
        const std::size_t n = std::size_t(c) * (r - 1);
        for (std::size_t s = 0; s < n; ++s) {
            const float dx = x[s + c] - x[s], dy = hy + (y[s + c] - y[s]);
            const float len = std::sqrt(dx * dx + dy * dy);
            const float tension = k * (len - restY) - pushY * rep[s];
            const float f = tension / len;
            vx[s] = f * dx;
            vy[s] = f * dy;
        }
    }
    float* __restrict fx = m_fx.data();
    float* __restrict fy = m_fy.data();
    const float* hsx = sx;
    const float* hsy = sy;
    const float* vsx = sx + horizontal;
    const float* vsy = sy + horizontal;
    for (int j = 0; j < r; ++j) {
        const std::size_t row = std::size_t(j) * c, hrow = std::size_t(j) * (c - 1);
        float* fxr = fx + row;
        float* fyr = fy + row;
        // Horizontal: +right spring, -left spring.
        fxr[0] = hsx[hrow];
        fyr[0] = hsy[hrow];
        for (int i = 1; i < c - 1; ++i) {
            fxr[i] = hsx[hrow + i] - hsx[hrow + i - 1];
            fyr[i] = hsy[hrow + i] - hsy[hrow + i - 1];
        }
        fxr[c - 1] = -hsx[hrow + c - 2];
        fyr[c - 1] = -hsy[hrow + c - 2];
        // Vertical: +spring below, -spring above.
        if (j + 1 < r) {
            const float* bx = vsx + row;
            const float* by = vsy + row;
            for (int i = 0; i < c; ++i) {
                fxr[i] += bx[i];
                fyr[i] += by[i];
            }
        }
        if (j > 0) {
            const float* ax = vsx + row - c;
            const float* ay = vsy + row - c;
            for (int i = 0; i < c; ++i) {
                fxr[i] -= ax[i];
                fyr[i] -= ay[i];
            }
        }
    }
}

void SpringSystem::integrate(double timeStep, double damping) {
    const int c = m_columns, r = m_rows;
    const std::size_t n = std::size_t(c) * r;
    const float dt = float(timeStep), a = float(timeStep / m_options.mass);
    // Damping taken implicitly: unconditionally stable whatever c is.
    const float keep = float(1.0 / (1.0 + damping * timeStep / m_options.mass));
    float* __restrict vx = m_vx.data();
    float* __restrict vy = m_vy.data();
    float* __restrict fx = m_fx.data();
    float* __restrict fy = m_fy.data();
    // Boundary particles slide along their edge: the constraint cancels the normal force.
    for (int j = 0; j < r; ++j) {
        fx[std::size_t(j) * c] = 0.0f;
        fx[std::size_t(j) * c + c - 1] = 0.0f;
    }
    for (int i = 0; i < c; ++i) {
        fy[i] = 0.0f;
        fy[std::size_t(r - 1) * c + i] = 0.0f;
    }
    fx[0] = fy[0] = fx[c - 1] = fy[c - 1] = 0.0f;
    fx[n - 1] = fy[n - 1] = fx[n - c] = fy[n - c] = 0.0f;
    const float* __restrict x = m_x.data();
    const float* __restrict y = m_y.data();
    float* __restrict nx = m_nx.data();
    float* __restrict ny = m_ny.data();
    for (std::size_t k = 0; k < n; ++k) {
        vx[k] = (vx[k] + a * fx[k]) * keep;
        vy[k] = (vy[k] + a * fy[k]) * keep;
        nx[k] = x[k] + dt * vx[k];
        ny[k] = y[k] + dt * vy[k];
    }
    // The normal force was zero, so the normal velocity and displacement are too: the coordinate
    // stays exact. Keep the tangential one on the edge (the guard would stop a particle passing a
    // corner anyway).
    for (int j = 0; j < r; ++j) {
        const float rest = float(double(j) / (r - 1));
        for (std::size_t k : {std::size_t(j) * c, std::size_t(j) * c + c - 1}) ny[k] = std::clamp(ny[k], -rest, 1.0f - rest);
    }
    for (int i = 0; i < c; ++i) {
        const float rest = float(double(i) / (c - 1));
        for (std::size_t k : {std::size_t(i), std::size_t(r - 1) * c + i}) nx[k] = std::clamp(nx[k], -rest, 1.0f - rest);
    }
}

bool SpringSystem::cellOk(int i, int j) const {
    const std::size_t k0 = std::size_t(j) * m_columns + i, k3 = k0 + m_columns;
    // Corners relative to the cell's rest corner: cross products do not depend on where it is.
    const double hx = m_hx, hy = m_hy;
    const double px[4] = {m_nx[k0], hx + m_nx[k0 + 1], hx + m_nx[k3 + 1], m_nx[k3]};
    const double py[4] = {m_ny[k0], m_ny[k0 + 1], hy + m_ny[k3 + 1], hy + m_ny[k3]};
    bool ok = true;
    for (int q = 0; q < 4; ++q) {
        const int prev = (q + 3) & 3, next = (q + 1) & 3;
        const double ax = px[q] - px[prev], ay = py[q] - py[prev];
        const double bx = px[next] - px[q], by = py[next] - py[q];
        ok &= ax * by - ay * bx > m_minCross;
    }
    return ok;
}

void SpringSystem::holdBack(int k) {
    m_heldFlag[k] = 1;
    m_held.push_back(k);
    m_nx[k] = m_x[k];
    m_ny[k] = m_y[k];
    m_vx[k] = m_vy[k] = 0.0f;
    m_fx[k] = m_fy[k] = 0.0f;
}

// Every cell after the step must pass; a cell that does not gets its four particles put back,
// and the cells around them are checked again. Cells whose four particles are all back passed
// in the previous state, so this ends, and ends valid.
void SpringSystem::guard() {
    const int c = m_columns, r = m_rows;
    m_work.clear();
    std::vector<double> worst(std::size_t(c - 1));
    for (int j = 0; j + 1 < r; ++j) {
        const std::size_t row = std::size_t(j) * c;
        cellRowWorst(&m_nx[row], &m_ny[row], &m_nx[row + c], &m_ny[row + c], c - 1, m_hx, m_hy, worst.data());
        for (int i = 0; i + 1 < c; ++i)
            if (!(worst[i] > m_minCross)) m_work.push_back(j * (c - 1) + i);
    }
    while (!m_work.empty()) {
        m_next.clear();
        for (int cell : m_work) {
            const int i = cell % (c - 1), j = cell / (c - 1);
            if (cellOk(i, j)) continue;  // fixed by an earlier hold in this pass
            for (int q = 0; q < 4; ++q) {
                const int pi = i + (q & 1), pj = j + (q >> 1);
                const int k = pj * c + pi;
                if (m_heldFlag[k]) continue;
                holdBack(k);
                for (int cj = std::max(0, pj - 1); cj <= std::min(r - 2, pj); ++cj)
                    for (int ci = std::max(0, pi - 1); ci <= std::min(c - 2, pi); ++ci) m_next.push_back(cj * (c - 1) + ci);
            }
        }
        std::swap(m_work, m_next);
    }
}

// One step of length dt with damping c; step() uses the automatic (or given) ones.
void SpringSystem::advance(double dt, double damping) {
    m_stepped = true;
    for (int k : m_held) m_heldFlag[k] = 0;
    m_held.clear();
    depositStrokes(dt);
    computeForces();
    integrate(dt, damping);
    guard();
    std::swap(m_x, m_nx);
    std::swap(m_y, m_ny);
    m_time += dt;
    ++m_steps;
}

void SpringSystem::step(int n) {
    for (int s = 0; s < n; ++s) advance(m_dt, m_damping);
}

bool SpringSystem::stable() const {
    if (!m_strokes.empty() || !m_stepped) return false;
    const double h = std::min(m_hx, m_hy);
    const double vLimit = m_options.speedTolerance * h / m_dt, fLimit = m_options.forceTolerance * m_options.stiffness * h;
    const float v2 = float(vLimit * vLimit), f2 = float(fLimit * fLimit);
    const std::size_t n = m_x.size();
    for (std::size_t k = 0; k < n; ++k) {
        if (m_vx[k] * m_vx[k] + m_vy[k] * m_vy[k] >= v2) return false;
        if (m_fx[k] * m_fx[k] + m_fy[k] * m_fy[k] >= f2) return false;
    }
    return true;
}

// Coarse-to-fine warm start. The equilibrium equations are scale-free (spring rest lengths and
// brush pushes are in units of the spacing), so a half-resolution system with the same strokes
// has nearly the same equilibrium map. Its slow long-wavelength modes take about 4x fewer steps to
// settle at 1/4 of the cost per step, recursively; prolonged bilinearly to this grid, what is left
// is the small difference between the two discretizations plus some high-frequency interpolation
// error, which the dynamic steps remove quickly.
void SpringSystem::warmStart(int maxSteps) {
    m_warmDone = true;
    const int c = m_columns, r = m_rows;
    if (!m_options.multilevel || std::min(c, r) < 2 * kCoarsestSide) return;
    // The coarse system is solved to its own equilibrium with every stroke fully painted in, so
    // finish painting here too.
    if (!m_strokes.empty()) depositStrokes(0.0, true);
    SpringOptions coarseOptions = m_options;
    coarseOptions.timeStep = 0.0;  // each level its own automatic step (same as this one's
    coarseOptions.damping = -1.0;  // when these are automatic) and damping
    if (m_options.timeStep > 0.0 || m_options.damping >= 0.0) coarseOptions = m_options;
    const int cc = (c + 1) / 2, cr = (r + 1) / 2;
    SpringSystem coarse(cc, cr, coarseOptions);
    for (Stroke s : m_allStrokes) {
        s.duration = 0.0;
        coarse.addStroke(s);
    }
    coarse.runUntilStable(maxSteps);
    const double ratio = double(cc) * cr / (double(c) * r);
    m_warmWork += ratio * (double(coarse.steps()) + coarse.warmStartWork());
    // Prolong: bilinear in displacement at each particle's rest position.
    for (int j = 0; j < r; ++j) {
        for (int i = 0; i < c; ++i) {
            const GridPoint g = gridPoint(cc, cr, c, r, i, j);
            const std::size_t q = std::size_t(j) * c + i;
            m_nx[q] = float(g.interpolate(coarse.m_x));
            m_ny[q] = float(g.interpolate(coarse.m_y));
        }
    }
    // Edge particles keep their normal coordinate exact (the coarse edges have zero normal
    // displacement, so interpolation already gives 0 up to rounding).
    for (int j = 0; j < r; ++j) m_nx[std::size_t(j) * c] = m_nx[std::size_t(j) * c + c - 1] = 0.0f;
    for (int i = 0; i < c; ++i) m_ny[i] = m_ny[std::size_t(r - 1) * c + i] = 0.0f;
    // The prolonged map must pass the guard like any state: a cell straddling coarse cells could
    // in principle fail the margin where the map bends sharply. Then move only part of the way
    // from the current (valid) state, halving until every cell passes.
    const std::vector<float> targetX = m_nx, targetY = m_ny;
    auto allOk = [&] {
        for (int j = 0; j + 1 < r; ++j)
            for (int i = 0; i + 1 < c; ++i)
                if (!cellOk(i, j)) return false;
        return true;
    };
    float alpha = 1.0f;
    for (int attempt = 0; attempt < 12 && !allOk(); ++attempt) {
        alpha *= 0.5f;
        for (std::size_t q = 0; q < m_nx.size(); ++q) {
            m_nx[q] = m_x[q] + alpha * (targetX[q] - m_x[q]);
            m_ny[q] = m_y[q] + alpha * (targetY[q] - m_y[q]);
        }
    }
    if (!allOk()) return;  // keep the current state; plain stepping from here
    std::swap(m_x, m_nx);
    std::swap(m_y, m_ny);
    std::fill(m_vx.begin(), m_vx.end(), 0.0f);
    std::fill(m_vy.begin(), m_vy.end(), 0.0f);
    for (int k : m_held) m_heldFlag[k] = 0;
    m_held.clear();
    m_stepped = false;
}

int SpringSystem::runUntilStable(int maxSteps, const ProgressFn& progress) {
    int taken = 0;
    if (!m_warmDone && maxSteps > 0) warmStart(maxSteps);
    while (taken < maxSteps && !stable()) {
        advance(m_relaxDt, m_relaxDamping);
        ++taken;
        if (progress && (taken & 63) == 0) progress(double(taken) / maxSteps);
    }
    if (progress) progress(1.0);
    return taken;
}

std::vector<glm::vec2> SpringSystem::positions() const {
    std::vector<glm::vec2> p(m_x.size());
    for (int j = 0; j < m_rows; ++j) {
        const double v = double(j) / (m_rows - 1);
        for (int i = 0; i < m_columns; ++i) {
            const std::size_t k = std::size_t(j) * m_columns + i;
            // Boundary displacements are 0 across the edge, so edge coordinates come out exact.
            p[k] = glm::vec2(float(double(i) / (m_columns - 1) + m_x[k]), float(v + m_y[k]));
        }
    }
    return p;
}

SamplingMap SpringSystem::toMap(int columns, int rows, double* scale) const {
    if (scale) *scale = 1.0;
    if (columns == m_columns && rows == m_rows) {
        std::vector<glm::vec2> nodes = positions();
        if (map_rules::isValidGrid(columns, rows, nodes)) return SamplingMap(columns, rows, std::move(nodes));
    }
    if (columns < 2 || rows < 2 || columns > kMaxMapSide || rows > kMaxMapSide) {
        fail("spring map of " + std::to_string(columns) + "x" + std::to_string(rows) + " nodes; each side must be in [2, " +
             std::to_string(kMaxMapSide) + "]");
    }
    // Eq. 1 on the particle grid at each node's undistorted position, as a displacement.
    std::vector<glm::dvec2> d(std::size_t(columns) * rows);
    for (int J = 0; J < rows; ++J) {
        for (int I = 0; I < columns; ++I) {
            const GridPoint g = gridPoint(m_columns, m_rows, columns, rows, I, J);
            // Bilinear in displacement = bilinear in position: the rest grid is itself bilinear.
            d[std::size_t(J) * columns + I] = glm::dvec2(g.interpolate(m_x), g.interpolate(m_y));
        }
    }
    ComposeResult fitted = fitDisplacement(columns, rows, d);
    if (scale) *scale = fitted.scale;
    return std::move(fitted.map);
}

}  // namespace conus::codec
