#include "view_state.h"

#include <algorithm>
#include <cmath>

namespace conus::viewer {

ViewState::ViewState(int windowWidth, int windowHeight, int imageWidth, int imageHeight)
    : m_windowWidth(std::max(1, windowWidth)), m_windowHeight(std::max(1, windowHeight)),
      m_imageWidth(std::max(1, imageWidth)), m_imageHeight(std::max(1, imageHeight)) {
    fit();
}

void ViewState::setWindowSize(int width, int height) {
    m_windowWidth = std::max(1, width);
    m_windowHeight = std::max(1, height);
    m_zoom = std::clamp(m_zoom, minZoom(), kMaxZoom);
}

void ViewState::setImageSize(int width, int height) {
    m_imageWidth = std::max(1, width);
    m_imageHeight = std::max(1, height);
    fit();
}

double ViewState::fitZoom() const {
    return std::min(double(m_windowWidth) / m_imageWidth, double(m_windowHeight) / m_imageHeight);
}

// Small images may be fitted above kMaxZoom's reach; the minimum never exceeds the maximum.
double ViewState::minZoom() const { return std::min(fitZoom() * kMinZoomOfFit, kMaxZoom); }

codec::View ViewState::view() const {
    const glm::dvec2 topLeft = windowToImage({0.0, 0.0});
    const glm::dvec2 bottomRight = windowToImage({double(m_windowWidth), double(m_windowHeight)});
    return {topLeft.x, topLeft.y, bottomRight.x, bottomRight.y};
}

glm::dvec2 ViewState::windowToImage(glm::dvec2 window) const {
    const glm::dvec2 offset = window - 0.5 * glm::dvec2(m_windowWidth, m_windowHeight);
    return m_center + offset / (m_zoom * glm::dvec2(m_imageWidth, m_imageHeight));
}

glm::dvec2 ViewState::imageToWindow(glm::dvec2 image) const {
    return 0.5 * glm::dvec2(m_windowWidth, m_windowHeight) +
           (image - m_center) * (m_zoom * glm::dvec2(m_imageWidth, m_imageHeight));
}

void ViewState::zoomAbout(double factor, glm::dvec2 window) {
    if (!(factor > 0.0) || !std::isfinite(factor)) return;
    const glm::dvec2 anchor = windowToImage(window);
    const double zoom = std::clamp(m_zoom * factor, minZoom(), kMaxZoom);
    // Solve for the centre that puts `anchor` back under `window` at the new zoom: the cursor's
    // point is fixed exactly (up to rounding), and no clamping of the centre follows, which would
    // make it drift.
    const double ratio = m_zoom / zoom;
    m_center = anchor + (m_center - anchor) * ratio;
    m_zoom = zoom;
}

void ViewState::pan(glm::dvec2 delta) {
    m_center -= delta / (m_zoom * glm::dvec2(m_imageWidth, m_imageHeight));
    clampCenter();
}

void ViewState::fit() {
    m_zoom = fitZoom();
    m_center = {0.5, 0.5};
}

void ViewState::sourceResolution() { m_zoom = std::clamp(1.0, minZoom(), kMaxZoom); }

void ViewState::showView(const codec::View& view) {
    const double w = std::abs(view.u1 - view.u0) * m_imageWidth, h = std::abs(view.v1 - view.v0) * m_imageHeight;
    if (!(w > 0.0) || !(h > 0.0)) return;
    m_zoom = std::clamp(std::min(m_windowWidth / w, m_windowHeight / h), minZoom(), kMaxZoom);
    m_center = {0.5 * (view.u0 + view.u1), 0.5 * (view.v0 + view.v1)};
}

void ViewState::clampCenter() {
    m_center = glm::clamp(m_center, glm::dvec2(0.0), glm::dvec2(1.0));
}

}  // namespace conus::viewer
