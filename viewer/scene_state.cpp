#include "scene_state.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "conus/codec/builders/frame_foci.h"
#include "conus/codec/conus_file.h"
#include "conus/core/bounds.h"

namespace conus::viewer {
namespace {

constexpr double kDegrees = std::numbers::pi / 180.0;
constexpr double kFocusMargin = 0.02;  // a focus centre stays this far inside the image
constexpr double kMinFocusRadius = 0.02, kMaxFocusRadius = 0.5;

double widthDistance(glm::dvec2 a, glm::dvec2 b, double aspect) {
    return std::hypot(a.x - b.x, (a.y - b.y) / aspect);  // v in widths: circles are round in pixels
}

}  // namespace

glm::dvec3 Orbit::eye() const {
    const double yaw = yawDegrees * kDegrees, pitch = pitchDegrees * kDegrees;
    return target + distance * glm::dvec3(std::cos(pitch) * std::sin(yaw), std::sin(pitch), std::cos(pitch) * std::cos(yaw));
}

SceneState::SceneState(glm::dvec3 centre, double radius, std::vector<codec::Focus> foci, std::optional<Orbit> home)
    : m_centre(centre), m_radius(radius > 0 && std::isfinite(radius) ? radius : 1.0), m_foci(std::move(foci)) {
    if (home) {
        m_home = *home;
    } else {
        m_home.target = centre;
        // The sphere fills about 80% of the vertical field of view.
        m_home.distance = m_radius / std::sin(0.4 * m_home.fovYDegrees * kDegrees);
    }
    if (m_foci.size() > kMaxSceneFoci) m_foci.resize(kMaxSceneFoci);
    m_orbit = m_home;
}

Camera SceneState::camera(double aspect) const {
    const double reach = glm::length(m_orbit.eye() - m_centre) + m_radius;
    const double near = std::max(1e-3 * reach, glm::length(m_orbit.eye() - m_centre) - 1.5 * m_radius);
    return Camera::perspective(m_orbit.eye(), m_orbit.target, {0, 1, 0}, m_orbit.fovYDegrees, aspect, near, 1.5 * reach);
}

codec::SamplingMap SceneState::map(double aspect) const {
    if (!m_conus || m_foci.empty()) return codec::SamplingMap::identity(2, 2);
    codec::FociOptions options;
    options.aspect = aspect;
    return codec::buildFrameFociMap(m_foci, options);
}

void SceneState::rotate(double yawDegrees, double pitchDegrees) {
    m_orbit.yawDegrees = std::remainder(m_orbit.yawDegrees + yawDegrees, 360.0);
    m_orbit.pitchDegrees = std::clamp(m_orbit.pitchDegrees + pitchDegrees, -kMaxPitchDegrees, kMaxPitchDegrees);
    ++m_version;
}

void SceneState::dolly(double factor) {
    m_orbit.distance = std::clamp(m_orbit.distance * factor, 0.25 * m_radius, 50.0 * m_radius);
    ++m_version;
}

void SceneState::home() {
    m_orbit = m_home;
    ++m_version;
}

int SceneState::focusNear(glm::dvec2 uv, double aspect) const {
    int best = -1;
    double bestDistance = kFocusGrabRadius;
    for (std::size_t i = 0; i < m_foci.size(); ++i) {
        const double d = widthDistance(uv, {m_foci[i].u, m_foci[i].v}, aspect);
        if (d <= bestDistance) {
            bestDistance = d;
            best = static_cast<int>(i);
        }
    }
    return best;
}

void SceneState::moveFocus(int i, glm::dvec2 uv) {
    if (i < 0 || i >= static_cast<int>(m_foci.size())) return;
    m_foci[i].u = std::clamp(uv.x, kFocusMargin, 1 - kFocusMargin);
    m_foci[i].v = std::clamp(uv.y, kFocusMargin, 1 - kFocusMargin);
    ++m_version;
}

bool SceneState::addFocus(glm::dvec2 uv) {
    if (m_foci.size() >= kMaxSceneFoci) return false;
    m_foci.push_back({std::clamp(uv.x, kFocusMargin, 1 - kFocusMargin), std::clamp(uv.y, kFocusMargin, 1 - kFocusMargin),
                      kDefaultFocusRadius, kDefaultFocusK});
    ++m_version;
    return true;
}

bool SceneState::removeFocusNear(glm::dvec2 uv, double aspect) {
    if (m_foci.empty()) return false;
    const auto nearest = std::min_element(m_foci.begin(), m_foci.end(), [&](const codec::Focus& a, const codec::Focus& b) {
        return widthDistance(uv, {a.u, a.v}, aspect) < widthDistance(uv, {b.u, b.v}, aspect);
    });
    m_foci.erase(nearest);
    ++m_version;
    return true;
}

void SceneState::scaleFocusRadius(double factor) {
    for (codec::Focus& f : m_foci) f.r = std::clamp(f.r * factor, kMinFocusRadius, kMaxFocusRadius);
    ++m_version;
}

BoundingSphere boundingSphere(const std::vector<glm::dvec3>& points) {
    if (points.empty()) return {};
    const AxisBox box = boundsOf(std::span<const glm::dvec3>(points));
    return {box.centre(), std::max(1e-6, 0.5 * glm::length(box.hi - box.lo))};
}

format::ConusFile sceneFrameFile(Image image, const codec::SamplingMap& map, const Camera& camera,
                                 const std::vector<codec::Focus>& foci) {
    std::optional<format::AnalyticMap> analytic;
    if (!foci.empty()) {
        analytic.emplace();
        analytic->kind = enumName(format::MapKind::Foci);
        analytic->composition = enumName(format::FociComposition::Add);
        for (const codec::Focus& f : foci) analytic->foci.push_back({f.u, f.v, f.r, f.k});
    }
    if (image.channelIndex("Z") >= 0) return codec::makeDepthImageFile(std::move(image), map, camera, "world", std::move(analytic));
    const int width = image.width, height = image.height;
    return codec::makeImageFile(std::move(image), map, width, height, {}, std::move(analytic));
}

}  // namespace conus::viewer
