// The mesh reference through Embree 3: the one file of CoNUS that includes an Embree header.
// Embree finds the first triangle along each ray (robust mode, so rays through shared edges never
// slip between triangles); the hit is then recomputed in double against that triangle, so depths
// are exact to double precision for the triangle Embree found, whatever Embree's float rounding.
#include "conus/codec/mesh/raycast.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "../image/resample_pvt.h"
#include "conus/codec/mesh/shading.h"
#include "conus/core/limits.h"
#include "conus/core/parallel.h"

namespace conus::codec {
namespace {

const char* embreeErrorText(RTCError error) {
    switch (error) {
        case RTC_ERROR_NONE: return "no error";
        case RTC_ERROR_INVALID_ARGUMENT: return "invalid argument";
        case RTC_ERROR_INVALID_OPERATION: return "invalid operation";
        case RTC_ERROR_OUT_OF_MEMORY: return "out of memory";
        case RTC_ERROR_UNSUPPORTED_CPU: return "unsupported CPU";
        case RTC_ERROR_CANCELLED: return "cancelled";
        default: return "unknown error";
    }
}

void checkDevice(RTCDevice device, const char* what) {
    const RTCError error = rtcGetDeviceError(device);
    if (error != RTC_ERROR_NONE)
        throw Error(error == RTC_ERROR_OUT_OF_MEMORY ? ErrorCode::LimitExceeded : ErrorCode::Unsupported,
                    std::string("mesh reference: Embree failed to ") + what + ": " + embreeErrorText(error));
}

// An occlusion query's context that counts the surfaces its ray crosses: the filter rejects each
// hit (so the traversal goes on) until `stopAt`, then accepts one (which ends it).
struct CountingContext {
    RTCIntersectContext base;  // first: Embree hands the filter a pointer to it
    std::int64_t count = 0;
    std::int64_t stopAt = 0;
};

void countCrossing(const RTCFilterFunctionNArguments* args) {
    auto* context = reinterpret_cast<CountingContext*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0) continue;
        if (++context->count < context->stopAt) args->valid[i] = 0;
    }
}

}  // namespace

struct MeshScene::Impl {
    Mesh mesh;
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    ~Impl() {
        if (scene) rtcReleaseScene(scene);
        if (device) rtcReleaseDevice(device);
    }
};

MeshScene::MeshScene(Mesh mesh) : m_impl(std::make_unique<Impl>()) {
    checkMesh(mesh, "mesh reference");
    if (mesh.normals.empty()) computeVertexNormals(mesh);
    Impl& impl = *m_impl;
    impl.mesh = std::move(mesh);
    impl.device = rtcNewDevice(nullptr);
    if (!impl.device) throw Error(ErrorCode::Unsupported, "mesh reference: Embree could not start a device");
    impl.scene = rtcNewScene(impl.device);
    rtcSetSceneFlags(impl.scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(impl.scene, RTC_BUILD_QUALITY_HIGH);
    RTCGeometry geometry = rtcNewGeometry(impl.device, RTC_GEOMETRY_TYPE_TRIANGLE);
    const Mesh& m = impl.mesh;
    // Embree owns these buffers (padded as it needs); they are filled once.
    auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                                 3 * sizeof(float), m.positions.size()));
    auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                   3 * sizeof(unsigned), m.triangleCount()));
    if (!vertices || !indices) {
        rtcReleaseGeometry(geometry);
        checkDevice(impl.device, "allocate the mesh");
        throw Error(ErrorCode::LimitExceeded, "mesh reference: Embree could not allocate the mesh");
    }
    std::memcpy(vertices, m.positions.data(), m.positions.size() * sizeof(glm::vec3));
    std::memcpy(indices, m.indices.data(), m.indices.size() * sizeof(std::uint32_t));
    // Only occlusion queries (surfacesAlong) count; first-hit queries run without a filter.
    rtcSetGeometryOccludedFilterFunction(geometry, countCrossing);
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(impl.scene, geometry);
    rtcReleaseGeometry(geometry);
    rtcCommitScene(impl.scene);
    checkDevice(impl.device, "build the scene");
}

MeshScene::~MeshScene() = default;
MeshScene::MeshScene(MeshScene&&) noexcept = default;
MeshScene& MeshScene::operator=(MeshScene&&) noexcept = default;

const Mesh& MeshScene::mesh() const { return m_impl->mesh; }

std::optional<MeshScene::Hit> MeshScene::intersect(const Ray& ray, double tNear, double tFar) const {
    if (!(tFar >= tNear)) return std::nullopt;
    // Embree wants tnear >= 0: a segment starting behind the origin starts from a moved origin.
    const double shift = std::min(tNear, 0.0);
    const glm::dvec3 origin = ray.origin + ray.direction * shift;
    RTCRayHit rh{};
    rh.ray.org_x = float(origin.x);
    rh.ray.org_y = float(origin.y);
    rh.ray.org_z = float(origin.z);
    rh.ray.dir_x = float(ray.direction.x);
    rh.ray.dir_y = float(ray.direction.y);
    rh.ray.dir_z = float(ray.direction.z);
    rh.ray.tnear = float(tNear - shift);
    rh.ray.tfar = std::isfinite(tFar) ? float(tFar - shift) : std::numeric_limits<float>::infinity();
    rh.ray.mask = 0xFFFFFFFFu;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    rtcIntersect1(m_impl->scene, &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;

    const Mesh& m = m_impl->mesh;
    Hit hit;
    hit.triangle = rh.hit.primID;
    const std::uint32_t* corner = &m.indices[std::size_t{hit.triangle} * 3];
    const glm::dvec3 p0 = m.positions[corner[0]], p1 = m.positions[corner[1]], p2 = m.positions[corner[2]];
    // The plane of the triangle in double (Moller-Trumbore), for t and the barycentrics.
    const glm::dvec3 e1 = p1 - p0, e2 = p2 - p0, s = origin - p0;
    const glm::dvec3 pv = glm::cross(ray.direction, e2), qv = glm::cross(s, e1);
    const double det = glm::dot(e1, pv);
    double t = double(rh.ray.tfar), b1 = rh.hit.u, b2 = rh.hit.v;
    if (std::abs(det) > 0) {
        t = glm::dot(e2, qv) / det;
        b1 = glm::dot(s, pv) / det;
        b2 = glm::dot(ray.direction, qv) / det;
    }
    hit.distance = t + shift;
    hit.position = ray.origin + ray.direction * hit.distance;
    hit.b1 = float(b1);
    hit.b2 = float(b2);
    const float b0 = 1.0f - hit.b1 - hit.b2;
    glm::vec3 n = m.normals[corner[0]] * b0 + m.normals[corner[1]] * hit.b1 + m.normals[corner[2]] * hit.b2;
    float length = glm::length(n);
    if (!(length > 0)) {
        n = glm::vec3(glm::cross(e1, e2));
        length = glm::length(n);
    }
    hit.normal = length > 0 ? n / length : glm::vec3(0, 0, 1);
    return hit;
}

std::int64_t MeshScene::surfacesAlong(const Ray& ray, double tNear, double tFar, std::int64_t most) const {
    if (!(tFar >= tNear) || most < 1) return 0;
    const double shift = std::min(tNear, 0.0);
    const glm::dvec3 origin = ray.origin + ray.direction * shift;
    RTCRay r{};
    r.org_x = float(origin.x);
    r.org_y = float(origin.y);
    r.org_z = float(origin.z);
    r.dir_x = float(ray.direction.x);
    r.dir_y = float(ray.direction.y);
    r.dir_z = float(ray.direction.z);
    r.tnear = float(tNear - shift);
    r.tfar = std::isfinite(tFar) ? float(tFar - shift) : std::numeric_limits<float>::infinity();
    r.mask = 0xFFFFFFFFu;
    CountingContext context;
    rtcInitIntersectContext(&context.base);
    context.stopAt = most;
    rtcOccluded1(m_impl->scene, &context.base, &r);
    return std::min(context.count, most);
}

namespace {

// The shaded R, G, B, A, Z of the first surface along `ray` at distance in [from, to] (the far
// plane with A = 0 when none), and the distance it lies at (`at`, untouched on a miss).
std::array<float, 5> shadeFirst(const MeshScene& scene, const Camera& camera, const Ray& ray, double from, double to,
                                double& at) {
    const auto hit = scene.intersect(ray, from, to);
    if (!hit) return {0, 0, 0, 0, float(camera.far())};
    const glm::vec3 albedo = meshAlbedo(scene.mesh(), hit->triangle, hit->b1, hit->b2);
    const glm::vec3 colour = shadeHeadlight(albedo, hit->normal, glm::vec3(directionToEye(camera, hit->position)));
    at = hit->distance;
    return {colour.r, colour.g, colour.b, 1.0f, float(camera.project(hit->position).z)};
}

// The ray of the undistorted image position uv between the camera's near and far depths, as
// distances along it (a point at distance t has depth t * dot(direction, forward), plus the
// origin's, which is 0 for both projections); nullopt when it looks away from the view.
struct DepthRange {
    Ray ray;
    double from = 0, to = 0;
};
std::optional<DepthRange> viewRay(const Camera& camera, glm::dvec2 uv) {
    const Ray ray = camera.ray(uv);
    const double cosine = glm::dot(ray.direction, camera.forward());
    if (!(cosine > 0)) return std::nullopt;
    return DepthRange{ray, camera.near() / cosine, camera.far() / cosine};
}

}  // namespace

void checkSurfaceOverlap(const MeshScene& scene, const std::vector<RaySpan>& spans, const std::string& what) {
    const std::int64_t budget = std::int64_t{kMaxMeshOverlap} * std::int64_t(spans.size());
    std::int64_t total = 0;
    for (std::size_t k = 0; k < spans.size() && total <= budget; ++k)
        total += scene.surfacesAlong(spans[k].ray, spans[k].from, spans[k].to, budget - total + 1);
    if (total > budget)
        throw Error(ErrorCode::LimitExceeded,
                    what + ": the surfaces lie more than " + std::to_string(kMaxMeshOverlap) +
                        " deep along the average ray of this view (" + std::to_string(spans.size()) +
                        " rays probed), and each ray tests every surface in front of its first hit: overlapping "
                        "copies of its triangles? (limit meshOverlap)");
}

void checkSurfaceOverlap(const MeshScene& scene, const Fpc& fpc, int width, int height) {
    const int columns = std::clamp(width, 1, 64), rows = std::clamp(height, 1, 64);
    const Distortion* distortion = fpc.distortion();
    std::vector<RaySpan> spans;
    spans.reserve(std::size_t(columns) * std::size_t(rows));
    for (int j = 0; j < rows; ++j)
        for (int i = 0; i < columns; ++i) {
            const glm::dvec2 pd((i + 0.5) / columns, (j + 0.5) / rows);
            if (const auto v = viewRay(fpc.camera(), distortion ? distortion->undistort(pd) : pd))
                spans.push_back({v->ray, v->from, v->to});
            else
                spans.push_back({Ray{}, 0, -1});  // looks away: crosses nothing, counts in the average
        }
    checkSurfaceOverlap(scene, spans, "mesh reference");
}

std::array<float, 5> shadeRay(const MeshScene& scene, const Camera& camera, glm::dvec2 uv) {
    const auto v = viewRay(camera, uv);
    if (!v) return {0, 0, 0, 0, float(camera.far())};
    double at = 0;
    return shadeFirst(scene, camera, v->ray, v->from, v->to, at);
}

std::vector<std::array<float, 5>> shadeRayLayers(const MeshScene& scene, const Camera& camera, glm::dvec2 uv, int layers) {
    const Ray ray = camera.ray(uv);
    const double cosine = glm::dot(ray.direction, camera.forward());
    std::vector<std::array<float, 5>> out(static_cast<std::size_t>(std::max(layers, 0)),
                                          std::array<float, 5>{0, 0, 0, 0, float(camera.far())});
    if (!(cosine > 0)) return out;
    double from = camera.near() / cosine, at = -1;
    for (auto& layer : out) {
        layer = shadeFirst(scene, camera, ray, from, camera.far() / cosine, at);
        if (layer[kMeshChannelA] <= 0) break;
        from = at * (1.0 + kPeelGap);
    }
    return out;
}

Image renderMeshReference(const MeshScene& scene, const Fpc& fpc, int width, int height, const ReferenceOptions& options) {
    const int n = int(std::lround(std::sqrt(double(std::max(options.samplesPerPixel, 0)))));
    if (options.samplesPerPixel < 1 || options.samplesPerPixel > 256 || n * n != options.samplesPerPixel)
        throw Error(ErrorCode::InvalidArgument, "mesh reference: samples per pixel must be a square from 1 to 256, got " +
                                                    std::to_string(options.samplesPerPixel));
    Image out = makeImage(width, height, meshChannelNames());
    checkSurfaceOverlap(scene, fpc, width, height);
    const Camera& camera = fpc.camera();
    const Distortion* distortion = fpc.distortion();
    const float far = float(camera.far());
    detail::RowProgress progress(options.progress, height);
    parallelRows(height, options.threads, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y) {
            for (int x = 0; x < width; ++x) {
                glm::vec3 colour(0.0f);
                float coverage = 0;
                double depthSum = 0;
                for (int j = 0; j < n; ++j)
                    for (int i = 0; i < n; ++i) {
                        const glm::dvec2 pd((x + (i + 0.5) / n) / width, (y + (j + 0.5) / n) / height);
                        const std::array<float, 5> s = shadeRay(scene, camera, distortion ? distortion->undistort(pd) : pd);
                        colour += glm::vec3(s[0], s[1], s[2]);
                        if (s[kMeshChannelA] > 0) {
                            coverage += 1;
                            depthSum += s[kMeshChannelZ];
                        }
                    }
                const float samples = float(n * n);
                float* px = &out.at(x, y, 0);
                px[0] = colour.r / samples;
                px[1] = colour.g / samples;
                px[2] = colour.b / samples;
                px[kMeshChannelA] = coverage / samples;
                px[kMeshChannelZ] = coverage > 0 ? float(depthSum / coverage) : far;
            }
        }
        progress.add(y1 - y0);
    });
    return out;
}

std::vector<Image> renderMeshLayers(const MeshScene& scene, const Fpc& fpc, int width, int height, int layers, int threads) {
    if (layers < 1) throw Error(ErrorCode::InvalidArgument, "mesh layers: at least one layer, got " + std::to_string(layers));
    checkSurfaceOverlap(scene, fpc, width, height);
    std::vector<Image> out(static_cast<std::size_t>(layers), makeImage(width, height, meshChannelNames()));
    const Distortion* distortion = fpc.distortion();
    parallelRows(height, threads, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y)
            for (int x = 0; x < width; ++x) {
                const glm::dvec2 pd((x + 0.5) / width, (y + 0.5) / height);
                const auto surfaces = shadeRayLayers(scene, fpc.camera(), distortion ? distortion->undistort(pd) : pd, layers);
                for (std::size_t k = 0; k < surfaces.size(); ++k)
                    std::copy(surfaces[k].begin(), surfaces[k].end(), &out[k].at(x, y, 0));
            }
    });
    return out;
}

}  // namespace conus::codec
