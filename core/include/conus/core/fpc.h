// The flexible pinhole camera of the paper (section 3.1): a planar pinhole camera (camera.h) plus
// a distortion of its image plane, the sampling map. A 3-D point projects through the camera and
// then through Equation 1; a CoNUS pixel unprojects through the map's exact inverse and then the
// camera's ray. The depth is the camera's: the map moves image positions, never depths.
#pragma once

#include <memory>

#include <glm/glm.hpp>

#include "conus/core/camera.h"

namespace conus {

// A one-to-one map of the image plane [0,1]^2 onto itself, each edge onto itself: the sampling
// map's Equation 1 (`distort`, undistorted -> distorted) and its exact inverse. codec's
// SamplingMap is the grid one; an analytic map may be another.
class Distortion {
public:
    virtual ~Distortion() = default;
    virtual glm::dvec2 distort(glm::dvec2 p) const = 0;
    virtual glm::dvec2 undistort(glm::dvec2 pd) const = 0;
    // d distort / d p at undistorted p (column 0 is d/du, column 1 d/dv).
    virtual glm::dmat2 jacobian(glm::dvec2 p) const = 0;
};

class Fpc {
public:
    // `distortion` null: the identity (a conventional camera).
    Fpc(Camera camera, std::shared_ptr<const Distortion> distortion);

    const Camera& camera() const { return m_camera; }
    const Distortion* distortion() const { return m_distortion.get(); }

    // World -> (u_d, v_d, depth): the camera's projection, then Equation 1.
    glm::dvec3 project(glm::dvec3 world) const;
    // The world point under distorted image position pd at `depth`.
    glm::dvec3 unproject(glm::dvec2 pd, double depth) const;
    // The CoNUS ray through distorted image position pd.
    Ray ray(glm::dvec2 pd) const;

private:
    Camera m_camera;
    std::shared_ptr<const Distortion> m_distortion;
};

}  // namespace conus
