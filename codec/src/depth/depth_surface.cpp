// The stored surface of a depth image (intersect.h): its depths, the cells that straddle a
// discontinuity, and the surface's depth and weights at a point. The GLSL twin of sampleDepth and
// surfaceWeights is in renderers/shaders/intersect.inc.glsl (the flags travel with the depths).
#include <algorithm>
#include <cmath>
#include <string>

#include "conus/codec/depth/intersect.h"
#include "conus/core/error.h"

namespace conus::codec {
namespace {

// Whether the edge between texels a and b (neighbours on one line; a0 before a, b1 after b, or
// null at the image's edge) is a discontinuity: its step in q (1/depth or depth) exceeds
// kJumpRatio times every step beside it that goes the same way (a surface continuing, or a crease
// where two continue), and the depths differ by more than the threshold. A step beside it that
// goes back (the far side of an object a texel wide) continues nothing.
bool jumps(const float* a0, float a, float b, const float* b1, bool perspective, double relative, double absolute) {
    const auto q = [&](double d) { return perspective ? 1.0 / std::max(d, 1e-30) : d; };
    const double step = q(b) - q(a);
    double beside = 0.0;
    if (a0 && (q(a) - q(*a0)) * step > 0.0) beside = std::max(beside, std::abs(q(a) - q(*a0)));
    if (b1 && (q(*b1) - q(b)) * step > 0.0) beside = std::max(beside, std::abs(q(*b1) - q(b)));
    return std::abs(step) > kJumpRatio * beside && std::abs(double(a) - b) > relative * std::min(a, b) + absolute;
}

}  // namespace

DepthImage::DepthImage(Camera camera, std::shared_ptr<const SamplingMap> map, int width, int height,
                       std::vector<float> depths, bool solid)
    : m_camera(std::move(camera)), m_map(std::move(map)), m_width(width), m_height(height), m_depths(std::move(depths)),
      m_solid(solid) {
    if (!m_map) m_map = std::make_shared<SamplingMap>(SamplingMap::identity(2, 2));
    if (width < 1 || height < 1 || m_depths.size() != static_cast<std::size_t>(width) * height)
        throw Error(ErrorCode::InvalidArgument, "DepthImage: " + std::to_string(m_depths.size()) + " depths for " +
                                                    std::to_string(width) + "x" + std::to_string(height) + " pixels");
    for (const float d : m_depths)
        if (!std::isfinite(d)) throw Error(ErrorCode::InvalidArgument, "DepthImage: a depth is not finite");

    const bool perspective = m_camera.projection() == Projection::Perspective;
    if (perspective) {
        m_jumpRelative = kJumpRelative;
    } else {
        const double across = glm::distance(m_camera.unproject({0.0, 0.5}, 0.0), m_camera.unproject({1.0, 0.5}, 0.0));
        m_jumpAbsolute = kJumpTexels * across / width;
    }
    // Solid images keep the bilinear surface everywhere (intersect.h): no cell is flagged.
    m_flags.assign(m_depths.size(), 0);
    if (!solid) flagCells();
    // The range the surface spans: the samples', and where it is carried on to the image's sides
    // (sampleDepth; extremes at the sides' points level with texel centres, and the corners).
    const auto [lo, hi] = std::minmax_element(m_depths.begin(), m_depths.end());
    m_minDepth = *lo;
    m_maxDepth = *hi;
    const auto include = [&](double u, double v) {
        const double depth = sampleDepth({u, v});
        m_minDepth = std::min(m_minDepth, depth);
        m_maxDepth = std::max(m_maxDepth, depth);
    };
    for (int x = 0; x < width; ++x)
        for (const double v : {0.0, 1.0}) include((x + 0.5) / width, v);
    for (int y = 0; y < height; ++y)
        for (const double u : {0.0, 1.0}) include(u, (y + 0.5) / height);
    for (const double u : {0.0, 1.0})
        for (const double v : {0.0, 1.0}) include(u, v);
}

void DepthImage::flagCells() {
    const int width = m_width, height = m_height;
    const bool perspective = m_camera.projection() == Projection::Perspective;
    // Edge flags first (right: x to x + 1; down: y to y + 1), then each cell from its four edges.
    const auto d = [&](int x, int y) -> const float* {
        return x < 0 || y < 0 || x >= width || y >= height ? nullptr : &m_depths[static_cast<std::size_t>(y) * width + x];
    };
    std::vector<std::uint8_t> right(m_depths.size(), 0), down(m_depths.size(), 0);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const std::size_t i = static_cast<std::size_t>(y) * width + x;
            if (x + 1 < width)
                right[i] = jumps(d(x - 1, y), *d(x, y), *d(x + 1, y), d(x + 2, y), perspective, m_jumpRelative, m_jumpAbsolute);
            if (y + 1 < height)
                down[i] = jumps(d(x, y - 1), *d(x, y), *d(x, y + 1), d(x, y + 2), perspective, m_jumpRelative, m_jumpAbsolute);
        }
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const int x1 = std::min(x + 1, width - 1), y1 = std::min(y + 1, height - 1);
            const auto at = [&](const std::vector<std::uint8_t>& e, int ex, int ey) {
                return e[static_cast<std::size_t>(ey) * width + ex] != 0;
            };
            m_flags[static_cast<std::size_t>(y) * width + x] =
                at(right, x, y) || (y1 != y && at(right, x, y1)) || at(down, x, y) || (x1 != x && at(down, x1, y));
        }
}

DepthImage DepthImage::fromFile(const format::ConusFile& file) {
    if (!file.camera) throw Error(ErrorCode::InvalidArgument, "the file has no camera, so its depths have no place in space");
    const int z = file.image.channelIndex("Z");
    if (z < 0 || file.depth.kind == format::DepthKind::None)
        throw Error(ErrorCode::InvalidArgument, "the file has no depth channel Z");
    checkImage(file.image, "DepthImage::fromFile");
    Camera camera = format::toCamera(*file.camera);
    const bool height = file.depth.kind == format::DepthKind::Height;
    const double base = height ? heightToDepth(camera, 0.0) : 0.0;
    std::vector<float> depths(static_cast<std::size_t>(file.image.width) * file.image.height);
    for (std::size_t i = 0; i < depths.size(); ++i) {
        const float value = file.image.pixels[i * file.image.channels.size() + static_cast<std::size_t>(z)];
        depths[i] = height ? static_cast<float>(base - value) : value;
    }
    return DepthImage(std::move(camera), std::make_shared<SamplingMap>(SamplingMap::fromGrid(file.map)),
                      file.image.width, file.image.height, std::move(depths), height);
}

namespace {

// The cell of four texels around pd (pixel centres at (i + 0.5) / size): its top-left texel
// (x0, y0), the texel across (x1, y1), and pd's place in it. Within half a texel of the image's
// side the cell is the last one and f runs past [0, 1] (down to -0.5 or up to 1.5), so an
// unflagged cell's surface is carried on to the side (sampleDepth) instead of stopping flat at the
// last texel.
struct Cell {
    int x0, y0, x1, y1;
    double fx, fy;
};
Cell cellAt(glm::dvec2 pd, int width, int height) {
    // Clamped before the conversion to int (fmin and fmax also take a NaN to a side).
    const double x = std::fmax(-1.0, std::fmin(pd.x * width - 0.5, double(width)));
    const double y = std::fmax(-1.0, std::fmin(pd.y * height - 0.5, double(height)));
    const int x0 = std::clamp(static_cast<int>(std::floor(x)), 0, std::max(width - 2, 0));
    const int y0 = std::clamp(static_cast<int>(std::floor(y)), 0, std::max(height - 2, 0));
    const int x1 = std::min(x0 + 1, width - 1), y1 = std::min(y0 + 1, height - 1);
    return {x0, y0, x1, y1, x1 > x0 ? std::clamp(x - x0, -0.5, 1.5) : 0.0,
            y1 > y0 ? std::clamp(y - y0, -0.5, 1.5) : 0.0};
}

}  // namespace

std::size_t DepthImage::cellIndex(glm::dvec2 pd) const {
    const Cell c = cellAt(pd, m_width, m_height);
    return static_cast<std::size_t>(c.y0) * m_width + c.x0;
}

DepthImage::Weights DepthImage::surfaceWeights(glm::dvec2 pd) const {
    const Cell c = cellAt(pd, m_width, m_height);
    const double fx = std::clamp(c.fx, 0.0, 1.0), fy = std::clamp(c.fy, 0.0, 1.0);  // colours do not extrapolate
    Weights w{{{c.x0, c.y0}, {c.x1, c.y0}, {c.x0, c.y1}, {c.x1, c.y1}},
              {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy}};
    if (!m_flags[static_cast<std::size_t>(c.y0) * m_width + c.x0]) return w;
    // A flagged cell: keep the texels on the nearest texel's side of the cell's middle depth.
    double d[4], lo = 1e300, hi = -1e300;
    for (int k = 0; k < 4; ++k) {
        d[k] = depthAt(w.texel[k].x, w.texel[k].y);
        lo = std::min(lo, d[k]);
        hi = std::max(hi, d[k]);
    }
    const double middle = 0.5 * (lo + hi);
    const bool nearSide = d[(fx < 0.5 ? 0 : 1) + (fy < 0.5 ? 0 : 2)] <= middle;
    for (int k = 0; k < 4; ++k)
        if ((d[k] <= middle) != nearSide) w.weight[k] = 0.0;
    return w;
}

double DepthImage::sampleDepth(glm::dvec2 pd) const {
    const Cell c = cellAt(pd, m_width, m_height);
    // The common case first, as cheap as plain bilinear: an unflagged cell.
    if (!m_flags[static_cast<std::size_t>(c.y0) * m_width + c.x0]) {
        const auto bilinear = [&](const auto& value) {
            const double top = value(c.x0, c.y0) + (value(c.x1, c.y0) - value(c.x0, c.y0)) * c.fx;
            const double bottom = value(c.x0, c.y1) + (value(c.x1, c.y1) - value(c.x0, c.y1)) * c.fx;
            return top + (bottom - top) * c.fy;
        };
        const bool inside = c.fx >= 0.0 && c.fx <= 1.0 && c.fy >= 0.0 && c.fy <= 1.0;
        if (inside || m_camera.projection() != Projection::Perspective)
            return bilinear([&](int x, int y) { return double(depthAt(x, y)); });
        // Between the last centres and a perspective image's side: 1/depth carried on (a plane's
        // is affine in the image, so a floor reaches the side where it truly is), kept within
        // the camera's near and far planes.
        const double q = bilinear([&](int x, int y) { return 1.0 / double(depthAt(x, y)); });
        return 1.0 / std::clamp(q, 1.0 / m_camera.far(), 1.0 / m_camera.near());
    }
    const Weights w = surfaceWeights(pd);
    double sum = 0.0, weight = 0.0;
    for (int k = 0; k < 4; ++k) {
        sum += w.weight[k] * depthAt(w.texel[k].x, w.texel[k].y);
        weight += w.weight[k];
    }
    return sum / weight;
}

}  // namespace conus::codec
