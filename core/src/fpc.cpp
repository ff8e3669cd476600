#include "conus/core/fpc.h"

namespace conus {

Fpc::Fpc(Camera camera, std::shared_ptr<const Distortion> distortion)
    : m_camera(std::move(camera)), m_distortion(std::move(distortion)) {}

glm::dvec3 Fpc::project(glm::dvec3 world) const {
    const glm::dvec3 p = m_camera.project(world);
    if (!m_distortion) return p;
    const glm::dvec2 pd = m_distortion->distort({p.x, p.y});
    return {pd.x, pd.y, p.z};
}

glm::dvec3 Fpc::unproject(glm::dvec2 pd, double depth) const {
    return m_camera.unproject(m_distortion ? m_distortion->undistort(pd) : pd, depth);
}

Ray Fpc::ray(glm::dvec2 pd) const { return m_camera.ray(m_distortion ? m_distortion->undistort(pd) : pd); }

}  // namespace conus
