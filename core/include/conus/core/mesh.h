// A triangle mesh as CoNUS holds one in memory: what the height-field client builds from a CoNUS
// height field, what mesh files are read into (Assimp, at the edge), and what the mesh encoders
// render. Plain data; the frame is the caller's (a right-handed world, y up, unless a user says).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "conus/core/bounds.h"
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

// Throws conus::Error(InvalidArgument), naming `what`, unless `mesh` is well formed: at least one
// triangle, indices a multiple of 3 and all in range, finite positions, and normals, colours and
// UVs each either empty or one per vertex. Every consumer of a Mesh starts with it.
void checkMesh(const Mesh& mesh, const char* what);

// Sets mesh.normals to unit area-weighted vertex normals: each vertex takes the sum of the
// (unnormalized, so area-weighted) face normals of its triangles, counter-clockwise = outside.
// A vertex no non-degenerate triangle touches gets (0, 0, 1).
void computeVertexNormals(Mesh& mesh);

// The box around the mesh's positions (bounds.h).
inline AxisBox boundsOf(const Mesh& mesh) { return boundsOf(std::span<const glm::vec3>(mesh.positions)); }

}  // namespace conus
