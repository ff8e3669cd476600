#include "conus/codec/volume/raycast.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "../image/resample_pvt.h"
#include "conus/core/limits.h"
#include "conus/core/parallel.h"

namespace conus::codec {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kMaxRenderSide = 16384;

// The trilinear sample at voxel coordinates g (sample centres at whole numbers), clamped to the
// box: what GL_LINEAR with CLAMP_TO_EDGE reads at texture coordinate (g + 0.5) / size.
float trilinear(const Volume& v, glm::dvec3 g) {
    const glm::dvec3 hi(v.width - 1, v.height - 1, v.depth - 1);
    g = glm::clamp(g, glm::dvec3(0.0), hi);
    const glm::ivec3 i0 = glm::min(glm::ivec3(glm::floor(g)), glm::ivec3(hi) - 1);
    const glm::vec3 f = glm::vec3(g - glm::dvec3(i0));
    const auto row = [&](int y, int z) {
        const float* p = &v.values[v.index(i0.x, y, z)];
        return p[0] + (p[1] - p[0]) * f.x;
    };
    const float a = row(i0.y, i0.z), b = row(i0.y + 1, i0.z), c = row(i0.y, i0.z + 1), d = row(i0.y + 1, i0.z + 1);
    const float front = a + (b - a) * f.y, back = c + (d - c) * f.y;
    return front + (back - front) * f.z;
}

}  // namespace

glm::vec2 valueRange(const Volume& volume) {
    if (volume.values.empty()) return {0.0f, 0.0f};
    const auto [lo, hi] = std::minmax_element(volume.values.begin(), volume.values.end());
    return {*lo, *hi};
}

glm::vec2 renderRange(const Volume& volume, const VolumeRenderOptions& options) {
    glm::vec2 range = options.rangeLo < options.rangeHi ? glm::vec2(options.rangeLo, options.rangeHi) : valueRange(volume);
    if (!(range.y > range.x)) range.y = range.x + 1.0f;
    return range;
}

float pixelJitter(int x, int y) {
    // Two odd multipliers mix the coordinates, then a 32-bit avalanche (the "lowbias32" finalizer);
    // the top 24 bits make a float in [0,1) exactly.
    std::uint32_t h = static_cast<std::uint32_t>(x) * 0x8da6b343u ^ static_cast<std::uint32_t>(y) * 0xd8163841u;
    h ^= h >> 16;
    h *= 0x7feb352du;
    h ^= h >> 15;
    h *= 0x846ca68bu;
    h ^= h >> 16;
    return static_cast<float>(h >> 8) * (1.0f / 16777216.0f);
}

void checkVolumeRenderOptions(int width, int height, const VolumeRenderOptions& options) {
    if (width < 1 || height < 1 || width > kMaxRenderSide || height > kMaxRenderSide)
        throw Error(ErrorCode::InvalidArgument, "render volume: size " + std::to_string(width) + "x" +
                                                    std::to_string(height) + " is outside [1, 16384] per side");
    if (!(options.stepVoxels > 0.0 && options.stepVoxels <= 16.0))
        throw Error(ErrorCode::InvalidArgument, "render volume: step " + numberText(options.stepVoxels) +
                                                    " voxels is outside (0, 16]");
    if (!(options.depthOpacity > 0.0f && options.depthOpacity < 1.0f))
        throw Error(ErrorCode::InvalidArgument, "render volume: depth opacity " + numberText(options.depthOpacity) +
                                                    " is outside (0, 1)");
    if (!std::isfinite(options.rangeLo) || !std::isfinite(options.rangeHi) || options.rangeLo > options.rangeHi)
        throw Error(ErrorCode::InvalidArgument, "render volume: value range " + numberText(options.rangeLo) + ".." +
                                                    numberText(options.rangeHi) + " is not lo <= hi");
}

void checkRaySteps(const Volume& volume, double stepVoxels) {
    const double smallest = std::min({volume.spacing.x, volume.spacing.y, volume.spacing.z});
    const double steps = glm::length(volume.extent()) / (stepVoxels * smallest);
    const double samples = double(volume.width) + volume.height + volume.depth;
    const double cap = double(kMaxRayStepsPerSample) * samples;
    if (steps <= cap) return;
    // With an even spacing a step of at least 1/kMaxRayStepsPerSample always fits.
    const bool stepTooSmall = stepVoxels < 1.0 / double(kMaxRayStepsPerSample);
    throw Error(stepTooSmall ? ErrorCode::InvalidArgument : ErrorCode::LimitExceeded,
                "render volume: a step of " + numberText(stepVoxels) + " voxels takes up to " + numberText(steps) +
                    " steps per ray through a " + std::to_string(volume.width) + "x" + std::to_string(volume.height) +
                    "x" + std::to_string(volume.depth) + " volume of spacing " + numberText(volume.spacing.x) + "," +
                    numberText(volume.spacing.y) + "," + numberText(volume.spacing.z) + ", more than the limit of " +
                    numberText(cap) + (stepTooSmall ? "; give a larger step" : " (the spacing is too uneven)"));
}

std::array<float, 5> castVolumeRay(const Volume& volume, const TransferFunction& tf, const Camera& camera,
                                   glm::dvec2 uv, float jitter, glm::vec2 range, const VolumeRenderOptions& options,
                                   int* steps) {
    if (steps) *steps = 0;
    const float far = static_cast<float>(camera.far());
    std::array<float, 5> out{0.0f, 0.0f, 0.0f, 0.0f, far};
    const Ray ray = camera.ray(uv);
    const double cosine = glm::dot(ray.direction, camera.forward());
    if (!(cosine > 0.0)) return out;
    // The part of the ray inside the box [0, extent] (slabs) and between near and far.
    double tEnter = camera.near() / cosine, tExit = camera.far() / cosine;
    const glm::dvec3 extent = volume.extent();
    for (int a = 0; a < 3; ++a) {
        if (ray.direction[a] == 0.0) {
            if (ray.origin[a] < 0.0 || ray.origin[a] > extent[a]) return out;
            continue;
        }
        const double inv = 1.0 / ray.direction[a];
        double t0 = -ray.origin[a] * inv, t1 = (extent[a] - ray.origin[a]) * inv;
        if (t0 > t1) std::swap(t0, t1);
        tEnter = std::max(tEnter, t0);
        tExit = std::min(tExit, t1);
    }
    if (!(tEnter < tExit)) return out;

    const double step = options.stepVoxels * std::min({volume.spacing.x, volume.spacing.y, volume.spacing.z});
    const double offset = options.jitter ? jitter : 0.5;
    const float scale = 1.0f / (range.y - range.x);
    glm::vec3 colour(0.0f);
    float alpha = 0.0f;
    bool depthSet = false;
    const auto exponent = static_cast<float>(options.stepVoxels);
    for (int k = 0;; ++k) {
        const double t = tEnter + (k + offset) * step;
        if (t > tExit) break;
        if (steps) ++*steps;
        const glm::dvec3 p = ray.origin + t * ray.direction;
        const float value = trilinear(volume, p / volume.spacing);
        const glm::vec4 c = tf.lookup((value - range.x) * scale);
        const float a = 1.0f - std::pow(1.0f - c.a, exponent);
        colour += (1.0f - alpha) * a * glm::vec3(c);
        alpha += (1.0f - alpha) * a;
        if (!depthSet && alpha >= options.depthOpacity) {
            out[4] = static_cast<float>(t * cosine);
            depthSet = true;
        }
        if (alpha >= kTerminationOpacity) break;
    }
    out[0] = colour.r;
    out[1] = colour.g;
    out[2] = colour.b;
    out[3] = alpha;
    return out;
}

Image renderVolumeReference(const Volume& volume, const TransferFunction& tf, const Fpc& fpc, int width, int height,
                            const VolumeRenderOptions& options) {
    checkVolume(volume, "render volume");
    checkVolumeRenderOptions(width, height, options);
    checkRaySteps(volume, options.stepVoxels);
    Image out = makeImage(width, height, {kVolumeChannels.begin(), kVolumeChannels.end()});
    const glm::vec2 range = renderRange(volume, options);
    const Distortion* distortion = fpc.distortion();
    detail::RowProgress progress(options.progress, height);
    parallelRows(height, options.threads, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y)
            for (int x = 0; x < width; ++x) {
                const glm::dvec2 pd((x + 0.5) / width, (y + 0.5) / height);
                const std::array<float, 5> s = castVolumeRay(volume, tf, fpc.camera(),
                                                             distortion ? distortion->undistort(pd) : pd,
                                                             pixelJitter(x, y), range, options);
                std::copy(s.begin(), s.end(), &out.at(x, y, 0));
            }
        progress.add(y1 - y0);
    }, 4);
    return out;
}

namespace {

const glm::dvec3 kToEye = glm::normalize(glm::dvec3(0.45, -0.35, -1.0));  // the view's fixed direction

// Looks at `centre` from kToEye's direction, from `distance`, near and far bracketing the sphere
// of `radius` about it.
Camera viewFrom(glm::dvec3 centre, double distance, double radius, double aspect, double fovYDegrees) {
    return Camera::perspective(centre + distance * kToEye, centre, {0.0, -1.0, 0.0}, fovYDegrees, aspect,
                               std::max(distance - 1.05 * radius, 0.01 * distance), distance + 1.05 * radius);
}

double halfAngle(double fovYDegrees) { return 0.5 * fovYDegrees * kPi / 180.0; }

}  // namespace

Camera defaultVolumeCamera(const Volume& volume, double aspect, double fovYDegrees) {
    const glm::dvec3 centre = 0.5 * volume.extent();
    const double radius = std::max(0.5 * glm::length(volume.extent()), 1e-6);
    // The narrower of the two fields of view decides the distance that fits the bounding sphere.
    const double halfY = halfAngle(fovYDegrees), halfX = std::atan(std::tan(halfY) * aspect);
    return viewFrom(centre, 1.02 * radius / std::sin(std::min(halfX, halfY)), radius, aspect, fovYDegrees);
}

Camera defaultVolumeCamera(const Volume& volume, const TransferFunction& tf, glm::vec2 range, double aspect,
                           double fovYDegrees) {
    const float scale = range.y > range.x ? 1.0f / (range.y - range.x) : 1.0f;
    const auto shows = [&](int x, int y, int z) {
        return tf.lookup(std::clamp((volume.at(x, y, z) - range.x) * scale, 0.0f, 1.0f)).a > 1.0f / 255.0f;
    };
    glm::ivec3 lo(volume.width, volume.height, volume.depth), hi(-1);
    for (int z = 0; z < volume.depth; ++z)
        for (int y = 0; y < volume.height; ++y)
            for (int x = 0; x < volume.width; ++x)
                if (shows(x, y, z)) {
                    lo = glm::min(lo, glm::ivec3(x, y, z));
                    hi = glm::max(hi, glm::ivec3(x, y, z));
                }
    if (hi.x < 0) return defaultVolumeCamera(volume, aspect, fovYDegrees);
    // Look at the shown samples' box centre, from where every shown sample fits the frame.
    const glm::dvec3 centre = 0.5 * glm::dvec3(lo + hi) * volume.spacing;
    const double radius = std::max(0.5 * glm::length(glm::dvec3(hi - lo) * volume.spacing), 1e-6);
    const double tanY = 0.95 * std::tan(halfAngle(fovYDegrees)), tanX = tanY * aspect;  // a small border
    const glm::dvec3 forward = -kToEye, right = glm::normalize(glm::cross(forward, glm::dvec3(0.0, -1.0, 0.0)));
    const glm::dvec3 up = glm::cross(right, forward);
    double distance = 1.1 * radius;  // never inside the shown samples' sphere
    for (int z = lo.z; z <= hi.z; ++z)
        for (int y = lo.y; y <= hi.y; ++y)
            for (int x = lo.x; x <= hi.x; ++x)
                if (shows(x, y, z)) {
                    const glm::dvec3 r = glm::dvec3(x, y, z) * volume.spacing - centre;
                    const double along = glm::dot(r, forward);
                    distance = std::max({distance, std::abs(glm::dot(r, right)) / tanX - along,
                                         std::abs(glm::dot(r, up)) / tanY - along});
                }
    return viewFrom(centre, distance, radius, aspect, fovYDegrees);
}

}  // namespace conus::codec
