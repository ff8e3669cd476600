// The planar pinhole camera: two matrices (world -> camera, camera -> NDC) and what they imply.
#include "conus/core/camera.h"

#include <cmath>
#include <cstring>
#include <string>

#include "conus/core/error.h"

namespace conus {
namespace {

[[noreturn]] void invalid(const std::string& what) { throw Error(ErrorCode::InvalidArgument, "camera: " + what); }

glm::dmat4 loadMatrix(const std::array<float, 16>& a, const char* name) {
    glm::mat4 m;
    std::memcpy(&m[0][0], a.data(), sizeof m);  // OpenEXR's row-vector row-major == glm's layout (camera.h)
    for (float x : a)
        if (!std::isfinite(x)) invalid(std::string(name) + " has a non-finite element");
    const glm::dmat4 d(m);
    if (!(std::abs(glm::determinant(d)) > 1e-30)) invalid(std::string(name) + " is singular (no inverse)");
    return d;
}

std::array<float, 16> storeMatrix(const glm::dmat4& d) {
    const glm::mat4 m(d);
    std::array<float, 16> a{};
    std::memcpy(a.data(), &m[0][0], sizeof m);
    return a;
}

// World -> camera for an eye looking at target: rows right, up, forward (left-handed camera space).
glm::dmat4 lookAt(glm::dvec3 eye, glm::dvec3 target, glm::dvec3 up) {
    const glm::dvec3 f = target - eye;
    if (!(glm::length(f) > 0.0) || !std::isfinite(glm::length(f))) invalid("the eye and the target coincide");
    const glm::dvec3 forward = glm::normalize(f);
    const glm::dvec3 side = glm::cross(forward, up);
    if (!(glm::length(side) > 1e-12 * glm::length(up))) invalid("`up` is parallel to the viewing direction");
    const glm::dvec3 right = glm::normalize(side);
    const glm::dvec3 trueUp = glm::cross(right, forward);
    glm::dmat4 c(1.0);
    for (int i = 0; i < 3; ++i) {
        c[i][0] = right[i];
        c[i][1] = trueUp[i];
        c[i][2] = forward[i];
    }
    c[3] = glm::dvec4(-glm::dot(right, eye), -glm::dot(trueUp, eye), -glm::dot(forward, eye), 1.0);
    return c;
}

}  // namespace

Camera::Camera(const glm::dmat4& worldToCamera, const glm::dmat4& cameraToNdc, Projection projection, double near, double far)
    : m_worldToCamera(worldToCamera), m_cameraToWorld(glm::inverse(worldToCamera)), m_cameraToNdc(cameraToNdc),
      m_projection(projection), m_near(near), m_far(far) {}

Camera Camera::perspective(glm::dvec3 eye, glm::dvec3 target, glm::dvec3 up, double fovYDegrees, double aspect,
                           double near, double far) {
    if (!(fovYDegrees > 0.0 && fovYDegrees < 180.0)) invalid("vertical field of view " + std::to_string(fovYDegrees) + " is not in (0, 180) degrees");
    if (!(aspect > 0.0) || !std::isfinite(aspect)) invalid("aspect " + std::to_string(aspect) + " is not positive");
    if (!(near > 0.0 && far > near) || !std::isfinite(far)) invalid("clip distances need 0 < near < far (near " + std::to_string(near) + ", far " + std::to_string(far) + ")");
    const double sy = 0.5 / std::tan(glm::radians(fovYDegrees) / 2.0), sx = sy / aspect;
    // x' = sx x + z/2, y' = -sy y + z/2 (v grows downward), w' = z, so u = x'/w' is in [0,1] across
    // the field of view; z'/w' runs from 0 at near to 1 at far.
    glm::dmat4 k(0.0);
    k[0][0] = sx;
    k[1][1] = -sy;
    k[2][0] = 0.5;
    k[2][1] = 0.5;
    k[2][2] = far / (far - near);
    k[3][2] = -far * near / (far - near);
    k[2][3] = 1.0;
    return Camera(lookAt(eye, target, up), k, Projection::Perspective, near, far);
}

Camera Camera::orthographic(glm::dvec3 eye, glm::dvec3 target, glm::dvec3 up, double height, double aspect, double near,
                            double far) {
    if (!(height > 0.0) || !std::isfinite(height)) invalid("orthographic height " + std::to_string(height) + " is not positive");
    if (!(aspect > 0.0) || !std::isfinite(aspect)) invalid("aspect " + std::to_string(aspect) + " is not positive");
    if (!(far > near) || !std::isfinite(near) || !std::isfinite(far)) invalid("clip depths need near < far");
    glm::dmat4 k(0.0);
    k[0][0] = 1.0 / (height * aspect);
    k[3][0] = 0.5;
    k[1][1] = -1.0 / height;
    k[3][1] = 0.5;
    k[2][2] = 1.0 / (far - near);
    k[3][2] = -near / (far - near);
    k[3][3] = 1.0;
    return Camera(lookAt(eye, target, up), k, Projection::Orthographic, near, far);
}

Camera Camera::fromMatrices(const std::array<float, 16>& worldToCamera, const std::array<float, 16>& worldToNDC,
                            Projection projection) {
    const glm::dmat4 c = loadMatrix(worldToCamera, "worldToCamera");
    const glm::dmat4 n = loadMatrix(worldToNDC, "worldToNDC");
    const glm::dmat4 k = n * glm::inverse(c);
    const bool perspective = std::abs(k[2][3]) > 1e-12;  // w' depends on depth
    if (perspective != (projection == Projection::Perspective))
        invalid(std::string("the matrices describe a ") + enumName(perspective ? Projection::Perspective : Projection::Orthographic) + " camera, not " +
                enumName(projection));
    // The clip depths where z'/w' is 0 and 1, when the matrix maps depth that way; else unbounded.
    double near = perspective ? 0.0 : -1e300, far = 1e300;
    if (perspective && std::abs(k[2][2]) > 1e-12 && k[2][3] > 0) {
        const double a = k[2][2] / k[2][3], b = k[3][2] / k[2][3];  // z'/w' = a + b / depth
        if (a != 0.0 && a != 1.0 && -b / a > 0.0 && b / (1.0 - a) > -b / a) near = -b / a, far = b / (1.0 - a);
    } else if (!perspective && std::abs(k[2][2]) > 1e-300) {
        near = -k[3][2] / k[2][2];
        far = (1.0 - k[3][2]) / k[2][2];
        if (far < near) std::swap(near, far);
    }
    return Camera(c, k, projection, near, far);
}

std::array<float, 16> Camera::worldToCamera() const { return storeMatrix(m_worldToCamera); }
std::array<float, 16> Camera::worldToNDC() const { return storeMatrix(m_cameraToNdc * m_worldToCamera); }

glm::dvec3 Camera::project(glm::dvec3 world) const {
    const glm::dvec4 c = m_worldToCamera * glm::dvec4(world, 1.0);
    const glm::dvec4 n = m_cameraToNdc * c;
    return {n.x / n.w, n.y / n.w, c.z};
}

glm::dvec3 Camera::unproject(glm::dvec2 uv, double depth) const {
    // The camera-space x, y at this depth whose NDC is uv: two linear equations.
    const glm::dvec4 a = m_cameraToNdc[0], b = m_cameraToNdc[1], c = m_cameraToNdc[2] * depth + m_cameraToNdc[3];
    const double a11 = a.x - uv.x * a.w, a12 = b.x - uv.x * b.w, r1 = -(c.x - uv.x * c.w);
    const double a21 = a.y - uv.y * a.w, a22 = b.y - uv.y * b.w, r2 = -(c.y - uv.y * c.w);
    const double det = a11 * a22 - a12 * a21;
    const double x = det != 0.0 ? (r1 * a22 - a12 * r2) / det : 0.0;
    const double y = det != 0.0 ? (a11 * r2 - r1 * a21) / det : 0.0;
    return glm::dvec3(m_cameraToWorld * glm::dvec4(x, y, depth, 1.0));
}

Ray Camera::ray(glm::dvec2 uv) const {
    if (m_projection == Projection::Orthographic) return {unproject(uv, 0.0), forward()};
    const glm::dvec3 origin = eye();
    return {origin, glm::normalize(unproject(uv, 1.0) - origin)};
}

double Camera::verticalFovDegrees() const {
    if (m_projection != Projection::Perspective) return 0.0;
    // v = 1/2 - sy y / z at the top edge v = 0: y / z = 1 / (2 sy) = tan(fov / 2).
    const double sy = -m_cameraToNdc[1][1] / m_cameraToNdc[2][3];
    return sy > 0.0 ? glm::degrees(2.0 * std::atan(0.5 / sy)) : 0.0;
}

glm::dvec3 Camera::eye() const { return glm::dvec3(m_cameraToWorld[3]); }

glm::dvec3 Camera::forward() const { return glm::normalize(glm::dvec3(m_cameraToWorld[2])); }

}  // namespace conus
