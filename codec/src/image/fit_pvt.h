// Private: the decoder as a linear operator D (fit.h), a row of output pixels at a time, and its
// adjoint, shared by the fit and its test.
//
// DecoderTaps walks the decoder's multi-tap reference (decode_reference_pvt.h) for the whole-image
// view: the same row stepping of Eq. 1 (decode_pvt.h), the same footprint rule (decode_pvt.h's
// tapsFor, the taps at TapOffsets), the same clamp to the image. It yields each output pixel's taps
// instead of their value, so the fit can gather through them (D) and splat through them (D^T).
// The decoder keeps its own loop, faster for its one job; tests/codec/image/fit_test.cpp checks
// that the two agree on every pixel.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "conus/codec/image/decode.h"
#include "conus/codec/map/sampling_map.h"
#include "decode_pvt.h"
#include "resample_pvt.h"

namespace conus::codec::detail {

// One bilinear tap: CoNUS pixel coordinates plus one (pixel centres at 1, 2, ...; the decoder's
// "biased" coordinates, tapBiased) and its weight.
struct DecoderTap {
    double x = 0, y = 0;
    float weight = 1;
};

// The 2x2 pixels a tap reads and their weights, clamped to the image as the decoder clamps.
struct TapCorners {
    int x0, x1, y0, y1;
    float w00, w01, w10, w11;
};

inline TapCorners tapCorners(const DecoderTap& tap, int width, int height) {
    // Eq. 1 keeps every point in [0.5, size + 0.5]; the clamp only keeps rounding there.
    const double x = std::clamp(tap.x, 0.5, width + 0.5), y = std::clamp(tap.y, 0.5, height + 0.5);
    const int xi = static_cast<int>(x), yi = static_cast<int>(y);
    const float fx = static_cast<float>(x - xi), fy = static_cast<float>(y - yi);
    TapCorners c;
    c.x0 = std::max(xi - 1, 0);
    c.x1 = std::min(xi, width - 1);
    c.y0 = std::max(yi - 1, 0);
    c.y1 = std::min(yi, height - 1);
    c.w00 = (1 - fx) * (1 - fy) * tap.weight;
    c.w01 = fx * (1 - fy) * tap.weight;
    c.w10 = (1 - fx) * fy * tap.weight;
    c.w11 = fx * fy * tap.weight;
    return c;
}

class DecoderTaps {
public:
    static constexpr int kMaxTaps = kDecodeMaxTaps * kDecodeMaxTaps;

    // Per-thread working memory of row().
    struct Scratch {
        RowNodes nodes;
        std::vector<double> bx, by, ax, ay;
        std::vector<char> multi;
        DecoderTap taps[kMaxTaps];
    };

    DecoderTaps(const SamplingMap& map, int conusWidth, int conusHeight, int width, int height)
        : m_map(map), m_wc(conusWidth), m_hc(conusHeight), m_width(width), m_height(height),
          m_cols(viewColumns(map.columns(), 0.0, 1.0, width)) {}

    int conusWidth() const { return m_wc; }
    int conusHeight() const { return m_hc; }
    int width() const { return m_width; }
    int height() const { return m_height; }

    // Calls fn(x, taps, count) for every pixel x of output row y, left to right.
    template <typename Fn>
    void row(int y, Scratch& s, Fn&& fn) const {
        const int n = m_map.columns(), m = m_map.rows();
        const double du = 1.0 / m_width, dv = 1.0 / m_height;
        const CellRow cell = cellRow(m, (y + 0.5) / m_height);
        rowNodes(m_map, cell, m_cols.firstCell, m_cols.lastCell, glm::dvec2(m_wc, m_hc), glm::dvec2(-0.5), s.nodes);
        s.bx.resize(n);
        s.by.resize(n);
        s.ax.resize(n);
        s.ay.resize(n);
        s.multi.resize(n);
        const double rowInside = cell.inside ? 1.0 : 0.0;
        for (int i = m_cols.firstCell; i <= m_cols.lastCell + 1; ++i) {
            const glm::dvec2 d = glm::dvec2(m_map.node(i, cell.j + 1)) - glm::dvec2(m_map.node(i, cell.j));
            s.bx[i] = d.x * (m - 1) * dv * m_wc * rowInside;
            s.by[i] = d.y * (m - 1) * dv * m_hc * rowInside;
        }
        for (int i = m_cols.firstCell; i <= m_cols.lastCell; ++i) {
            s.ax[i] = s.nodes.dx[i] * (n - 1) * du;
            s.ay[i] = s.nodes.dy[i] * (n - 1) * du;
            const double lb = std::max(length(s.bx[i], s.by[i]), length(s.bx[i + 1], s.by[i + 1]));
            s.multi[i] = std::max(length(s.ax[i], s.ay[i]), lb) > kDecodeMultiTap;
        }
        DecoderTap* taps = s.taps;
        forEachSpan(m_cols, s.nodes, [&](const ColumnSpan& span, double px, double py, double sx, double sy) {
            const int i = span.cell;
            if (!s.multi[i]) {
                for (int x = span.x0; x < span.x1; ++x, px += sx, py += sy) {
                    taps[0] = {px, py, 1.0f};
                    fn(x, static_cast<const DecoderTap*>(taps), 1);
                }
                return;
            }
            const double inside = span.inside ? 1.0 : 0.0;
            const double axp = s.ax[i] * inside, ayp = s.ay[i] * inside;
            const int na = tapsFor(length(axp, ayp));
            double t = span.s0;
            for (int x = span.x0; x < span.x1; ++x, px += sx, py += sy, t += span.ds) {
                const double bxp = s.bx[i] + t * (s.bx[i + 1] - s.bx[i]), byp = s.by[i] + t * (s.by[i + 1] - s.by[i]);
                const int nb = tapsFor(length(bxp, byp));
                if (na == 1 && nb == 1) {
                    taps[0] = {px, py, 1.0f};
                    fn(x, static_cast<const DecoderTap*>(taps), 1);
                    continue;
                }
                const float weight = 1.0f / static_cast<float>(na * nb);
                int count = 0;
                for (int jb = 0; jb < nb; ++jb) {
                    const double qx = px + bxp * kOffsets.at[nb][jb], qy = py + byp * kOffsets.at[nb][jb];
                    for (int ia = 0; ia < na; ++ia)
                        taps[count++] = {qx + axp * kOffsets.at[na][ia], qy + ayp * kOffsets.at[na][ia], weight};
                }
                fn(x, static_cast<const DecoderTap*>(taps), count);
            }
        });
    }

private:
    static constexpr TapOffsets<kDecodeMaxTaps> kOffsets{};

    const SamplingMap& m_map;
    int m_wc, m_hc, m_width, m_height;
    ViewColumns m_cols;
};

// D and D^T for a whole-image view at width x height: the decoded view of `conus` (every channel,
// as decodeImage computes it), and the splat of `view` into a conusWidth x conusHeight image
// through the same taps. <fitForward(c), y> == <c, fitAdjoint(y)>.
Image fitForward(const Image& conus, const SamplingMap& map, int width, int height, int threads = 0);
Image fitAdjoint(const Image& view, const SamplingMap& map, int conusWidth, int conusHeight, int threads = 0);

// fitToDecoder solves its normal equations assembled on the CoNUS grid (one walk of the taps) unless
// the view minifies much of the image; forced, it walks the taps every iteration instead (the
// tests compare the two).
// A x of the assembled normal equations (A = D^T D for a whole-image view at width x height),
// and how many wide rows of D they keep; throws where the fit would walk the taps instead.
Image fitNormalProduct(const Image& x, const SamplingMap& map, int width, int height, std::size_t* wideRows = nullptr,
                       int threads = 0);
void forceFitPasses(bool passes);
bool fitPassesForced();

}  // namespace conus::codec::detail
