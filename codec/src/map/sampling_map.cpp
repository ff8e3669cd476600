// SamplingMap: Equation 1 (bilinear interpolation of the nodes) and its exact inverse through a
// bucket grid over the distorted plane. Everything is computed in double from the float nodes.
#include "conus/codec/map/sampling_map.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <mutex>
#include <string>

#include "conus/core/error.h"
#include "conus/core/map_rules.h"

namespace conus::codec {
namespace {

// Buckets per cell along each axis for ordinary maps: 2 keeps the candidate list short (about 2-4
// cells) for the usual 65x65 maps. The index then takes about 13 words a cell; maps whose cells
// overlap many buckets get coarser buckets so the index stays within its budget (limits.h).
constexpr int kBucketsPerCell = 2;
static_assert(kMaxMapSide < (1 << 16), "cells are packed as i | j << 16");
// Inside-cell test tolerance on the edge cross products (length^2 units): a point on a shared
// edge must be accepted by at least one of the two cells despite rounding.
constexpr double kInsideTolerance = 1e-14;

// Residual |distort(s,t) - q| (L1, coordinates in [0,1]) below which Newton cannot improve.
constexpr double kResidualAtRounding = 4e-16;
// Residual above which a root of the closed form is not a solution (a true root leaves ~1e-16).
constexpr double kRootResidual = 1e-9;

// Clamps to [0,1]; NaN goes to 0 so that no index is ever computed from it.
inline double clamp01(double x) { return x > 0.0 ? (x < 1.0 ? x : 1.0) : 0.0; }

inline double cross(glm::dvec2 a, glm::dvec2 b) { return a.x * b.y - a.y * b.x; }

// Cell and local coordinate of a clamped coordinate x in [0,1] on an axis of `cells` cells.
inline int cellOf(double x, int cells, double& local) {
    const double f = x * cells;
    const int i = std::min(static_cast<int>(f), cells - 1);
    local = f - i;
    return i;
}

// The one evaluation of a bilinear patch, shared by distort and by the Newton polish of undistort
// so that undistort(distort(p)) reproduces p to rounding.
inline glm::dvec2 bilinear(glm::dvec2 p00, glm::dvec2 p10, glm::dvec2 p01, glm::dvec2 p11, double s, double t) {
    const glm::dvec2 a = p00 + (p10 - p00) * s;
    const glm::dvec2 b = p01 + (p11 - p01) * s;
    return a + (b - a) * t;
}

// Solves bilinear(s,t) = q for a strictly convex cell: closed form (the quadratic in t, in its
// numerically stable form, which degrades gracefully to the linear case for parallelograms), then
// up to two Newton steps while the residual is above rounding. Returns (s,t) unclamped.
glm::dvec2 invertCell(glm::dvec2 p00, glm::dvec2 p10, glm::dvec2 p01, glm::dvec2 p11, glm::dvec2 q) {
    const glm::dvec2 b = p10 - p00;
    const glm::dvec2 c = p01 - p00;
    const glm::dvec2 d = (p11 - p01) - b;
    const glm::dvec2 e = q - p00;
    // e - c t and b + d t are parallel at the solution: cross(c,d) t^2 + (cross(c,b) - cross(e,d)) t - cross(e,b) = 0.
    const double qa = cross(c, d);
    const double qb = cross(c, b) - cross(e, d);
    const double qc = -cross(e, b);
    const double disc = std::max(0.0, qb * qb - 4.0 * qa * qc);
    const double h = -0.5 * (qb + std::copysign(std::sqrt(disc), qb));
    // Of the (up to) two roots take the one whose (s,t) is nearest [0,1]^2 (both t may be in range,
    // with s outside for one of them). qc/h is the stable root when qa ~ 0 and the usual answer, so
    // the other is computed only when the first is out of range.
    auto sOf = [&](double tt) {
        const glm::dvec2 dir = b + d * tt;
        const double dd = glm::dot(dir, dir);
        return dd > 0.0 ? glm::dot(e - c * tt, dir) / dd : 0.5;
    };
    auto outside = [](double ss, double tt) {
        const double o = std::max(std::max(-ss, ss - 1.0), std::max(-tt, tt - 1.0));
        return o == o ? o : std::numeric_limits<double>::infinity();  // NaN: worst
    };
    constexpr double kInRange = 1e-2;
    // Fast path: s from its own quadratic, cross(b,d) s^2 + (cross(b,c) - cross(e,d)) s - cross(e,c) = 0,
    // independent of t so both square roots and divisions overlap. Kept only if the pair is the
    // solution (a wrong pairing of roots leaves a large residual).
    double t = h != 0.0 ? qc / h : std::numeric_limits<double>::quiet_NaN();
    {
        const double sa = cross(b, d);
        const double sb = cross(b, c) - cross(e, d);
        const double sc = -cross(e, c);
        const double sdisc = std::max(0.0, sb * sb - 4.0 * sa * sc);
        const double sh = -0.5 * (sb + std::copysign(std::sqrt(sdisc), sb));
        const double s = sh != 0.0 ? sc / sh : std::numeric_limits<double>::quiet_NaN();
        if (outside(s, t) <= kInRange) {
            const glm::dvec2 f = bilinear(p00, p10, p01, p11, s, t) - q;
            if (std::abs(f.x) + std::abs(f.y) <= kResidualAtRounding) return {s, t};
        }
    }
    auto residual = [&](double ss, double tt) {
        const glm::dvec2 f = bilinear(p00, p10, p01, p11, ss, tt) - q;
        const double r = std::abs(f.x) + std::abs(f.y);
        return r == r ? r : std::numeric_limits<double>::infinity();  // NaN: worst
    };
    double s = sOf(t);
    const bool in1 = outside(s, t) <= kInRange;
    const double r1 = residual(s, t);
    // The usual case: this root solves the equations to rounding, where Newton would stop at once.
    if (in1 && r1 <= kResidualAtRounding) return {s, t};
    // The other root too when this one is out of range or does not solve the equations: a t on the
    // line where the patch's extension folds (b + d t = 0, as in a cell tapering to a point)
    // leaves s undetermined. In range first, then the smaller residual.
    if (!in1 || !(r1 <= kRootResidual)) {
        const double t2 = qa != 0.0 ? h / qa : std::numeric_limits<double>::quiet_NaN();
        const double s2 = sOf(t2);
        const bool in2 = outside(s2, t2) <= kInRange;
        if (in2 != in1 ? in2 : in1 ? residual(s2, t2) < r1 : outside(s2, t2) < outside(s, t)) s = s2, t = t2;
        if (!std::isfinite(s) || !std::isfinite(t)) s = t = 0.5;  // Newton from the middle
    }
    // Newton on the same evaluation as distort, skipped once the residual is at rounding level
    // (the usual case after the closed form: it saves a division on the hot path).
    for (int it = 0; it < 2; ++it) {
        const glm::dvec2 f = bilinear(p00, p10, p01, p11, s, t) - q;
        if (std::abs(f.x) + std::abs(f.y) <= kResidualAtRounding) break;
        const glm::dvec2 ju = b + d * t;  // d/ds
        const glm::dvec2 jv = c + d * s;  // d/dt
        const double det = cross(ju, jv);
        if (!(std::abs(det) > 0.0)) break;
        const double inv = 1.0 / det;
        const double ds = cross(f, jv) * inv, dt = cross(ju, f) * inv;
        s -= ds;
        t -= dt;
        if (std::abs(ds) + std::abs(dt) < 1e-13) break;
    }
    return {s, t};
}

format::GridNodes makeGrid(int columns, int rows, const std::vector<glm::vec2>& nodes) {
    format::GridNodes grid;
    grid.columns = columns;
    grid.rows = rows;
    grid.xy.reserve(nodes.size() * 2);
    for (const glm::vec2& p : nodes) {
        grid.xy.push_back(p.x);
        grid.xy.push_back(p.y);
    }
    return grid;
}

}  // namespace

// The acceleration structure: per bucket of the distorted plane, the cells whose bounding box
// overlaps it (compressed rows: cells[start[b] .. start[b+1])). Its size is the sum over cells of
// the buckets their boxes cover, which a hostile map (long thin cells) makes cubic in the side at
// a fixed bucket size; so the bucket grid is the finest of 2, 1, 1/2, 1/4, ... buckets per cell
// whose size, counted in 64-bit before anything is allocated, fits the budget. A single bucket
// always fits (4 bytes a cell), so every valid map gets an index; lookups in a coarse one scan
// longer lists but stay exact.
struct SamplingMap::Index {
    int bucketsX = 0, bucketsY = 0;
    std::vector<std::uint32_t> start;
    std::vector<std::uint32_t> cells;  // the cell's (i, j) packed as i | j << 16

    static std::int64_t budget(std::int64_t cellCount) {
        return std::min(kMaxIndexBytes, kIndexBytesPerCell * cellCount + kIndexBytesBase);
    }

    Index(int columns, int rows, const std::vector<glm::dvec2>& nodes) {
        const int cellsX = columns - 1, cellsY = rows - 1;
        const std::int64_t cellCount = std::int64_t{cellsX} * cellsY;
        // Buckets covered by cell (i, j)'s bounding box on a bx x by grid. Multiplication and
        // truncation are monotone, so a point inside the box always falls in one of these buckets
        // (lookups use the same expression).
        auto bucketRange = [&](int i, int j, int bx, int by, int& x0, int& x1, int& y0, int& y1) {
            const std::size_t k = std::size_t(j) * columns + i;
            const glm::dvec2 p[4] = {nodes[k], nodes[k + 1], nodes[k + columns], nodes[k + columns + 1]};
            double loX = p[0].x, hiX = p[0].x, loY = p[0].y, hiY = p[0].y;
            for (int c = 1; c < 4; ++c) {
                loX = std::min(loX, p[c].x), hiX = std::max(hiX, p[c].x);
                loY = std::min(loY, p[c].y), hiY = std::max(hiY, p[c].y);
            }
            auto bucket = [](double x, int n) { return std::clamp(static_cast<int>(clamp01(x) * n), 0, n - 1); };
            x0 = bucket(loX, bx), x1 = bucket(hiX, bx);
            y0 = bucket(loY, by), y1 = bucket(hiY, by);
        };
        const std::int64_t budgetBytes = budget(cellCount);
        int bx = cellsX * kBucketsPerCell, by = cellsY * kBucketsPerCell;
        for (;; bx = std::max(1, (bx + 1) / 2), by = std::max(1, (by + 1) / 2)) {
            const std::int64_t startBytes = 4 * (std::int64_t{bx} * by + 1);
            const std::int64_t maxEntries = (budgetBytes - startBytes) / 4;
            std::int64_t entries = 0;
            for (int j = 0; j < cellsY && entries <= maxEntries; ++j) {
                for (int i = 0; i < cellsX; ++i) {
                    int x0, x1, y0, y1;
                    bucketRange(i, j, bx, by, x0, x1, y0, y1);
                    entries += std::int64_t{x1 - x0 + 1} * (y1 - y0 + 1);
                }
            }
            if (startBytes <= budgetBytes && entries <= maxEntries) break;
            if (bx == 1 && by == 1) break;  // cannot happen (cellCount * 4 + 8 bytes fit), but never loop forever
        }
        bucketsX = bx;
        bucketsY = by;
        start.assign(std::size_t(bucketsX) * bucketsY + 1, 0);
        for (int j = 0; j < cellsY; ++j) {
            for (int i = 0; i < cellsX; ++i) {
                int x0, x1, y0, y1;
                bucketRange(i, j, bx, by, x0, x1, y0, y1);
                for (int y = y0; y <= y1; ++y)
                    for (int x = x0; x <= x1; ++x) ++start[std::size_t(y) * bucketsX + x + 1];
            }
        }
        for (std::size_t b = 1; b < start.size(); ++b) start[b] += start[b - 1];
        cells.resize(start.back());
        std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
        for (int j = 0; j < cellsY; ++j) {
            for (int i = 0; i < cellsX; ++i) {
                int x0, x1, y0, y1;
                bucketRange(i, j, bx, by, x0, x1, y0, y1);
                const auto k = static_cast<std::uint32_t>(i) | static_cast<std::uint32_t>(j) << 16;
                for (int y = y0; y <= y1; ++y)
                    for (int x = x0; x <= x1; ++x) cells[fill[std::size_t(y) * bucketsX + x]++] = k;
            }
        }
    }

    std::size_t bytes() const { return (start.capacity() + cells.capacity()) * sizeof(std::uint32_t); }
};

// Built on the first undistort (decoding only distorts), once, whichever thread asks first: the
// encoder calls undistort from several threads. Copies of a map share the built index (it is
// immutable), so `owner` is written once before `ready` is published and never again.
struct SamplingMap::LazyIndex {
    std::mutex mutex;
    std::shared_ptr<const Index> owner;
    std::atomic<const Index*> ready{nullptr};
};

// Inline (undistort, in this file, is its only caller): after the first call it is one atomic load,
// which an out-of-line call made a tenth of undistort's instructions. The build stays out of line.
inline const SamplingMap::Index& SamplingMap::index() const {
    if (const Index* built = m_lazy->ready.load(std::memory_order_acquire)) [[likely]] return *built;
    return [this]() __attribute__((noinline)) -> const Index& {
        const std::lock_guard<std::mutex> lock(m_lazy->mutex);
        if (!m_lazy->owner) {
            m_lazy->owner = std::make_shared<const Index>(m_columns, m_rows, m_dnodes);
            m_lazy->ready.store(m_lazy->owner.get(), std::memory_order_release);
        }
        return *m_lazy->owner;
    }();
}

std::size_t SamplingMap::indexBytes() const { return index().bytes(); }

SamplingMap::SamplingMap(int columns, int rows, std::vector<glm::vec2> nodes) {
    if (!map_rules::isValidGrid(columns, rows, nodes)) {
        const format::ValidationReport report = format::validateGrid(makeGrid(columns, rows, nodes));
        throw Error(ErrorCode::InvalidMap, report.str(), report.ruleNumbers());
    }
    m_columns = columns;
    m_rows = rows;
    m_nodes = std::move(nodes);
    m_dnodes.assign(m_nodes.begin(), m_nodes.end());
    m_invCellsX = 1.0 / (m_columns - 1);
    m_invCellsY = 1.0 / (m_rows - 1);
    m_lazy = std::make_unique<LazyIndex>();
}

SamplingMap SamplingMap::identity(int columns, int rows) {
    if (columns < 2 || rows < 2) {
        throw Error(ErrorCode::InvalidArgument,
                    "identity map of " + std::to_string(columns) + "x" + std::to_string(rows) + " nodes; need at least 2x2");
    }
    if (columns > kMaxMapSide || rows > kMaxMapSide)
        throw Error(ErrorCode::LimitExceeded, "identity map of " + std::to_string(columns) + "x" + std::to_string(rows) +
                                                  " nodes; at most " + std::to_string(kMaxMapSide) + " a side");
    std::vector<glm::vec2> nodes(std::size_t(columns) * rows);
    for (int j = 0; j < rows; ++j)
        for (int i = 0; i < columns; ++i)
            nodes[std::size_t(j) * columns + i] = {static_cast<float>(double(i) / (columns - 1)),
                                                   static_cast<float>(double(j) / (rows - 1))};
    return SamplingMap(columns, rows, std::move(nodes));
}

SamplingMap SamplingMap::fromGrid(const format::GridNodes& grid) {
    // The constructor validates (a wrong value count is V7 there).
    std::vector<glm::vec2> nodes(grid.xy.size() / 2);
    for (std::size_t k = 0; k < nodes.size(); ++k) nodes[k] = {grid.xy[2 * k], grid.xy[2 * k + 1]};
    return SamplingMap(grid.columns, grid.rows, std::move(nodes));
}

format::GridNodes SamplingMap::toGrid() const { return makeGrid(m_columns, m_rows, m_nodes); }

glm::dvec2 SamplingMap::distort(glm::dvec2 p) const {
    double s, t;
    const int i = cellOf(clamp01(p.x), m_columns - 1, s);
    const int j = cellOf(clamp01(p.y), m_rows - 1, t);
    const glm::dvec2* n = m_dnodes.data() + std::size_t(j) * m_columns + i;
    const glm::dvec2 r = bilinear(n[0], n[1], n[m_columns], n[m_columns + 1], s, t);
    return {clamp01(r.x), clamp01(r.y)};
}

glm::dvec2 SamplingMap::undistort(glm::dvec2 pd) const {
    const Index& index = this->index();
    const glm::dvec2 q{clamp01(pd.x), clamp01(pd.y)};
    const int bx = std::min(static_cast<int>(q.x * index.bucketsX), index.bucketsX - 1);
    const int by = std::min(static_cast<int>(q.y * index.bucketsY), index.bucketsY - 1);
    const std::size_t bucket = std::size_t(by) * index.bucketsX + bx;
    const glm::dvec2* nodes = m_dnodes.data();
    const int stride = m_columns;

    auto first = [&](std::uint32_t cell) { return nodes + std::size_t(cell >> 16) * stride + (cell & 0xffffu); };
    auto solve = [&](std::uint32_t cell) {
        const glm::dvec2* n = first(cell);
        const glm::dvec2 st = invertCell(n[0], n[1], n[stride], n[stride + 1], q);
        const int i = static_cast<int>(cell & 0xffffu), j = static_cast<int>(cell >> 16);
        return glm::dvec2{(i + std::clamp(st.x, 0.0, 1.0)) * m_invCellsX, (j + std::clamp(st.y, 0.0, 1.0)) * m_invCellsY};
    };

    // Cells are convex and a convex cell's bilinear patch covers exactly the quad, so a point is
    // in a cell iff it is on the inner side of its four edges (p00 -> p10 -> p11 -> p01).
    for (std::uint32_t c = index.start[bucket], end = index.start[bucket + 1]; c < end; ++c) {
        const std::uint32_t k = index.cells[c];
        const glm::dvec2* n = first(k);
        const glm::dvec2 p00 = n[0], p10 = n[1], p01 = n[stride], p11 = n[stride + 1];
        if (cross(p10 - p00, q - p00) >= -kInsideTolerance && cross(p11 - p10, q - p10) >= -kInsideTolerance &&
            cross(p01 - p11, q - p11) >= -kInsideTolerance && cross(p00 - p01, q - p01) >= -kInsideTolerance) {
            return solve(k);
        }
    }

    // Rounding left q just outside every candidate (or the bucket is empty, which a valid map
    // never gives): take the cell it is closest to being inside, by signed edge distance.
    auto margin = [&](std::uint32_t k) {
        const glm::dvec2* n = first(k);
        const glm::dvec2 p[4] = {n[0], n[1], n[stride + 1], n[stride]};
        double worst = std::numeric_limits<double>::infinity();
        for (int e = 0; e < 4; ++e) {
            const glm::dvec2 edge = p[(e + 1) % 4] - p[e];
            worst = std::min(worst, cross(edge, q - p[e]) / std::max(glm::length(edge), 1e-300));
        }
        return worst;
    };
    std::uint32_t best = 0;
    double bestMargin = -std::numeric_limits<double>::infinity();
    auto consider = [&](std::uint32_t k) {
        const double m = margin(k);
        if (m > bestMargin) bestMargin = m, best = k;
    };
    if (index.start[bucket] != index.start[bucket + 1]) {
        for (std::uint32_t c = index.start[bucket]; c < index.start[bucket + 1]; ++c) consider(index.cells[c]);
    } else {
        for (int j = 0; j + 1 < m_rows; ++j)
            for (int i = 0; i + 1 < m_columns; ++i) consider(static_cast<std::uint32_t>(i) | static_cast<std::uint32_t>(j) << 16);
    }
    return solve(best);
}

glm::dmat2 SamplingMap::jacobian(glm::dvec2 p) const {
    double s, t;
    const int i = cellOf(clamp01(p.x), m_columns - 1, s);
    const int j = cellOf(clamp01(p.y), m_rows - 1, t);
    const glm::dvec2* n = m_dnodes.data() + std::size_t(j) * m_columns + i;
    const glm::dvec2 p00 = n[0], p10 = n[1], p01 = n[m_columns], p11 = n[m_columns + 1];
    const glm::dvec2 du = ((p10 - p00) * (1.0 - t) + (p11 - p01) * t) * double(m_columns - 1);
    const glm::dvec2 dv = ((p01 - p00) * (1.0 - s) + (p11 - p10) * s) * double(m_rows - 1);
    return glm::dmat2(du, dv);
}

double SamplingMap::density(glm::dvec2 p) const { return glm::determinant(jacobian(p)); }

SamplingMap SamplingMap::resampled(int columns, int rows) const {
    if (columns < 2 || rows < 2) {
        throw Error(ErrorCode::InvalidArgument,
                    "resampled map of " + std::to_string(columns) + "x" + std::to_string(rows) + " nodes; need at least 2x2");
    }
    std::vector<glm::vec2> nodes(std::size_t(columns) * rows);
    for (int j = 0; j < rows; ++j) {
        for (int i = 0; i < columns; ++i) {
            glm::dvec2 p = distort({double(i) / (columns - 1), double(j) / (rows - 1)});
            // Float rounding of an interpolated edge node need not land on the edge (V10 is exact).
            if (i == 0) p.x = 0.0;
            if (i == columns - 1) p.x = 1.0;
            if (j == 0) p.y = 0.0;
            if (j == rows - 1) p.y = 1.0;
            nodes[std::size_t(j) * columns + i] = glm::vec2(p);
        }
    }
    return SamplingMap(columns, rows, std::move(nodes));
}

SamplingMap::SamplingMap(const SamplingMap& other)
    : m_columns(other.m_columns),
      m_rows(other.m_rows),
      m_nodes(other.m_nodes),
      m_dnodes(other.m_dnodes),
      m_invCellsX(other.m_invCellsX),
      m_invCellsY(other.m_invCellsY),
      m_lazy(std::make_unique<LazyIndex>()) {
    if (other.m_lazy && other.m_lazy->ready.load(std::memory_order_acquire)) {
        m_lazy->owner = other.m_lazy->owner;
        m_lazy->ready.store(m_lazy->owner.get(), std::memory_order_release);
    }
}

SamplingMap& SamplingMap::operator=(const SamplingMap& other) {
    if (this != &other) {
        SamplingMap copy(other);
        *this = std::move(copy);
    }
    return *this;
}

SamplingMap::SamplingMap(SamplingMap&&) noexcept = default;
SamplingMap& SamplingMap::operator=(SamplingMap&&) noexcept = default;
SamplingMap::~SamplingMap() = default;

}  // namespace conus::codec
