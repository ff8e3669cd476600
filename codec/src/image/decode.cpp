// The CPU decoder (paper section 4): a conventional view from a CoNUS image. This file is its
// entry and dispatch: Eq. 1 along each output row by the stepping of decode_pvt.h (not by
// SamplingMap::distort), then each span of columns in one map cell goes to the path its footprint
// asks for:
//   magnified (every footprint within one tap)   decode_magnify_pvt.h: one bilinear tap a pixel,
//                                                 stepped in fixed point and vector lanes;
//   zoomed out, no pyramid                       decode_reference_pvt.h: the multi-tap average,
//                                                 the readable reference the GPU decoder is held to;
//   zoomed out, with a pyramid                   pyramid_pvt.h: one trilinear tap, through the
//                                                 planned pass (decode_planned.cpp, baseline and
//                                                 AVX2 copies) for 3 and 4 channels.
// The footprint is bounded per map cell, so a span's path is chosen once. The bilinear baseline
// it is timed against is resize_bilinear.cpp.
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "conus/codec/image/decode.h"
#include "conus/core/check.h"
#include "conus/core/parallel.h"
#include "decode_magnify_pvt.h"
#include "decode_planned_pvt.h"
#include "decode_pvt.h"
#include "decode_reference_pvt.h"
#include "pyramid_pvt.h"
#include "resample_pvt.h"

namespace conus::codec {
namespace detail {

ViewColumns viewColumns(int mapColumns, double u0, double u1, int width) {
    ViewColumns c;
    c.cell.resize(width);
    c.s.resize(width);
    c.inside.resize(width);
    const int cells = mapColumns - 1;
    c.firstCell = cells - 1;
    c.lastCell = 0;
    for (int x = 0; x < width; ++x) {
        const double u = u0 + (x + 0.5) / width * (u1 - u0);
        const double uc = std::clamp(u, 0.0, 1.0);
        const double f = uc * cells;
        const int i = std::clamp(static_cast<int>(f), 0, cells - 1);
        c.cell[x] = i;
        c.s[x] = f - i;
        c.inside[x] = (u >= 0.0 && u <= 1.0) ? 1.0 : 0.0;
        c.firstCell = std::min(c.firstCell, i);
        c.lastCell = std::max(c.lastCell, i);
    }
    // s steps by ds per column inside [0,1]; a span restarts where the cell or the clamp changes.
    const double ds = (u1 - u0) / width * cells;
    for (int x = 0; x < width;) {
        ColumnSpan span;
        span.x0 = x;
        span.cell = c.cell[x];
        span.s0 = c.s[x];
        span.inside = c.inside[x] != 0.0;
        span.ds = span.inside ? ds : 0.0;
        while (x < width && c.cell[x] == span.cell && (c.inside[x] != 0.0) == span.inside) ++x;
        span.x1 = x;
        c.spans.push_back(span);
    }
    CONUS_DCHECK(!c.spans.empty() && c.spans.back().x1 == width);  // the spans tile the row
    return c;
}

CellRow cellRow(int mapRows, double v) {
    CellRow r;
    const double vc = std::clamp(v, 0.0, 1.0);
    const double f = vc * (mapRows - 1);
    r.j = std::clamp(static_cast<int>(f), 0, mapRows - 2);
    r.t = f - r.j;
    r.inside = v >= 0.0 && v <= 1.0;
    return r;
}

void rowNodes(const SamplingMap& map, const CellRow& row, int first, int last, glm::dvec2 scale, glm::dvec2 offset,
              RowNodes& out) {
    const std::size_t n = static_cast<std::size_t>(map.columns());
    out.x.resize(n);
    out.y.resize(n);
    out.dx.resize(n);
    out.dy.resize(n);
    for (int i = first; i <= last + 1; ++i) {
        const glm::dvec2 a(map.node(i, row.j)), b(map.node(i, row.j + 1));
        const glm::dvec2 p = a + row.t * (b - a);
        out.x[i] = p.x * scale.x - offset.x;
        out.y[i] = p.y * scale.y - offset.y;
    }
    for (int i = first; i <= last; ++i) {
        out.dx[i] = out.x[i + 1] - out.x[i];
        out.dy[i] = out.y[i + 1] - out.y[i];
    }
}

std::vector<glm::dvec2> distortViewRow(const SamplingMap& map, const View& view, int width, int height, int y) {
    const ViewColumns cols = viewColumns(map.columns(), view.u0, view.u1, width);
    const CellRow row = cellRow(map.rows(), view.v0 + (y + 0.5) / height * (view.v1 - view.v0));
    RowNodes nodes;
    rowNodes(map, row, cols.firstCell, cols.lastCell, glm::dvec2(1.0), glm::dvec2(0.0), nodes);
    std::vector<glm::dvec2> out(width);
    forEachSpan(cols, nodes, [&](const ColumnSpan& span, double px, double py, double sx, double sy) {
        for (int x = span.x0; x < span.x1; ++x, px += sx, py += sy) out[x] = {px, py};
    });
    return out;
}

void checkView(const View& v, const char* what) {
    if (!std::isfinite(v.u0) || !std::isfinite(v.u1) || !std::isfinite(v.v0) || !std::isfinite(v.v1) ||
        v.u0 == v.u1 || v.v0 == v.v1 || std::abs(v.u1 - v.u0) > 1e6 || std::abs(v.v1 - v.v0) > 1e6)
        throw Error(ErrorCode::InvalidArgument, std::string(what) + ": view (" + std::to_string(v.u0) + ", " +
                                                    std::to_string(v.v0) + ") - (" + std::to_string(v.u1) + ", " +
                                                    std::to_string(v.v1) + ") is empty or not finite");
}

// The run [first, last) of the indices k < count whose centre a0 + (k + 0.5) / count * (a1 - a0)
// lies in [0, 1]: one run, as the centres are monotone in k (empty: first == last).
std::pair<int, int> insideRun(double a0, double a1, int count) {
    const auto inside = [&](int k) {
        const double a = a0 + (k + 0.5) / count * (a1 - a0);
        return a >= 0.0 && a <= 1.0;
    };
    int first = 0;
    while (first < count && !inside(first)) ++first;
    int last = first;
    while (last < count && inside(last)) ++last;
    return {first, last};
}

// Pixels whose centre lies outside the image ([0,1]^2 undistorted) show the background, 0 in every
// channel, instead of the edge pixels smeared outward. Only those pixels are touched: a view
// inside the image costs nothing here.
void clearOutside(Image& out, const View& view) {
    const std::size_t c = out.channels.size();
    const std::size_t rowValues = static_cast<std::size_t>(out.width) * c;
    const auto [x0, x1] = insideRun(view.u0, view.u1, out.width);
    const auto [y0, y1] = insideRun(view.v0, view.v1, out.height);
    for (int y = 0; y < out.height; ++y) {
        float* row = out.pixels.data() + y * rowValues;
        if (y < y0 || y >= y1 || x0 == x1) {
            std::fill(row, row + rowValues, 0.0f);
            continue;
        }
        std::fill(row, row + x0 * c, 0.0f);
        std::fill(row + x1 * c, row + rowValues, 0.0f);
    }
}

}  // namespace detail

namespace {

// A footprint longer than this (in CoNUS pixels) on either axis gets several taps.
constexpr double kMultiTapThreshold = kDecodeMultiTap;
// The pyramid decode's level is 0 (one bilinear tap) up to this footprint: 2^kDecodePyramidBias.
const double kPyramidOneTap = std::exp2(kDecodePyramidBias);

// kPyramid: zoomed-out pixels take one trilinear tap from `levels` instead of the multi-tap
// average (DecodeOptions::pyramid).
template <int kC, bool kPyramid>
void decodeRows(const Image& src, const SamplingMap& map, const View& view, Image& dst,
                const detail::ViewColumns& cols, const std::vector<detail::Level>& levels, int y0, int y1) {
    const int channels = kC > 0 ? kC : src.channelCount();
    const int W = dst.width, H = dst.height, Wc = src.width, Hc = src.height;
    const int n = map.columns(), m = map.rows();
    const double du = std::abs(view.u1 - view.u0) / W, dv = std::abs(view.v1 - view.v0) / H;
    const std::size_t stride = static_cast<std::size_t>(Wc) * channels;
    detail::RowNodes nodes;
    // Per node column: d(position)/dv over one output pixel, CoNUS pixels. Per cell: footprint
    // along u over one output pixel, and whether any pixel of the cell may need several taps.
    std::vector<double> bx(n), by(n), ax(n), ay(n);
    std::vector<char> multi(n);
    std::vector<float> dynamicAcc(kC > 0 ? 0 : channels);
    float fixedScratch[kC > 0 ? kC : 1];
    std::vector<float> dynamicScratch(kC > 0 ? 0 : channels);
    float* const scratch = kC > 0 ? fixedScratch : dynamicScratch.data();
    const float* pixels = src.pixels.data();
    const float* const last = levels[0].last;
    const bool lanes = detail::kLanes<kC> && detail::lanesFit(Wc, Hc, channels);
    // The pyramid decode's planned blocks (3 and 4 channels).
    const bool planned = kPyramid && detail::kLanes<kC> && detail::plannable(levels[0], channels);
    std::unique_ptr<detail::PixelPlan> plan(planned ? new detail::PixelPlan : nullptr);
    [[maybe_unused]] detail::BlockFn blockFn = nullptr;
    if constexpr (detail::kLanes<kC>) blockFn = detail::chooseBlockFn<kC>();

    for (int y = y0; y < y1; ++y) {
        const detail::CellRow row = detail::cellRow(m, view.v0 + (y + 0.5) / H * (view.v1 - view.v0));
        // CoNUS pixel coordinates plus one (see tapBiased).
        detail::rowNodes(map, row, cols.firstCell, cols.lastCell, glm::dvec2(Wc, Hc), glm::dvec2(-0.5), nodes);
        const double rowInside = row.inside ? 1.0 : 0.0;
        for (int i = cols.firstCell; i <= cols.lastCell + 1; ++i) {
            const glm::dvec2 d = glm::dvec2(map.node(i, row.j + 1)) - glm::dvec2(map.node(i, row.j));
            bx[i] = d.x * (m - 1) * dv * Wc * rowInside;
            by[i] = d.y * (m - 1) * dv * Hc * rowInside;
        }
        for (int i = cols.firstCell; i <= cols.lastCell; ++i) {
            ax[i] = nodes.dx[i] * (n - 1) * du;
            ay[i] = nodes.dy[i] * (n - 1) * du;
            // |b| is convex along the cell, so its larger end bounds it.
            const double lb = std::max(detail::length(bx[i], by[i]), detail::length(bx[i + 1], by[i + 1]));
            multi[i] = std::max(detail::length(ax[i], ay[i]), lb) > (kPyramid ? kPyramidOneTap : kMultiTapThreshold);
        }

        float* const rowOut = dst.pixels.data() + static_cast<std::size_t>(y) * W * channels;
        detail::forEachSpan(cols, nodes, [&](const detail::ColumnSpan& span, double px, double py, double sx,
                                             double sy) {
            const int i = span.cell;
            float* out = rowOut + static_cast<std::size_t>(span.x0) * channels;
            const int count = span.x1 - span.x0;
            if (!multi[i]) {
                detail::magnifySpan<kC>(pixels, Wc, Hc, channels, stride, last, lanes, px, py, sx, sy, count, out);
                return;
            }
            const double inside = span.inside ? 1.0 : 0.0;
            const double axp = ax[i] * inside, ayp = ay[i] * inside;
            const double s = span.s0;
            if constexpr (kPyramid) {
                // The span's positions, and b along it, in float as the GPU has them.
                const detail::SpanInputs in{static_cast<float>(px),
                                            static_cast<float>(py),
                                            static_cast<float>(sx),
                                            static_cast<float>(sy),
                                            static_cast<float>(axp * axp + ayp * ayp),
                                            static_cast<float>(bx[i] + s * (bx[i + 1] - bx[i])),
                                            static_cast<float>(by[i] + s * (by[i + 1] - by[i])),
                                            static_cast<float>(span.ds * (bx[i + 1] - bx[i])),
                                            static_cast<float>(span.ds * (by[i + 1] - by[i]))};
                const int top = static_cast<int>(levels.size()) - 1;
                if constexpr (detail::kLanes<kC>) {
                    if (planned) {
                        for (int k0 = 0; k0 < count; k0 += detail::kPlanBlock) {
                            const int n = std::min(detail::kPlanBlock, count - k0);
                            blockFn(levels.data(), top, in, k0, n, *plan, out);
                            out += static_cast<std::size_t>(n) * kC;
                        }
                        return;
                    }
                }
                for (int k = 0; k < count; ++k, out += channels) {
                    if constexpr (detail::kLanes<kC>)
                        detail::trilinearTapLanes<kC>(levels.data(), top, in.xAt(k), in.yAt(k), in.rho2At(k), out);
                    else
                        detail::trilinearTap<kC>(levels.data(), top, channels, in.xAt(k), in.yAt(k), in.rho2At(k),
                                                 out, scratch);
                }
                return;
            }
            detail::multiTapSpan<kC>(pixels, Wc, Hc, channels, px, py, sx, sy, axp, ayp, bx[i], by[i], bx[i + 1],
                                     by[i + 1], s, span.ds, count, out, dynamicAcc.data());
        });
    }
}

}  // namespace

bool viewZoomsOut(const Image& conus, const SamplingMap& map, const View& view, int width, int height) {
    detail::checkView(view, "viewZoomsOut");
    detail::checkOutputSize(width, height, "viewZoomsOut");
    const int n = map.columns(), m = map.rows();
    // Output pixels per map cell along u and v; the cells the view covers (clamped like Eq. 1).
    const double du = std::abs(view.u1 - view.u0) / width * (n - 1), dv = std::abs(view.v1 - view.v0) / height * (m - 1);
    const auto cells = [](double a, double b, int count) {
        const double lo = std::clamp(std::min(a, b), 0.0, 1.0), hi = std::clamp(std::max(a, b), 0.0, 1.0);
        return std::pair{std::clamp(static_cast<int>(lo * count), 0, count - 1),
                         std::clamp(static_cast<int>(hi * count), 0, count - 1)};
    };
    const auto [i0, i1] = cells(view.u0, view.u1, n - 1);
    const auto [j0, j1] = cells(view.v0, view.v1, m - 1);
    const glm::dvec2 scale(conus.width, conus.height);
    double longest2 = 0;  // the longest footprint edge, squared: |a| and |b| are largest on a cell's edges
    for (int j = j0; j <= j1 + 1; ++j)
        for (int i = i0; i <= i1 + 1; ++i) {
            const glm::dvec2 p = glm::dvec2(map.node(i, j)) * scale;
            if (i <= i1) {
                const glm::dvec2 a = (glm::dvec2(map.node(i + 1, j)) * scale - p) * du;
                longest2 = std::max(longest2, a.x * a.x + a.y * a.y);
            }
            if (j <= j1) {
                const glm::dvec2 b = (glm::dvec2(map.node(i, j + 1)) * scale - p) * dv;
                longest2 = std::max(longest2, b.x * b.x + b.y * b.y);
            }
        }
    return longest2 > kPyramidOneTap * kPyramidOneTap;
}

void checkDecodeMemory(const Image& conus, int width, int height, std::int64_t maxBytes, bool withPyramid,
                       std::int64_t extraBytes) {
    const std::int64_t channels = conus.channelCount();
    const std::int64_t image = std::int64_t{conus.width} * conus.height;
    const std::int64_t bytes = (image + (withPyramid ? image / 3 : 0) + std::int64_t{width} * height) * channels *
                                   std::int64_t(sizeof(float)) +
                               extraBytes;
    if (bytes > maxBytes) {
        throw Error(ErrorCode::LimitExceeded,
                    "decoding a " + std::to_string(conus.width) + "x" + std::to_string(conus.height) + " image to " +
                        std::to_string(width) + "x" + std::to_string(height) + " pixels of " + std::to_string(channels) +
                        " channels" + (withPyramid ? std::string(" with its pyramid") : std::string()) +
                        (extraBytes > 0 ? " and the picture writer's copies" : "") + " takes " +
                        std::to_string(bytes) + " bytes, beyond the decode memory limit of " +
                        std::to_string(maxBytes));
    }
}

Image decodeImage(const Image& conus, const SamplingMap& map, const DecodeOptions& options) {
    checkImage(conus, "decodeImage");
    detail::checkOutputSize(options.width, options.height, "decodeImage");
    checkDecodeMemory(conus, options.width, options.height, kMaxDecodeBytes, options.pyramid != nullptr);
    detail::checkView(options.view, "decodeImage");
    if (options.pyramid) checkPyramid(conus, *options.pyramid);
    const std::vector<detail::Level> levels = detail::pyramidLevels(conus, options.pyramid);
    Image out = detail::makeOutput(conus, options.width, options.height);
    const detail::ViewColumns cols = detail::viewColumns(map.columns(), options.view.u0, options.view.u1, out.width);
    detail::RowProgress progress(options.progress, out.height);
    parallelRows(
        out.height, options.threads,
        [&](int y0, int y1) {
            detail::dispatchChannels(conus.channelCount(), [&]<int kC>() {
                if (options.pyramid) decodeRows<kC, true>(conus, map, options.view, out, cols, levels, y0, y1);
                else decodeRows<kC, false>(conus, map, options.view, out, cols, levels, y0, y1);
            });
            progress.add(y1 - y0);
        },
        16);
    detail::clearOutside(out, options.view);
    return out;
}

}  // namespace conus::codec
