// Scenes for the mesh reference's tests: cameras, an FPC with an off-centre focus, a box with flat
// faces, a textured plane, a plane mirror, and the analytic intersections they are checked against.
#pragma once

#include <cmath>
#include <memory>
#include <optional>

#include "conus/codec/builders/foci.h"
#include "conus/codec/depth/reflection.h"
#include "conus/core/fpc.h"
#include "conus/core/mesh.h"
#include "sceneio/test_meshes.h"
#include "test_images.h"

namespace conus::codec::test {

using namespace conus::test;

// An FPC whose map magnifies an off-centre disc (asymmetric on purpose).
inline std::shared_ptr<const SamplingMap> focusMap(double u, double v, double r, double k, double aspect) {
    FociOptions options;
    options.aspect = aspect;
    const Focus focus{u, v, r, k};
    return std::make_shared<SamplingMap>(buildFociMap(std::span<const Focus>(&focus, 1), options));
}

// A box [lo, hi] with four vertices a face, so every vertex normal is its face's normal.
inline Mesh flatBox(glm::vec3 lo, glm::vec3 hi) {
    const Mesh shared = sharedBox(lo, hi);
    Mesh m;
    for (std::size_t t = 0; t < shared.indices.size(); t += 6) {
        const std::uint32_t q[4] = {shared.indices[t], shared.indices[t + 1], shared.indices[t + 2], shared.indices[t + 5]};
        const std::uint32_t base = std::uint32_t(m.positions.size());
        const glm::vec3 n = glm::normalize(glm::cross(shared.positions[q[1]] - shared.positions[q[0]],
                                                      shared.positions[q[2]] - shared.positions[q[0]]));
        for (std::uint32_t k : q) {
            m.positions.push_back(shared.positions[k]);
            m.normals.push_back(n);
        }
        m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    }
    return m;
}

// A horizontal square at height y, half side `half`, normal +y, with UVs 0..`repeat` across it and
// `texture` (a detailed grey texture) when given.
inline Mesh plane(float y, float half, float repeat = 1, std::optional<Image> texture = std::nullopt) {
    Mesh m;
    m.positions = {{-half, y, -half}, {-half, y, half}, {half, y, half}, {half, y, -half}};
    m.normals.assign(4, glm::vec3(0, 1, 0));
    m.indices = {0, 1, 2, 0, 2, 3};
    if (texture) {
        m.uvs = {{0, 0}, {0, repeat}, {repeat, repeat}, {repeat, 0}};
        m.texture = std::move(texture);
    }
    return m;
}

// The reflection tests' scene: a flat box [lo, hi] with a colour ramp across it (so a misplaced hit
// shows; its 12 triangles first) above a grey floor at y = -1, half side 4.
inline Mesh rampedBoxAndFloor(glm::vec3 lo, glm::vec3 hi) {
    Mesh scene = flatBox(lo, hi);
    const Mesh floor = plane(-1.0f, 4.0f);
    const auto base = static_cast<std::uint32_t>(scene.positions.size());
    scene.positions.insert(scene.positions.end(), floor.positions.begin(), floor.positions.end());
    scene.normals.insert(scene.normals.end(), floor.normals.begin(), floor.normals.end());
    for (std::uint32_t i : floor.indices) scene.indices.push_back(base + i);
    scene.colours.assign(scene.positions.size(), glm::vec3(0.8f));
    for (std::size_t i = 0; i < base; ++i) {
        const glm::vec3 f = (scene.positions[i] - lo) / (hi - lo);
        scene.colours[i] = glm::vec3(f.x, 0.3f, f.z);
    }
    return scene;
}

// The layered reflection tests' scene: an occluding box before a wall (a slab), both off the
// axes, seen from the origin along +z; a colour ramp across both (the box bluish, the wall
// yellowish) so that a hit on the wrong one shows.
inline const glm::dvec3 kOccluderLo(-0.35, -0.25, 1.6), kOccluderHi(0.25, 0.3, 2.0);
inline const glm::dvec3 kWallLo(-3.0, -2.5, 3.0), kWallHi(3.2, 2.8, 3.3);
inline Mesh boxBeforeWall() {
    Mesh m = flatBox(glm::vec3(kOccluderLo), glm::vec3(kOccluderHi));
    const Mesh wall = flatBox(glm::vec3(kWallLo), glm::vec3(kWallHi));
    const auto base = static_cast<std::uint32_t>(m.positions.size());
    m.positions.insert(m.positions.end(), wall.positions.begin(), wall.positions.end());
    m.normals.insert(m.normals.end(), wall.normals.begin(), wall.normals.end());
    for (std::uint32_t i : wall.indices) m.indices.push_back(base + i);
    for (std::size_t i = 0; i < m.positions.size(); ++i) {
        const glm::vec3 p = m.positions[i];
        m.colours.emplace_back(0.5f + 0.15f * p.x, 0.5f + 0.15f * p.y, i < base ? 0.8f : 0.2f);
    }
    return m;
}

// Ray-sphere: the nearest t >= 0 along a unit-direction ray, if it meets the sphere.
inline std::optional<double> hitSphere(const Ray& ray, glm::dvec3 centre, double radius) {
    const glm::dvec3 oc = ray.origin - centre;
    const double b = glm::dot(oc, ray.direction), c = glm::dot(oc, oc) - radius * radius;
    const double disc = b * b - c;
    if (disc < 0) return std::nullopt;
    const double t = -b - std::sqrt(disc);
    if (t >= 0) return t;
    return std::nullopt;
}

// Distance from the sphere's centre to the ray's line.
inline double rayDistance(const Ray& ray, glm::dvec3 centre) {
    const glm::dvec3 oc = centre - ray.origin;
    return glm::length(oc - ray.direction * glm::dot(oc, ray.direction));
}

// Ray-box (slabs): entry t and the axis entered through, if the ray meets the box in front.
struct BoxHit {
    double t;
    int axis;
};
inline std::optional<BoxHit> hitBox(const Ray& ray, glm::dvec3 lo, glm::dvec3 hi) {
    double tEnter = -1e300, tExit = 1e300;
    int axis = -1;
    for (int a = 0; a < 3; ++a) {
        if (ray.direction[a] == 0) {
            if (ray.origin[a] < lo[a] || ray.origin[a] > hi[a]) return std::nullopt;
            continue;
        }
        double t0 = (lo[a] - ray.origin[a]) / ray.direction[a], t1 = (hi[a] - ray.origin[a]) / ray.direction[a];
        if (t0 > t1) std::swap(t0, t1);
        if (t0 > tEnter) {
            tEnter = t0;
            axis = a;
        }
        tExit = std::min(tExit, t1);
    }
    if (tEnter > tExit || tEnter < 0) return std::nullopt;
    return BoxHit{tEnter, axis};
}

// A square plane mirror z = 0 facing +z, centred on the origin, of half side `halfSide`.
inline Reflector planeMirrorZ(double halfSide) {
    Reflector r;
    r.kind = Reflector::Kind::Plane;
    r.centre = {0.0, 0.0, 0.0};
    r.normal = {0.0, 0.0, 1.0};
    r.radius = halfSide;
    return r;
}

}  // namespace conus::codec::test
