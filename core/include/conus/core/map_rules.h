// The sampling-map rules of spec/conus-format.md, written once: the grid's node count (V7), finite
// nodes (V8) inside [0,1]^2 (V9), boundary nodes exactly on their edge (V10) and strictly convex
// cells with the identity's orientation (V11); the focus parameters (V12). isValidGrid is the one
// question "is this grid a valid map?" and isValidFocus "is this a valid focus?": codec's builders
// and SamplingMap ask them, and format's validator asks them too before it words each broken rule,
// so what one accepts the other accepts.
#pragma once

#include <cmath>
#include <cstddef>
#include <span>

#include <glm/vec2.hpp>

#include "conus/core/limits.h"

namespace conus::map_rules {

// V11: every corner cross product of every cell must exceed this (folded, flipped and degenerate
// cells fail).
inline constexpr double kMinCornerCross = 1e-12;
// V12: a focus magnifies by k in [1, kMaxMagnification].
inline constexpr double kMaxMagnification = 64.0;
// V12: a focus's radius r (a fraction of the image width) is in (0, kMaxFocusRadius]: no wider than
// the picture, which is what every builder makes and every writer has written.
inline constexpr double kMaxFocusRadius = 1.0;
// V12: a ground map's row profile (conus:groundRows) holds 2 to kMaxGroundRows values.
inline constexpr int kMaxGroundRows = 4097;
// V12: a focus's transition (conus:param:falloffWidth) ends at w radii, w in (1, kMaxFalloffWidth];
// its shape (conus:param:falloffShape) is an integer in [0, kFalloffShapes): density, log, logr.
inline constexpr double kMaxFalloffWidth = 8.0;
inline constexpr int kFalloffShapes = 3;
// The grid the builders make when a user does not say (nodes per side).
inline constexpr int kDefaultSide = 65;
// A map finer than its image adds nothing the image can show and costs memory and work in
// proportion to its nodes (a 16x16 image with a 4097^2 map: 570 MB to describe): builders and
// readers take at most kMapNodesPerPixel (limits.h) nodes a pixel along the image's longer side,
// plus one, and always kMapSideAlways.
inline constexpr std::int64_t maxSideForImage(std::int64_t width, std::int64_t height) {
    const std::int64_t side = kMapNodesPerPixel * (width > height ? width : height) + 1;
    return side < kMapSideAlways ? kMapSideAlways : side;
}
// The builders' default bound on anisotropy: the ratio of a cell's Jacobian singular values in
// pixels (codec's map_measures.h). A CoNUS pixel's footprint is at most this elongated, so the
// encode's filter and the decode's stretch stay local; foci reach their k by widening their
// transition instead (codec/builders/density_map.h, foci.h).
inline constexpr double kMaxAnisotropy = 7.0;

// The corners of cell (i,j) in its cyclic order: (i,j), (i+1,j), (i+1,j+1), (i,j+1).
inline constexpr int kCornerDi[4] = {0, 1, 1, 0};
inline constexpr int kCornerDj[4] = {0, 0, 1, 1};

// A grid of columns x rows nodes, row-major, (u, v) interleaved: what format::GridNodes holds and
// what an array of glm::vec2 is in memory.
struct GridView {
    int columns = 0, rows = 0;
    const float* uv = nullptr;

    double u(int i, int j) const { return uv[2 * (std::size_t(j) * columns + i)]; }
    double v(int i, int j) const { return uv[2 * (std::size_t(j) * columns + i) + 1]; }
};

// V11 at corner c (0..3) of cell (i,j): the cross product of its incoming and outgoing edge.
inline double cornerCross(const GridView& g, int i, int j, int c) {
    const int prev = (c + 3) & 3, next = (c + 1) & 3;
    const double pu = g.u(i + kCornerDi[prev], j + kCornerDj[prev]), pv = g.v(i + kCornerDi[prev], j + kCornerDj[prev]);
    const double cu = g.u(i + kCornerDi[c], j + kCornerDj[c]), cv = g.v(i + kCornerDi[c], j + kCornerDj[c]);
    const double nu = g.u(i + kCornerDi[next], j + kCornerDj[next]), nv = g.v(i + kCornerDi[next], j + kCornerDj[next]);
    return (cu - pu) * (nv - cv) - (cv - pv) * (nu - cu);
}

// The first corner of cell (i,j) that breaks V11, or -1 when the cell is strictly convex.
inline int firstBadCorner(const GridView& g, int i, int j) {
    for (int c = 0; c < 4; ++c)
        if (!(cornerCross(g, i, j, c) > kMinCornerCross)) return c;  // NaN fails too
    return -1;
}

// V7's size: columns and rows in [kMinMapSide, kMaxMapSide].
inline bool sidesInRange(int columns, int rows) {
    return columns >= kMinMapSide && columns <= kMaxMapSide && rows >= kMinMapSide && rows <= kMaxMapSide;
}

// V8 for node (i,j).
inline bool nodeFinite(const GridView& g, int i, int j) { return std::isfinite(g.u(i, j)) && std::isfinite(g.v(i, j)); }

// V9 and V10 for node (i,j), assuming it is finite.
inline bool nodeInside(const GridView& g, int i, int j) {
    const double u = g.u(i, j), v = g.v(i, j);
    return u >= 0.0 && u <= 1.0 && v >= 0.0 && v <= 1.0;
}
inline bool nodeOnItsEdge(const GridView& g, int i, int j) {
    const double u = g.u(i, j), v = g.v(i, j);
    return !((i == 0 && u != 0.0) || (i == g.columns - 1 && u != 1.0) || (j == 0 && v != 0.0) ||
             (j == g.rows - 1 && v != 1.0));
}

// V12, one focus (u, v, r, k), each part asked on its own so that callers can say which failed; all
// written as negations of the accepting test, so that NaN fails every one.
inline bool focusCentreValid(double u, double v) { return u >= 0.0 && u <= 1.0 && v >= 0.0 && v <= 1.0; }
inline bool focusRadiusValid(double r) { return r > 0.0 && r <= kMaxFocusRadius; }
inline bool focusMagnificationValid(double k) { return k >= 1.0 && k <= kMaxMagnification; }
// V12 for one focus: what codec's builders accept (codec::checkFocus) and what format's validator
// accepts in conus:foci.
inline bool isValidFocus(double u, double v, double r, double k) {
    return focusCentreValid(u, v) && focusRadiusValid(r) && focusMagnificationValid(k);
}

// V7's size and V8..V11 together, without messages (format::validateGrid says what is wrong).
bool isValidGrid(const GridView& g);
// The same for nodes as floats (u, v interleaved: format::GridNodes) or as glm::vec2 (codec's
// maps): false too when there are not columns x rows nodes.
bool isValidGrid(int columns, int rows, std::span<const float> uv);
bool isValidGrid(int columns, int rows, std::span<const glm::vec2> nodes);

}  // namespace conus::map_rules
