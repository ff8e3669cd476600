// Private: the decoder's fast evaluation of Equation 1 along an output row, shared with its test,
// and the view rules the decoder and its bilinear baseline share.
//
// Along an output row v is fixed, so interpolating the two node rows of v's cell once gives one
// distorted point per node column; inside a map cell Eq. 1 is then linear in u. Each output
// column's cell and position in it depend only on u, so they are computed once per view.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/glm.hpp>

#include "conus/codec/image/decode.h"
#include "conus/codec/map/sampling_map.h"

namespace conus::codec::detail {

// The multi-tap footprint rule (decode.h), for the decoder and for the fit that models it: the
// length of a footprint axis (written out: std::hypot rounds differently at the thresholds), and
// its taps: up to kDecodeMultiTap CoNUS pixels one bilinear tap (its tent spans two pixels),
// longer ceil(length) taps at most a pixel apart, at most kDecodeMaxTaps.
inline double length(double x, double y) { return std::sqrt(x * x + y * y); }
inline int tapsFor(double length) {
    return length <= kDecodeMultiTap ? 1 : std::min(kDecodeMaxTaps, static_cast<int>(std::ceil(length)));
}

// Per output column of a view: map cell i and s = u(n-1) - i in [0,1], u clamped to [0,1] as
// distort() does; inside is 0 where u was clamped (the point does not move with u there).
// Spans are the runs of columns in one cell on one side of a clamp: s is linear in x along each.
struct ColumnSpan {
    int x0 = 0, x1 = 0;  // columns [x0, x1)
    int cell = 0;
    double s0 = 0, ds = 0;  // s at x0, and its step per column (0 where clamped)
    bool inside = true;
};
struct ViewColumns {
    std::vector<int> cell;
    std::vector<double> s;
    std::vector<double> inside;
    std::vector<ColumnSpan> spans;
    int firstCell = 0, lastCell = 0;
};
ViewColumns viewColumns(int mapColumns, double u0, double u1, int width);

// The cell row at v (clamped to [0,1]): j and t = v(m-1) - j in [0,1].
struct CellRow {
    int j = 0;
    double t = 0;
    bool inside = true;
};
CellRow cellRow(int mapRows, double v);

// Distorted positions of node columns [first, last] interpolated at the cell row, as
// (position * scale - offset) so the decoder gets CoNUS pixel coordinates directly; dx, dy hold
// the step to the next node column. Arrays are indexed by node column.
struct RowNodes {
    std::vector<double> x, y, dx, dy;
};
void rowNodes(const SamplingMap& map, const CellRow& row, int first, int last, glm::dvec2 scale, glm::dvec2 offset,
              RowNodes& out);

// Walks the spans of a row: fn(span, x, y, stepX, stepY) with the node-row point at the span's
// first column and its step per column, in the units of `nodes`.
template <typename Fn>
inline void forEachSpan(const ViewColumns& cols, const RowNodes& nodes, Fn&& fn) {
    for (const ColumnSpan& span : cols.spans) {
        const int i = span.cell;
        fn(span, nodes.x[i] + span.s0 * nodes.dx[i], nodes.y[i] + span.s0 * nodes.dy[i], span.ds * nodes.dx[i],
           span.ds * nodes.dy[i]);
    }
}

// Throws conus::Error(InvalidArgument) for an empty or non-finite view (`what` names the caller).
void checkView(const View& v, const char* what);

// Sets to 0 (the background) the pixels of `out` whose centre lies outside the image ([0,1]^2
// undistorted), instead of the edge pixels smeared outward; touches only those pixels.
void clearOutside(Image& out, const View& view);

// Equation 1 at every output column of row `y` of a width x height view, by the stepping above
// (normalized distorted coordinates). Tests compare it with SamplingMap::distort.
std::vector<glm::dvec2> distortViewRow(const SamplingMap& map, const View& view, int width, int height, int y);

}  // namespace conus::codec::detail
