// The exact CPU reference of the mesh encoder: CoNUS ray casting with Embree (kept inside
// codec/src/mesh/raycast.cpp; no Embree type leaves it). For every CoNUS pixel, its undistorted
// image position by the FPC's exact inverse (Fpc::ray), the camera's ray through it, the first
// hit, shaded by shading.h. This is the ground truth the GPU path (vertex distortion by Eq. 1 and
// rasterization) approximates. An identity Fpc (null distortion) renders the conventional image
// of the same pixel count, and the full-resolution frame.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "conus/core/error.h"
#include "conus/core/fpc.h"
#include "conus/core/image.h"
#include "conus/core/mesh.h"

namespace conus::codec {

// A mesh with its ray-tracing acceleration structure, built once, then shared by any number of
// renders and threads (read-only).
class MeshScene {
public:
    // Checks the mesh (checkMesh) and computes its normals when it has none. Degenerate triangles
    // are kept (they are never hit). Throws conus::Error(InvalidArgument) for a bad mesh.
    explicit MeshScene(Mesh mesh);
    ~MeshScene();
    MeshScene(MeshScene&&) noexcept;
    MeshScene& operator=(MeshScene&&) noexcept;
    MeshScene(const MeshScene&) = delete;
    MeshScene& operator=(const MeshScene&) = delete;

    const Mesh& mesh() const;

    struct Hit {
        double distance = 0;       // along the ray's unit direction from its origin
        glm::dvec3 position{0.0};  // world
        std::uint32_t triangle = 0;
        float b1 = 0, b2 = 0;      // barycentric weights of corners 1 and 2
        glm::vec3 normal{0.0f};    // interpolated unit vertex normal
    };
    // The first hit along `ray` at distance in [tNear, tFar], if any.
    std::optional<Hit> intersect(const Ray& ray, double tNear = 0.0,
                                 double tFar = std::numeric_limits<double>::infinity()) const;
    // The surfaces `ray` crosses at distance in [tNear, tFar], counted up to `most` (the count
    // stops there): what a first-hit query may have to test. A triangle split across several
    // nodes of the acceleration structure may count more than once.
    std::int64_t surfacesAlong(const Ray& ray, double tNear, double tFar, std::int64_t most) const;

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

struct ReferenceOptions {
    // 1: one ray through the distorted pixel centre. n*n (4, 9, 16, ...): stratified sub-pixel
    // positions on an n x n grid of the *distorted* pixel, each undistorted exactly and averaged
    // (what a multisampling rasterizer approximates): RGB and A averaged over all samples (misses
    // count 0), Z the mean depth of the samples that hit (far when none did).
    int samplesPerPixel = 1;
    int threads = 0;  // 0: all cores
    ProgressFn progress;
};

// Refuses (LimitExceeded) a view whose rays cross more than kMaxMeshOverlap (limits.h) surfaces on
// average between the camera's near and far planes, probed on a grid of up to 64x64 rays through
// `fpc` before a width x height render (renderMeshReference and renderMeshLayers call it): each
// ray of the render tests every surface in front of its first hit, so many overlapping copies of a
// triangle would cost every ray that many tests. The probe stops once the limit is passed.
void checkSurfaceOverlap(const MeshScene& scene, const Fpc& fpc, int width, int height);

// A ray between two distances along it (from <= to; to may be infinite).
struct RaySpan {
    Ray ray;
    double from = 0, to = std::numeric_limits<double>::infinity();
};
// The same refusal for any rays a render will trace (the reflection frame's eye rays and the
// rays its mirror reflects): `spans` cross more than kMaxMeshOverlap surfaces on average. `what`
// names the render in the message.
void checkSurfaceOverlap(const MeshScene& scene, const std::vector<RaySpan>& spans, const std::string& what);

// A width x height CoNUS render of `scene` through `fpc`, channels R, G, B, A, Z (shading.h).
// Hits count between the camera's near and far depths. Throws conus::Error(InvalidArgument) for a
// bad size or a samplesPerPixel that is not a square in [1, 256], and LimitExceeded as
// checkSurfaceOverlap does.
Image renderMeshReference(const MeshScene& scene, const Fpc& fpc, int width, int height,
                          const ReferenceOptions& options = {});

// The shaded R, G, B, A, Z of one ray of `camera`'s through undistorted image position uv (what
// one sample of renderMeshReference computes).
std::array<float, 5> shadeRay(const MeshScene& scene, const Camera& camera, glm::dvec2 uv);

// The first `layers` surfaces along that ray (depth peeling by ray casting): entry k is shadeRay's
// R, G, B, A, Z of the first surface more than kPeelGap * its depth behind surface k - 1 (front or
// back side alike: the mirror sees either); the far plane with A = 0 where there is none.
inline constexpr double kPeelGap = 1e-3;
std::vector<std::array<float, 5>> shadeRayLayers(const MeshScene& scene, const Camera& camera, glm::dvec2 uv, int layers);

// `layers` width x height CoNUS renders of `scene` through `fpc`, one ray per pixel, image k the
// k-th surface (shadeRayLayers); image 0 is renderMeshReference's at one sample. Throws
// conus::Error(InvalidArgument) for layers < 1.
std::vector<Image> renderMeshLayers(const MeshScene& scene, const Fpc& fpc, int width, int height, int layers,
                                    int threads = 0);

}  // namespace conus::codec
