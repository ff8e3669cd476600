// The 3-D modes of conus-view (--mesh, --volume, --relief, --reflection) as pure interaction state,
// without GL: an orbiting camera around the scene, the foci of the flexible pinhole camera (paper
// sections 3.1 and 6), and whether the frame is CoNUS or conventional. Each frame the window renders
// the scene through camera() and map() (scene.h) and shows the CoNUS image itself: the paper's
// focus-plus-context display. The map is rebuilt from the foci in closed form
// (codec/builders/frame_foci.h) whenever they move, so dragging a focus is live.
//
// Image coordinates are the displayed CoNUS image's normalized (u_d, v_d), v down.
#pragma once

#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "conus/codec/builders/foci.h"
#include "conus/codec/map/sampling_map.h"
#include "conus/core/camera.h"
#include "conus/core/image.h"
#include "conus/format/container.h"

namespace conus::viewer {

inline constexpr double kOrbitStepDegrees = 10.0;   // an arrow key
inline constexpr double kOrbitDegreesPerPixel = 0.4;  // a left drag away from the foci
inline constexpr double kDollyStep = 1.25;          // + / -; the wheel dollies by kWheelStep a notch
inline constexpr double kMaxPitchDegrees = 89.0;
inline constexpr double kFocusGrabRadius = 0.06;    // a press this near a focus centre (in widths) drags it
inline constexpr int kMaxSceneFoci = 8;
inline constexpr double kDefaultFocusRadius = 0.12, kDefaultFocusK = 3.0;

// A camera on a sphere around `target`: yaw about the world's up (+y), pitch above the horizon.
struct Orbit {
    glm::dvec3 target{0.0};
    double distance = 3.0;
    double yawDegrees = 30.0, pitchDegrees = 20.0;
    double fovYDegrees = 40.0;
    glm::dvec3 eye() const;
};

class SceneState {
public:
    // A scene whose content lies within `radius` of `centre`; `home` is where F returns (a camera
    // looking at centre from the front right, framing the sphere, when none is given).
    SceneState(glm::dvec3 centre, double radius, std::vector<codec::Focus> foci, std::optional<Orbit> home = std::nullopt);

    const Orbit& orbit() const { return m_orbit; }
    // The camera of a frame with this aspect (width / height); near and far enclose the scene's sphere.
    Camera camera(double aspect) const;
    // The frame's sampling map: the foci's closed-form map, or the identity when conventional (or no foci).
    codec::SamplingMap map(double aspect) const;

    void rotate(double yawDegrees, double pitchDegrees);
    void dolly(double factor);  // distance *= factor, within [radius / 4, 50 radius]
    void home();

    bool conus() const { return m_conus; }
    void toggleConus() { m_conus = !m_conus; ++m_version; }

    const std::vector<codec::Focus>& foci() const { return m_foci; }
    // The focus whose centre is within kFocusGrabRadius (widths) of `uv` (nearest first), or -1.
    int focusNear(glm::dvec2 uv, double aspect) const;
    // Moves focus i to uv (kept inside the image). The lens of frame_foci leaves its own centre
    // where it is, so the focus stays under the cursor that drags it.
    void moveFocus(int i, glm::dvec2 uv);
    // Adds a focus of the default size at uv (false when kMaxSceneFoci are there already).
    bool addFocus(glm::dvec2 uv);
    // Removes the focus nearest uv (any distance); false when there is none.
    bool removeFocusNear(glm::dvec2 uv, double aspect);
    // Scales every focus's radius (within (0.02, 0.5)).
    void scaleFocusRadius(double factor);

    // Moves whenever a frame would look different: the window renders again then.
    int version() const { return m_version; }

private:
    glm::dvec3 m_centre;
    double m_radius;
    Orbit m_home, m_orbit;
    std::vector<codec::Focus> m_foci;
    bool m_conus = true;
    int m_version = 0;
};

// The sphere the orbit turns about, for a set of points: the centre of their bounding box and half
// its diagonal (at least 1e-6).
struct BoundingSphere {
    glm::dvec3 centre{0.0};
    double radius = 1.0;
};
BoundingSphere boundingSphere(const std::vector<glm::dvec3>& points);

// A rendered frame as the CoNUS file the viewer shows and probes: a depth image with the camera
// when the image has Z (codec::makeDepthImageFile), else an image file; the foci recorded as the
// analytic map (the outlines of O); give no foci for a conventional frame.
format::ConusFile sceneFrameFile(Image image, const codec::SamplingMap& map, const Camera& camera,
                                 const std::vector<codec::Focus>& foci);

}  // namespace conus::viewer
