// The mesh value type's two rules every consumer shares: what a well-formed mesh is, and how
// vertex normals are made when a mesh has none.
#include <cmath>
#include <string>

#include "conus/core/error.h"
#include "conus/core/mesh.h"

namespace conus {

void checkMesh(const Mesh& mesh, const char* what) {
    auto fail = [&](const std::string& why) { throw Error(ErrorCode::InvalidArgument, std::string(what) + ": " + why); };
    if (mesh.indices.empty()) fail("the mesh has no triangles");
    if (mesh.indices.size() % 3 != 0)
        fail(std::to_string(mesh.indices.size()) + " indices are not a whole number of triangles");
    const std::size_t n = mesh.positions.size();
    for (std::size_t i = 0; i < mesh.indices.size(); ++i)
        if (mesh.indices[i] >= n)
            fail("index " + std::to_string(i) + " is " + std::to_string(mesh.indices[i]) + ", past the " +
                 std::to_string(n) + " vertices");
    for (std::size_t i = 0; i < n; ++i) {
        const glm::vec3 p = mesh.positions[i];
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            fail("vertex " + std::to_string(i) + " is not finite");
    }
    auto perVertex = [&](std::size_t size, const char* name) {
        if (size != 0 && size != n)
            fail(std::string("it has ") + std::to_string(size) + " " + name + " for " + std::to_string(n) + " vertices");
    };
    perVertex(mesh.normals.size(), "normals");
    perVertex(mesh.colours.size(), "colours");
    perVertex(mesh.uvs.size(), "UVs");
}

void computeVertexNormals(Mesh& mesh) {
    // Sums in double: a vertex shared by thousands of small triangles keeps its precision.
    std::vector<glm::dvec3> sum(mesh.positions.size(), glm::dvec3(0.0));
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        const std::uint32_t i0 = mesh.indices[t], i1 = mesh.indices[t + 1], i2 = mesh.indices[t + 2];
        if (i0 >= sum.size() || i1 >= sum.size() || i2 >= sum.size()) continue;
        const glm::dvec3 p0 = mesh.positions[i0], p1 = mesh.positions[i1], p2 = mesh.positions[i2];
        const glm::dvec3 faceTimesTwoArea = glm::cross(p1 - p0, p2 - p0);  // length = twice the area
        sum[i0] += faceTimesTwoArea;
        sum[i1] += faceTimesTwoArea;
        sum[i2] += faceTimesTwoArea;
    }
    mesh.normals.resize(mesh.positions.size());
    for (std::size_t i = 0; i < sum.size(); ++i) {
        const double length = glm::length(sum[i]);
        mesh.normals[i] = length > 0 && std::isfinite(length) ? glm::vec3(sum[i] / length) : glm::vec3(0, 0, 1);
    }
}

}  // namespace conus
