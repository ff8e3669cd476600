// The CPU reference of ray / depth-image intersection (intersect.h). Its GLSL twin,
// renderers/shaders/intersect.inc.glsl, follows these functions one for one: change both together.
#include "conus/codec/depth/intersect.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "conus/core/error.h"

namespace conus::codec {
namespace {

// The segment of a ray inside the depth image's clipped volume, as the image sees it: its
// undistorted end points and the reciprocal w, depth / w and t / w there, which are linear along
// the projected segment (perspective-correct interpolation).
struct Segment {
    glm::dvec2 p0, p1;
    double iw0, iw1, dw0, dw1, tw0, tw1;
    int face;  // the face the ray entered through (-1: it starts inside)

    glm::dvec2 point(double s) const { return p0 + (p1 - p0) * s; }
    double invW(double s) const { return iw0 + (iw1 - iw0) * s; }
    double depth(double s) const { return (dw0 + (dw1 - dw0) * s) / invW(s); }
    double t(double s) const { return (tw0 + (tw1 - tw0) * s) / invW(s); }
};

// Clips `ray` to u, v in [0,1] and depth in [lo, hi] (each a half-space a + b t >= 0 in
// homogeneous clip coordinates, where perspective and orthographic cameras are alike).
std::optional<Segment> clipRay(const DepthImage& image, const Ray& ray, double tMax) {
    const Camera& camera = image.camera();
    const glm::dmat4 m = camera.worldToNdcMatrix();
    const glm::dvec4 c0 = m * glm::dvec4(ray.origin, 1.0), cd = m * glm::dvec4(ray.direction, 0.0);
    const glm::dvec3 forward = camera.forward();
    const double z0 = glm::dot(ray.origin - camera.eye(), forward), zd = glm::dot(ray.direction, forward);
    // The data's depth range, a hair wider so a surface exactly at its extreme is still reached;
    // in front of a perspective eye's near plane nothing projects.
    const double margin = kIntersectDepthMargin * (1.0 + std::max(std::abs(image.minDepth()), std::abs(image.maxDepth())));
    double lo = image.minDepth() - margin;
    const double hi = image.maxDepth() + margin;
    if (camera.projection() == Projection::Perspective) lo = std::max(lo, camera.near());

    double tEnter = 0.0, tExit = tMax;
    int face = -1;
    const double planes[6][2] = {{c0.x, cd.x},
                                 {c0.w - c0.x, cd.w - cd.x},
                                 {c0.y, cd.y},
                                 {c0.w - c0.y, cd.w - cd.y},
                                 {z0 - lo, zd},
                                 {hi - z0, -zd}};
    for (int k = 0; k < 6; ++k) {
        const double a = planes[k][0], b = planes[k][1];
        if (b == 0.0) {
            if (a < 0.0) return std::nullopt;
            continue;
        }
        const double t = -a / b;
        if (b > 0.0) {
            if (t > tEnter) {
                tEnter = t;
                face = k;
            }
        } else {
            tExit = std::min(tExit, t);
        }
    }
    if (!(tEnter <= tExit)) return std::nullopt;

    const auto end = [&](double t, glm::dvec2& p, double& iw, double& dw, double& tw) {
        const glm::dvec4 c = c0 + cd * t;
        iw = 1.0 / c.w;
        p = glm::clamp(glm::dvec2(c.x, c.y) * iw, 0.0, 1.0);
        dw = (z0 + zd * t) * iw;
        tw = t * iw;
    };
    Segment segment{};
    segment.face = face;
    end(tEnter, segment.p0, segment.iw0, segment.dw0, segment.tw0);
    end(tExit, segment.p1, segment.iw1, segment.dw1, segment.tw1);
    return segment;
}

}  // namespace

DepthImage::DepthImage(Camera camera, std::shared_ptr<const SamplingMap> map, int width, int height,
                       std::vector<float> depths)
    : m_camera(std::move(camera)), m_map(std::move(map)), m_width(width), m_height(height), m_depths(std::move(depths)) {
    if (!m_map) m_map = std::make_shared<SamplingMap>(SamplingMap::identity(2, 2));
    if (width < 1 || height < 1 || m_depths.size() != static_cast<std::size_t>(width) * height)
        throw Error(ErrorCode::InvalidArgument, "DepthImage: " + std::to_string(m_depths.size()) + " depths for " +
                                                    std::to_string(width) + "x" + std::to_string(height) + " pixels");
    const auto [lo, hi] = std::minmax_element(m_depths.begin(), m_depths.end());
    for (const float d : m_depths)
        if (!std::isfinite(d)) throw Error(ErrorCode::InvalidArgument, "DepthImage: a depth is not finite");
    m_minDepth = *lo;
    m_maxDepth = *hi;
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
                      file.image.width, file.image.height, std::move(depths));
}

double DepthImage::sampleDepth(glm::dvec2 pd) const {
    const double x = std::clamp(pd.x * m_width - 0.5, 0.0, m_width - 1.0);
    const double y = std::clamp(pd.y * m_height - 0.5, 0.0, m_height - 1.0);
    const int x0 = std::min(static_cast<int>(x), m_width - 1), y0 = std::min(static_cast<int>(y), m_height - 1);
    const int x1 = std::min(x0 + 1, m_width - 1), y1 = std::min(y0 + 1, m_height - 1);
    const double fx = x - x0, fy = y - y0;
    const double top = depthAt(x0, y0) + (depthAt(x1, y0) - depthAt(x0, y0)) * fx;
    const double bottom = depthAt(x0, y1) + (depthAt(x1, y1) - depthAt(x0, y1)) * fx;
    return top + (bottom - top) * fy;
}

double heightToDepth(const Camera& camera, double height) {
    return glm::dot(-camera.eye(), camera.forward()) - height;
}

void checkIntersectOptions(const IntersectOptions& o) {
    if (!(o.stepTexels > 0.0 && o.stepTexels <= 64.0) || o.refinements < 0 || o.refinements > 64 || o.maxSteps < 1 ||
        o.maxSteps > (1 << 20) || !(o.tMax > 0.0))
        throw Error(ErrorCode::InvalidArgument,
                    "intersect: step " + std::to_string(o.stepTexels) + " texels, " + std::to_string(o.refinements) +
                        " refinements, " + std::to_string(o.maxSteps) + " steps, tMax " + std::to_string(o.tMax) +
                        ": want a step in (0, 64], refinements in [0, 64], steps in [1, 2^20], tMax > 0");
}

void checkRay(const Ray& ray) {
    const double length = glm::length(ray.direction);
    if (!std::isfinite(length) || !std::isfinite(glm::length(ray.origin)) || std::abs(length - 1.0) > 1e-6)
        throw Error(ErrorCode::InvalidArgument, "intersect: the ray's origin must be finite and its direction unit (length " +
                                                    std::to_string(length) + ")");
}

std::optional<DepthHit> intersect(const DepthImage& image, const Ray& ray, const IntersectOptions& options) {
    const std::optional<Segment> clipped = clipRay(image, ray, options.tMax);
    if (!clipped) return std::nullopt;
    const Segment& segment = *clipped;
    const SamplingMap& map = image.map();
    const glm::dvec2 size(image.width(), image.height());
    const glm::dvec2 along = segment.p1 - segment.p0;
    // How far the surface lies in front of the ray at s (> 0: the ray is still in front).
    const auto gap = [&](double s, glm::dvec2& pd) {
        pd = map.distort(segment.point(s));
        return image.sampleDepth(pd) - segment.depth(s);
    };

    glm::dvec2 pd;
    double before = 0.0, s = 0.0;
    int steps = 0;
    while (gap(s, pd) > 0.0) {
        if (s >= 1.0 || steps >= options.maxSteps) return std::nullopt;
        // CoNUS pixels the curve covers per unit s here: |J (p1 - p0)| in pixels.
        const double speed = glm::length(map.jacobian(segment.point(s)) * along * size);
        before = s;
        s = std::min(1.0, s + (speed > 0.0 ? options.stepTexels / speed : 1.0));
        ++steps;
    }
    if (steps > 0) {
        double a = before, b = s;
        for (int k = 0; k < options.refinements; ++k) {
            const double m = 0.5 * (a + b);
            (gap(m, pd) > 0.0 ? a : b) = m;
        }
        s = 0.5 * (a + b);
        gap(s, pd);
    }
    DepthHit hit;
    hit.t = segment.t(s);
    hit.position = ray.origin + ray.direction * hit.t;
    hit.depth = segment.depth(s);
    hit.point = segment.point(s);
    hit.distorted = pd;
    hit.texel = glm::clamp(glm::ivec2(glm::floor(pd * size)), glm::ivec2(0), glm::ivec2(size) - 1);
    hit.steps = steps;
    hit.face = steps == 0 ? segment.face : -1;
    return hit;
}

}  // namespace conus::codec
