// How a mesh pixel is shaded: the ONE statement of it. The CPU reference (raycast.h) calls these
// functions; the GPU mesh encoder gets the constants injected into its shader
// (renderers/src/shader_constants.cpp) and repeats the formula there.
//
// - albedo: the vertex colour when the mesh has colours, else the texture at the UV when it has a
//   texture and UVs, else kDefaultAlbedo (linear grey).
// - a headlight, two-sided so open meshes shade:
//     colour = albedo * (kAmbient + (1 - kAmbient) * |dot(N, L)|)
//   N the interpolated unit normal, L the unit direction from the surface point to the eye
//   (perspective) or -forward (orthographic).
// - the output of a mesh render has the channels kMeshChannels: R, G, B, A, Z. A is coverage (1 hit,
//   0 miss; a fraction with several samples a pixel), Z the camera depth of the hit
//   (conus::Camera::project(p).z, the spec's cameraDepth) and the camera's far where missed, RGB
//   0 where missed.
// - textures are sampled bilinearly between texel centres, wrapping (repeat) on both axes, no
//   mipmaps: what GL_LINEAR with GL_REPEAT does. UV (0,0) is the texture's top-left corner.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "conus/core/camera.h"
#include "conus/core/image.h"
#include "conus/core/mesh.h"

namespace conus::codec {

inline constexpr float kAmbient = 0.15f;
inline constexpr float kDefaultAlbedo = 0.8f;  // each of R, G, B
inline constexpr std::array<const char*, 5> kMeshChannels = {"R", "G", "B", "A", "Z"};
inline constexpr int kMeshChannelR = 0, kMeshChannelA = 3, kMeshChannelZ = 4;

// The headlight term for albedo, unit normal N and unit direction L to the eye.
inline glm::vec3 shadeHeadlight(glm::vec3 albedo, glm::vec3 normal, glm::vec3 toEye) {
    return albedo * (kAmbient + (1.0f - kAmbient) * std::abs(glm::dot(normal, toEye)));
}

// L of the formula at world point p for `camera`.
glm::dvec3 directionToEye(const Camera& camera, glm::dvec3 p);

// The texture's linear RGB at uv (bilinear, repeat; a one-channel texture is grey).
glm::vec3 sampleTexture(const Image& texture, glm::vec2 uv);

// The albedo of triangle `triangle` of `mesh` at barycentric (b1, b2) (corner 0 weighs 1-b1-b2),
// by the rule above.
glm::vec3 meshAlbedo(const Mesh& mesh, std::size_t triangle, float b1, float b2);

// The channel names of a mesh render, as an Image holds them.
std::vector<std::string> meshChannelNames();

}  // namespace conus::codec
