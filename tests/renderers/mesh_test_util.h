// Shared by the mesh renderer tests: procedural meshes whose true surfaces are known (spheres,
// boxes), their exact ray casts, and comparisons of mesh renders (R, G, B, A, Z).
#pragma once

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "conus/codec/image/metrics.h"
#include "conus/codec/mesh/shading.h"
#include "conus/core/fpc.h"
#include "conus/core/image.h"
#include "conus/core/mesh.h"

namespace conus::renderers::test {

struct Sphere {
    glm::dvec3 centre{0.0};
    double radius = 1.0;
};

// Vertex colour of a sphere point: affine in the position (so a facet interpolates it exactly)
// and different along every axis, so a flipped or mirrored image cannot match.
inline glm::vec3 sphereColour(const Sphere& s, glm::dvec3 p) {
    const glm::dvec3 q = (p - s.centre) / s.radius;
    return glm::vec3(0.5 + 0.4 * q.x, 0.45 + 0.35 * q.y, 0.5 - 0.3 * q.z);
}

// A UV sphere of `slices` x `stacks` quads, counter-clockwise from outside, exact unit normals.
inline void appendSphere(Mesh& mesh, const Sphere& s, int slices, int stacks) {
    const auto base = static_cast<std::uint32_t>(mesh.positions.size());
    constexpr double kPi = 3.14159265358979323846;
    for (int j = 0; j <= stacks; ++j)
        for (int i = 0; i <= slices; ++i) {
            const double theta = kPi * j / stacks, phi = 2.0 * kPi * i / slices;
            const glm::dvec3 n(std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi));
            const glm::dvec3 p = s.centre + s.radius * n;
            mesh.positions.emplace_back(p);
            mesh.normals.emplace_back(n);
            mesh.colours.push_back(sphereColour(s, p));
        }
    const auto at = [&](int i, int j) { return base + static_cast<std::uint32_t>(j * (slices + 1) + i); };
    for (int j = 0; j < stacks; ++j)
        for (int i = 0; i < slices; ++i) {
            mesh.indices.insert(mesh.indices.end(), {at(i, j), at(i, j + 1), at(i + 1, j + 1)});
            mesh.indices.insert(mesh.indices.end(), {at(i, j), at(i + 1, j + 1), at(i + 1, j)});
        }
}

// An axis-aligned box with flat faces (4 vertices a face), one colour a face.
inline void appendBox(Mesh& mesh, glm::dvec3 lo, glm::dvec3 hi) {
    const glm::vec3 colours[6] = {{0.9f, 0.3f, 0.2f}, {0.2f, 0.7f, 0.3f}, {0.25f, 0.35f, 0.9f},
                                  {0.85f, 0.8f, 0.2f}, {0.6f, 0.25f, 0.7f}, {0.3f, 0.8f, 0.85f}};
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
            glm::vec3 n(0.0f);
            n[axis] = side ? 1.0f : -1.0f;
            const int a = (axis + 1) % 3, b = (axis + 2) % 3;
            const auto base = static_cast<std::uint32_t>(mesh.positions.size());
            for (int k = 0; k < 4; ++k) {
                glm::dvec3 p;
                p[axis] = side ? hi[axis] : lo[axis];
                p[a] = (k == 1 || k == 2) ? hi[a] : lo[a];
                p[b] = (k >= 2) ? hi[b] : lo[b];
                mesh.positions.emplace_back(p);
                mesh.normals.push_back(n);
                mesh.colours.push_back(colours[axis * 2 + side]);
            }
            // Winding is irrelevant to the renderers (two-sided, no culling).
            mesh.indices.insert(mesh.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
        }
}

// The first hit of `ray` with any sphere: distance along the unit direction.
inline std::optional<std::pair<double, int>> hitSpheres(const std::vector<Sphere>& spheres, const Ray& ray) {
    std::optional<std::pair<double, int>> best;
    for (int k = 0; k < static_cast<int>(spheres.size()); ++k) {
        const glm::dvec3 oc = ray.origin - spheres[k].centre;
        const double b = glm::dot(oc, ray.direction);
        const double c = glm::dot(oc, oc) - spheres[k].radius * spheres[k].radius;
        const double disc = b * b - c;
        if (disc < 0) continue;
        const double t = -b - std::sqrt(disc);
        if (t > 0 && (!best || t < best->first)) best = std::make_pair(t, k);
    }
    return best;
}

// The exact CoNUS render of the spheres through `fpc`, one ray through each pixel centre, shaded
// by codec/mesh/shading.h with the true normal and the true surface's colour.
inline Image castSpheres(const std::vector<Sphere>& spheres, const Fpc& fpc, int width, int height) {
    Image out = makeImage(width, height, {"R", "G", "B", "A", "Z"});
    const Camera& camera = fpc.camera();
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const Ray ray = fpc.ray({(x + 0.5) / width, (y + 0.5) / height});
            const auto hit = hitSpheres(spheres, ray);
            if (!hit) {
                out.at(x, y, 4) = static_cast<float>(camera.far());
                continue;
            }
            const Sphere& s = spheres[hit->second];
            const glm::dvec3 p = ray.origin + hit->first * ray.direction;
            const glm::vec3 n((p - s.centre) / s.radius);
            const glm::vec3 c = codec::shadeHeadlight(sphereColour(s, p), n, glm::vec3(codec::directionToEye(camera, p)));
            out.at(x, y, 0) = c.r;
            out.at(x, y, 1) = c.g;
            out.at(x, y, 2) = c.b;
            out.at(x, y, 3) = 1.0f;
            out.at(x, y, 4) = static_cast<float>(camera.project(p).z);
        }
    return out;
}

inline Image channelsOf(const Image& image, const std::vector<std::string>& names) {
    Image out = makeImage(image.width, image.height, names);
    for (std::size_t c = 0; c < names.size(); ++c) {
        const int from = image.channelIndex(names[c]);
        for (int y = 0; y < image.height; ++y)
            for (int x = 0; x < image.width; ++x) out.at(x, y, static_cast<int>(c)) = image.at(x, y, from);
    }
    return out;
}

// PSNR of colour and coverage (R, G, B, A; peak 1).
inline double colourPsnr(const Image& a, const Image& b) {
    const std::vector<std::string> rgba{"R", "G", "B", "A"};
    return codec::psnr(channelsOf(a, rgba), channelsOf(b, rgba));
}

// |Z difference| over the pixels both images cover fully (A = 1): largest, mean, 99th percentile
// (a pixel on an occlusion edge may see the far surface in one image and the near one in the
// other: a few such pixels are the edge's position, not a depth error), and how many pixels.
struct DepthError {
    double max = 0, mean = 0, p99 = 0;
    int pixels = 0;
};
inline DepthError depthError(const Image& a, const Image& b) {
    DepthError e;
    double sum = 0;
    std::vector<double> all;
    const int za = a.channelIndex("Z"), zb = b.channelIndex("Z"), aa = a.channelIndex("A"), ab = b.channelIndex("A");
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x) {
            if (a.at(x, y, aa) < 1.0f || b.at(x, y, ab) < 1.0f) continue;
            const double d = std::abs(double(a.at(x, y, za)) - b.at(x, y, zb));
            e.max = std::max(e.max, d);
            all.push_back(d);
            sum += d;
            ++e.pixels;
        }
    e.mean = e.pixels ? sum / e.pixels : 0.0;
    if (!all.empty()) {
        const auto k = static_cast<std::ptrdiff_t>(0.99 * static_cast<double>(all.size() - 1));
        std::nth_element(all.begin(), all.begin() + k, all.end());
        e.p99 = all[static_cast<std::size_t>(k)];
    }
    return e;
}

}  // namespace conus::renderers::test
