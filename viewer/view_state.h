// Navigation of conus-view as pure math (no GL, no GLFW), so it is unit-tested: which rectangle of
// the undistorted image plane a window shows, and how wheel, drag and keys change it the way tev
// users expect (zoom about the cursor with no drift, drag pans, fit, 1:1 source resolution).
//
// Window coordinates are framebuffer pixels, x right, y down, (0,0) the top-left corner of the
// window (pixel (x,y) covers [x,x+1) x [y,y+1)). Image coordinates are spec/'s normalized (u,v).
// The zoom is window pixels per source pixel (1 = "1:1"), isotropic: source pixels stay square.
#pragma once

#include <cmath>

#include <glm/glm.hpp>

#include "conus/codec/image/decode.h"

namespace conus::viewer {

inline constexpr double kMaxZoom = 256.0;        // window pixels per source pixel
inline constexpr double kMinZoomOfFit = 1.0 / 16; // the smallest zoom, as a fraction of the fit
inline constexpr double kWheelStep = 1.18920711500272106672;  // 2^(1/4) per wheel notch
inline constexpr double kKeyZoomStep = 2.0;
inline constexpr double kKeyPanFraction = 0.125;  // arrow keys pan by this much of the window

class ViewState {
public:
    ViewState() = default;
    // Fits the image into the window.
    ViewState(int windowWidth, int windowHeight, int imageWidth, int imageHeight);

    // Keeps the image point at the window centre and the zoom (a resized tev window does too).
    void setWindowSize(int width, int height);
    // A new image (source pixels): fits it.
    void setImageSize(int width, int height);

    int windowWidth() const { return m_windowWidth; }
    int windowHeight() const { return m_windowHeight; }
    double zoom() const { return m_zoom; }
    glm::dvec2 center() const { return m_center; }  // image point at the window centre
    // The undistorted rectangle the window shows (u0,v0 at the window's top-left corner).
    codec::View view() const;

    glm::dvec2 windowToImage(glm::dvec2 window) const;
    glm::dvec2 imageToWindow(glm::dvec2 image) const;

    // Multiplies the zoom by `factor` (clamped to [minZoom, kMaxZoom]) keeping the image point
    // under `window` where it is.
    void zoomAbout(double factor, glm::dvec2 window);
    // Wheel notches (positive zooms in) about the cursor.
    void scroll(double notches, glm::dvec2 window) { zoomAbout(std::pow(kWheelStep, notches), window); }
    // The content follows the mouse: the image moves by `delta` window pixels. The window centre
    // stays over the image (the image never leaves the window entirely).
    void pan(glm::dvec2 delta);
    // The whole image, centred, as large as fits.
    void fit();
    // 1 source pixel = 1 window pixel, about the window centre.
    void sourceResolution();
    // Shows `view` (an undistorted rectangle) as large as fits, centred on it.
    void showView(const codec::View& view);

    double fitZoom() const;
    double minZoom() const;

private:
    void clampCenter();
    int m_windowWidth = 1, m_windowHeight = 1;
    int m_imageWidth = 1, m_imageHeight = 1;
    double m_zoom = 1.0;
    glm::dvec2 m_center{0.5, 0.5};
};

}  // namespace conus::viewer
