// Shared by the intersection tests (codec: analytic; renderers: CPU == GLSL): depth images of
// surfaces known in closed form, sampled through a map the way an encoder samples them (each
// CoNUS pixel centre undistorted, its ray cast at the true surface), and that surface's own
// intersection for comparison.
#pragma once

#include <cmath>
#include <functional>
#include <memory>
#include <optional>
#include <random>
#include <vector>

#include "conus/codec/builders/foci.h"
#include "conus/codec/depth/intersect.h"
#include "conus/codec/depth/relief.h"
#include "conus/core/map_rules.h"

namespace conus::codec::test {

// A relief box over x, z in [0,1] (world), heights along +y, seen from straight above: u = x, v = z.
inline Camera reliefCamera() { return codec::reliefCamera({1.0, 1.0}, 2.0); }

// A perspective view of a sphere in front of a wall (the reflection case: depth along the axis).
inline Camera sphereCamera() { return Camera::perspective({0.0, 0.0, -5.0}, {0.0, 0.0, 0.0}, {0, 1, 0}, 40.0, 1.0, 0.5, 20.0); }
inline constexpr double kWallZ = 2.0;
inline const glm::dvec3 kSphereCentre{0.2, -0.1, 0.0};
inline constexpr double kSphereRadius = 1.0;

using HeightFn = std::function<double(double x, double z)>;

inline std::shared_ptr<const SamplingMap> identityMap() { return std::make_shared<SamplingMap>(SamplingMap::identity(2, 2)); }
// Magnifies a disc around (u, v) k times (a CoNUS map).
inline std::shared_ptr<const SamplingMap> focusMap(double u, double v, double r = 0.15, double k = 4.0) {
    const Focus focus{u, v, r, k};
    FociOptions options;
    options.columns = options.rows = map_rules::kDefaultSide;
    return std::make_shared<SamplingMap>(buildFociMap(std::span<const Focus>(&focus, 1), options));
}

inline DepthImage heightImage(const HeightFn& height, std::shared_ptr<const SamplingMap> map, int size) {
    const Camera camera = reliefCamera();
    std::vector<float> depths(static_cast<std::size_t>(size) * size);
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const glm::dvec2 p = map->undistort({(x + 0.5) / size, (y + 0.5) / size});
            depths[static_cast<std::size_t>(y) * size + x] = static_cast<float>(heightToDepth(camera, height(p.x, p.y)));
        }
    return DepthImage(camera, std::move(map), size, size, std::move(depths));
}

// Where a ray meets the sphere or the wall behind it (nearest positive t).
inline std::optional<double> sphereSceneHit(const Ray& ray) {
    std::optional<double> best;
    const glm::dvec3 oc = ray.origin - kSphereCentre;
    const double b = glm::dot(oc, ray.direction), c = glm::dot(oc, oc) - kSphereRadius * kSphereRadius;
    const double disc = b * b - c;
    if (disc >= 0.0) {
        const double t = -b - std::sqrt(disc);
        if (t > 0.0) best = t;
    }
    if (!best && ray.direction.z > 0.0) {
        const double t = (kWallZ - ray.origin.z) / ray.direction.z;
        if (t > 0.0) best = t;
    }
    return best;
}

inline DepthImage sphereImage(std::shared_ptr<const SamplingMap> map, int size) {
    const Camera camera = sphereCamera();
    std::vector<float> depths(static_cast<std::size_t>(size) * size);
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const glm::dvec2 p = map->undistort({(x + 0.5) / size, (y + 0.5) / size});
            const Ray ray = camera.ray(p);
            const double t = sphereSceneHit(ray).value();  // the wall fills the whole view
            depths[static_cast<std::size_t>(y) * size + x] =
                static_cast<float>(glm::dot(ray.origin + ray.direction * t - camera.eye(), camera.forward()));
        }
    return DepthImage(camera, std::move(map), size, size, std::move(depths));
}

// A thin board (|x| <= kBoardHalf, |y| <= 2, in the plane z = 0, facing the camera) in front of the
// wall z = kWallZ, seen by sphereCamera: the silhouette case of a depth image of a scene.
inline constexpr double kBoardHalf = 0.04;

inline std::optional<double> boardSceneHit(const Ray& ray) {
    if (ray.direction.z != 0.0) {
        const double t = -ray.origin.z / ray.direction.z;
        const glm::dvec3 p = ray.origin + ray.direction * t;
        if (t > 0.0 && std::abs(p.x) <= kBoardHalf && std::abs(p.y) <= 2.0) return t;
    }
    if (ray.direction.z > 0.0) return (kWallZ - ray.origin.z) / ray.direction.z;
    return std::nullopt;
}

// The board scene's camera depths through `map`; `solid` as DepthImage takes it (a scene: false).
inline DepthImage boardImage(std::shared_ptr<const SamplingMap> map, int size, bool solid = false) {
    const Camera camera = sphereCamera();
    std::vector<float> depths(static_cast<std::size_t>(size) * size);
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const Ray ray = camera.ray(map->undistort({(x + 0.5) / size, (y + 0.5) / size}));
            const double t = boardSceneHit(ray).value();
            depths[static_cast<std::size_t>(y) * size + x] =
                static_cast<float>(glm::dot(ray.origin + ray.direction * t - camera.eye(), camera.forward()));
        }
    return DepthImage(camera, std::move(map), size, size, std::move(depths), solid);
}

// A scene's image that saw nothing but a square of wall at depth 6 in its middle: every other
// texel holds the far plane (20), as a mesh render stores what it did not see.
inline DepthImage skyImage(std::shared_ptr<const SamplingMap> map, int size) {
    const Camera camera = sphereCamera();
    std::vector<float> depths(static_cast<std::size_t>(size) * size, static_cast<float>(camera.far()));
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const glm::dvec2 uv = map->undistort({(x + 0.5) / size, (y + 0.5) / size});
            if (std::abs(uv.x - 0.5) < 0.15 && std::abs(uv.y - 0.5) < 0.15) depths[static_cast<std::size_t>(y) * size + x] = 6.0f;
        }
    return DepthImage(camera, std::move(map), size, size, std::move(depths), false);
}

// Rays that enter skyImage's frustum through its side a little past the far plane (within a jump
// of it) and go on away from the eye.
inline std::vector<Ray> raysPastTheFarPlane() {
    std::vector<Ray> rays;
    for (int i = 0; i < 24; ++i) {
        const double depth = 20.1 + 0.03 * i, y = -3.0 + 0.25 * i;  // the eye is at z = -5, looking along +z
        rays.push_back({{12.0, y, -5.0 + depth}, glm::normalize(glm::dvec3(-1.0, 0.0, 0.02))});
    }
    return rays;
}

// A ray from `from` toward `to`.
inline Ray rayThrough(glm::dvec3 from, glm::dvec3 to) { return {from, glm::normalize(to - from)}; }

// A steep plane of heights, and rays from above toward points on it within half a texel of a
// side (or a corner) of a height image `size` texels a side: between the last texel centres and
// the side, where the surface goes on at its last step.
inline double steepPlane(double x, double z) { return 0.3 + 0.5 * x - 0.4 * z; }
// Points a from a side (a inside the strip) and b along it: on each of the four sides and a corner.
inline std::vector<glm::dvec2> sideStripPoints(double a, double b) {
    return {{a, b}, {1.0 - a, b}, {b, a}, {b, 1.0 - a}, {a, 1.0 - a}};
}
inline std::vector<Ray> raysIntoTheSideStrips(int size, unsigned seed, int count) {
    const double strip = 0.5 / size;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> inStrip(0.05 * strip, 0.95 * strip), along(0.05, 0.95), tilt(-0.4, 0.4);
    std::vector<Ray> rays;
    while (static_cast<int>(rays.size()) < count) {
        const double a = inStrip(rng), b = along(rng);
        for (const glm::dvec2 t : sideStripPoints(a, b)) {
            const glm::dvec3 target(t.x, steepPlane(t.x, t.y), t.y);
            rays.push_back(rayThrough(target + glm::dvec3(tilt(rng), 1.2, tilt(rng)), target));
        }
    }
    return rays;
}

// A wall tilted toward sphereCamera, filling its view, as a scene's image (not solid): the same
// strips seen in perspective, where a plane's 1/depth is affine in the image.
inline const glm::dvec3 kTiltedWallPoint{0.0, 0.0, 2.0};
inline glm::dvec3 tiltedWallNormal() { return glm::normalize(glm::dvec3(0.3, 0.4, -1.0)); }
inline std::optional<double> tiltedWallHit(const Ray& ray) {
    const double facing = glm::dot(ray.direction, tiltedWallNormal());
    if (facing == 0.0) return std::nullopt;
    const double t = glm::dot(kTiltedWallPoint - ray.origin, tiltedWallNormal()) / facing;
    return t > 0.0 ? std::optional<double>(t) : std::nullopt;
}
inline DepthImage tiltedWallImage(std::shared_ptr<const SamplingMap> map, int size) {
    const Camera camera = sphereCamera();
    std::vector<float> depths(static_cast<std::size_t>(size) * size);
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const Ray ray = camera.ray(map->undistort({(x + 0.5) / size, (y + 0.5) / size}));
            const glm::dvec3 p = ray.origin + ray.direction * tiltedWallHit(ray).value();
            const double depth = glm::dot(p - camera.eye(), camera.forward());
            depths[static_cast<std::size_t>(y) * size + x] = static_cast<float>(depth);
        }
    return DepthImage(camera, std::move(map), size, size, std::move(depths), false);
}
// Rays from inside sphereCamera's view toward the wall where the image shows it within half a
// texel of a side (or a corner).
inline std::vector<Ray> raysIntoTheWallsSideStrips(int size, unsigned seed, int count) {
    const double strip = 0.5 / size;
    const Camera camera = sphereCamera();
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> inStrip(0.05 * strip, 0.95 * strip), along(0.05, 0.95);
    std::uniform_real_distribution<double> jitter(-0.1, 0.1);
    std::vector<Ray> rays;
    while (static_cast<int>(rays.size()) < count)
        for (const glm::dvec2 uv : sideStripPoints(inStrip(rng), along(rng))) {
            const Ray sight = camera.ray(uv);
            const glm::dvec3 target = sight.origin + sight.direction * tiltedWallHit(sight).value();
            rays.push_back(rayThrough({0.3 + jitter(rng), 0.2 + jitter(rng), -3.5}, target));
        }
    return rays;
}

// The first t where the ray is at or below height(x, z) inside the unit box (heights in [0, top]):
// dense marching on the true function, then bisection.
inline std::optional<double> heightFieldHit(const HeightFn& height, const Ray& ray, double tFar = 6.0) {
    const auto below = [&](double t) {
        const glm::dvec3 q = ray.origin + ray.direction * t;
        if (q.x < 0 || q.x > 1 || q.z < 0 || q.z > 1) return false;
        return q.y <= height(q.x, q.z);
    };
    const double dt = 1e-4;
    for (double t = 0.0; t < tFar; t += dt)
        if (below(t)) {
            double a = t - dt, b = t;
            for (int k = 0; k < 40; ++k) (below(0.5 * (a + b)) ? b : a) = 0.5 * (a + b);
            return 0.5 * (a + b);
        }
    return std::nullopt;
}

}  // namespace conus::codec::test
