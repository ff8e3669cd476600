// Edge subdivision for the GPU mesh encoder (subdivide.h). Each pass chooses the edges to split
// (by their two vertex indices, so both triangles of a shared edge agree), splits them at their
// world-space midpoints, and replaces each triangle by two, three or four; passes repeat until none
// is chosen. Midpoints are keyed by edge too, so a split edge has one new vertex.
#include "conus/codec/mesh/subdivide.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_map>

#include "conus/core/error.h"

namespace conus::codec {
namespace {

// Projects every vertex once: image position and whether it lies in front of the near plane.
struct Projected {
    std::vector<glm::dvec2> uv;
    std::vector<char> measurable;
};

Projected projectAll(const Mesh& mesh, const Camera& camera) {
    Projected out;
    out.uv.resize(mesh.positions.size());
    out.measurable.resize(mesh.positions.size());
    const bool perspective = camera.projection() == Projection::Perspective;
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
        const glm::dvec3 p = camera.project(glm::dvec3(mesh.positions[i]));
        out.uv[i] = {p.x, p.y};
        out.measurable[i] = (!perspective || p.z > camera.near()) && std::isfinite(p.x) && std::isfinite(p.y);
    }
    return out;
}

// Length in map cells of the edge a-b, or -1 when it is not measured.
double cellLength(const Projected& projected, std::uint32_t a, std::uint32_t b, glm::dvec2 cells) {
    if (!projected.measurable[a] || !projected.measurable[b]) return -1;
    return glm::length((projected.uv[b] - projected.uv[a]) * cells);
}

std::uint64_t edgeKey(std::uint32_t a, std::uint32_t b) {
    if (a > b) std::swap(a, b);
    return (std::uint64_t{a} << 32) | b;
}

glm::dvec2 cellsOf(const SamplingMap& map) { return {map.columns() - 1, map.rows() - 1}; }

}  // namespace

double longestProjectedEdge(const Mesh& mesh, const Camera& camera, const SamplingMap& map) {
    checkMesh(mesh, "longestProjectedEdge");
    const Projected projected = projectAll(mesh, camera);
    const glm::dvec2 cells = cellsOf(map);
    double longest = 0;
    for (std::size_t t = 0; t < mesh.indices.size(); t += 3)
        for (int e = 0; e < 3; ++e)
            longest = std::max(longest, cellLength(projected, mesh.indices[t + e], mesh.indices[t + (e + 1) % 3], cells));
    return longest;
}

namespace {

// The edges one pass splits, by edgeKey; each value becomes the edge's midpoint vertex.
using EdgeSplits = std::unordered_map<std::uint64_t, std::uint32_t>;

// Splits every edge in `split` at its world-space midpoint and replaces each triangle by two,
// three or four. A triangle looks its edges up by key, so both triangles of a shared edge use its
// one new vertex: no T-junction.
void splitEdges(Mesh& mesh, Projected& projected, const Camera& camera, EdgeSplits& split, const SubdivideOptions& options,
                const std::string& bound) {
    const std::size_t triangles = mesh.triangleCount();
    std::vector<std::uint8_t> splitMask(triangles, 0);
    std::int64_t total = std::int64_t(triangles);
    for (std::size_t t = 0; t < triangles; ++t)
        for (int e = 0; e < 3; ++e)
            if (split.count(edgeKey(mesh.indices[t * 3 + e], mesh.indices[t * 3 + (e + 1) % 3]))) {
                splitMask[t] |= std::uint8_t(1u << e);
                ++total;  // 1 split: +1 triangle, 2: +2, 3: +3
            }
    if (total > options.maxTriangles)
        throw Error(ErrorCode::LimitExceeded, "subdivideForMap: " + bound + " needs more than " +
                                                  std::to_string(options.maxTriangles) + " triangles (" +
                                                  std::to_string(total) + " after this pass)");
    if (mesh.positions.size() + split.size() > std::size_t{UINT32_MAX})
        throw Error(ErrorCode::LimitExceeded, "subdivideForMap: too many vertices");
    const bool perspective = camera.projection() == Projection::Perspective;

    // New vertices, in a deterministic order (by the triangle and edge that first named them).
    for (auto& [key, id] : split) id = UINT32_MAX;
    for (std::size_t t = 0; t < triangles; ++t)
        for (int e = 0; e < 3; ++e) {
            if (!(splitMask[t] & (1u << e))) continue;
            const std::uint32_t a = mesh.indices[t * 3 + e], b = mesh.indices[t * 3 + (e + 1) % 3];
            std::uint32_t& id = split.at(edgeKey(a, b));
            if (id != UINT32_MAX) continue;
            id = std::uint32_t(mesh.positions.size());
            const glm::vec3 p = (mesh.positions[a] + mesh.positions[b]) * 0.5f;
            mesh.positions.push_back(p);
            const glm::vec3 n = mesh.normals[a] + mesh.normals[b];
            const float length = glm::length(n);
            mesh.normals.push_back(length > 0 ? n / length : mesh.normals[a]);
            if (!mesh.colours.empty()) mesh.colours.push_back((mesh.colours[a] + mesh.colours[b]) * 0.5f);
            if (!mesh.uvs.empty()) mesh.uvs.push_back((mesh.uvs[a] + mesh.uvs[b]) * 0.5f);
            const glm::dvec3 q = camera.project(glm::dvec3(p));
            projected.uv.emplace_back(q.x, q.y);
            projected.measurable.push_back((!perspective || q.z > camera.near()) && std::isfinite(q.x) && std::isfinite(q.y));
        }

    std::vector<std::uint32_t> indices;
    indices.reserve(std::size_t(total) * 3);
    auto emit = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) { indices.insert(indices.end(), {a, b, c}); };
    for (std::size_t t = 0; t < triangles; ++t) {
        const std::uint32_t v[3] = {mesh.indices[t * 3], mesh.indices[t * 3 + 1], mesh.indices[t * 3 + 2]};
        const std::uint8_t mask = splitMask[t];
        auto mid = [&](int e) { return split.at(edgeKey(v[e], v[(e + 1) % 3])); };
        switch (mask) {
            case 0:
                emit(v[0], v[1], v[2]);
                break;
            case 7: {  // all three: four triangles
                const std::uint32_t m0 = mid(0), m1 = mid(1), m2 = mid(2);
                emit(v[0], m0, m2);
                emit(m0, v[1], m1);
                emit(m2, m1, v[2]);
                emit(m0, m1, m2);
                break;
            }
            default: {
                // Rotate so the split edges come first: edge e runs v[e] -> v[e+1].
                int r = 0;
                const int count = (mask & 1) + ((mask >> 1) & 1) + ((mask >> 2) & 1);
                if (count == 1) {
                    while (!(mask & (1u << r))) ++r;
                } else {  // two: the unsplit edge is the third after rotation
                    while (mask & (1u << ((r + 2) % 3)) || !(mask & (1u << r))) ++r;
                }
                const std::uint32_t a = v[r], b = v[(r + 1) % 3], c = v[(r + 2) % 3];
                const std::uint32_t mab = split.at(edgeKey(a, b));
                if (count == 1) {
                    emit(a, mab, c);
                    emit(mab, b, c);
                } else {
                    const std::uint32_t mbc = split.at(edgeKey(b, c));
                    emit(mab, b, mbc);
                    // The quad a, mab, mbc, c: cut along its shorter diagonal.
                    const double d1 = glm::length(glm::dvec3(mesh.positions[a]) - glm::dvec3(mesh.positions[mbc]));
                    const double d2 = glm::length(glm::dvec3(mesh.positions[mab]) - glm::dvec3(mesh.positions[c]));
                    if (d1 <= d2) {
                        emit(a, mab, mbc);
                        emit(a, mbc, c);
                    } else {
                        emit(a, mab, c);
                        emit(mab, mbc, c);
                    }
                }
            }
        }
    }
    mesh.indices = std::move(indices);
}

}  // namespace

Mesh subdivideForMap(const Mesh& input, const Camera& camera, const SamplingMap& map, double maxEdge,
                     const SubdivideOptions& options) {
    checkMesh(input, "subdivideForMap");
    if (!(maxEdge > 0) || !std::isfinite(maxEdge))
        throw Error(ErrorCode::InvalidArgument, "subdivideForMap: the longest edge must be > 0 cells, got " + numberText(maxEdge));
    const glm::dvec2 cells = cellsOf(map);
    const std::string bound = "splitting edges to " + numberText(maxEdge) + " cells";
    Mesh mesh = input;
    if (mesh.normals.empty()) computeVertexNormals(mesh);
    Projected projected = projectAll(mesh, camera);
    // Passes until no edge is too long.
    for (;;) {
        EdgeSplits split;
        for (std::size_t t = 0; t < mesh.indices.size(); t += 3)
            for (int e = 0; e < 3; ++e) {
                const std::uint32_t a = mesh.indices[t + e], b = mesh.indices[t + (e + 1) % 3];
                if (cellLength(projected, a, b, cells) > maxEdge) split.emplace(edgeKey(a, b), 0);
            }
        if (split.empty()) return mesh;
        splitEdges(mesh, projected, camera, split, options, bound);
    }
}

}  // namespace conus::codec
