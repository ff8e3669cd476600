// A triangle mesh as CoNUS holds one in memory: what the height-field client builds from a CoNUS
// height field, what mesh files are read into (Assimp, at the edge), and what the mesh encoders
// render. Plain data; the frame is the caller's (a right-handed world, y up, unless a user says).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "conus/core/image.h"

namespace conus {

struct Mesh {
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals;      // unit, per vertex; empty: to be computed
    std::vector<glm::vec3> colours;      // per vertex, linear RGB; empty: white (or the texture)
    std::vector<glm::vec2> uvs;          // per vertex texture coordinates, (0,0) top-left; empty: none
    std::vector<std::uint32_t> indices;  // triangles, counter-clockwise seen from outside
    std::optional<Image> texture;        // base colour (linear light) sampled at `uvs`

    std::size_t triangleCount() const { return indices.size() / 3; }
};

}  // namespace conus
