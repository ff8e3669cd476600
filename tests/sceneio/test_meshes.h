// Meshes for the mesh suites (sceneio, codec/mesh): the shared models' folder, and procedural
// shapes whose normals, depths and areas are known in closed form, as conus::Mesh or as OBJ text.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "conus/core/mesh.h"

namespace conus::test {

inline std::filesystem::path sharedMeshes() { return std::filesystem::path(CONUS_SHARED_DATA) / "meshes"; }

// The five models of ../shared/data/meshes (its README).
inline const std::vector<std::string>& sharedMeshNames() {
    static const std::vector<std::string> names = {"stanford-bunny.obj", "spot.obj", "teapot.obj", "suzanne.obj", "cow.obj"};
    return names;
}

#define CONUS_REQUIRE_SHARED_MESHES()                                                                       \
    do {                                                                                                    \
        if (!std::filesystem::is_directory(::conus::test::sharedMeshes()))                                  \
            GTEST_SKIP() << "shared meshes not found at " << ::conus::test::sharedMeshes() << ": skipped"; \
    } while (0)

constexpr double kTestPi = 3.14159265358979323846;

// A UV sphere of `radius` around `centre`: `rings` bands of latitude, `segments` of longitude,
// one vertex at each pole, counter-clockwise seen from outside, closed (every edge in two triangles).
inline Mesh uvSphere(glm::vec3 centre, float radius, int rings, int segments) {
    Mesh m;
    m.positions.push_back(centre + glm::vec3(0, radius, 0));
    for (int r = 1; r < rings; ++r) {
        const double theta = kTestPi * r / rings;
        for (int s = 0; s < segments; ++s) {
            const double phi = 2 * kTestPi * s / segments;
            m.positions.push_back(centre + radius * glm::vec3(std::sin(theta) * std::cos(phi), std::cos(theta),
                                                              -std::sin(theta) * std::sin(phi)));
        }
    }
    m.positions.push_back(centre - glm::vec3(0, radius, 0));
    const auto ring = [&](int r, int s) { return std::uint32_t(1 + (r - 1) * segments + (s % segments)); };
    const std::uint32_t south = std::uint32_t(m.positions.size() - 1);
    for (int s = 0; s < segments; ++s) {
        m.indices.insert(m.indices.end(), {0u, ring(1, s), ring(1, s + 1)});
        for (int r = 1; r + 1 < rings; ++r) {
            m.indices.insert(m.indices.end(), {ring(r, s), ring(r + 1, s), ring(r + 1, s + 1)});
            m.indices.insert(m.indices.end(), {ring(r, s), ring(r + 1, s + 1), ring(r, s + 1)});
        }
        m.indices.insert(m.indices.end(), {ring(rings - 1, s), south, ring(rings - 1, s + 1)});
    }
    return m;
}

// An axis-aligned box [lo, hi] with 8 shared corners and 12 triangles, closed, outward winding.
inline Mesh sharedBox(glm::vec3 lo, glm::vec3 hi) {
    Mesh m;
    for (int i = 0; i < 8; ++i) m.positions.emplace_back(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
    // Faces as quads (a, b, c, d) counter-clockwise seen from outside.
    const std::uint32_t quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    for (const auto& q : quads) m.indices.insert(m.indices.end(), {q[0], q[1], q[2], q[0], q[2], q[3]});
    return m;
}

// OBJ text of `mesh` (positions and triangles; normals too when it has them and `normals`).
inline std::string objText(const Mesh& mesh, bool normals = false) {
    std::string text = "# written by a CoNUS test\n";
    char line[160];
    for (const glm::vec3& p : mesh.positions) {
        std::snprintf(line, sizeof line, "v %.9g %.9g %.9g\n", p.x, p.y, p.z);
        text += line;
    }
    const bool withNormals = normals && !mesh.normals.empty();
    if (withNormals)
        for (const glm::vec3& n : mesh.normals) {
            std::snprintf(line, sizeof line, "vn %.9g %.9g %.9g\n", n.x, n.y, n.z);
            text += line;
        }
    for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
        const unsigned a = mesh.indices[t] + 1, b = mesh.indices[t + 1] + 1, c = mesh.indices[t + 2] + 1;
        if (withNormals)
            std::snprintf(line, sizeof line, "f %u//%u %u//%u %u//%u\n", a, a, b, b, c, c);
        else
            std::snprintf(line, sizeof line, "f %u %u %u\n", a, b, c);
        text += line;
    }
    return text;
}

inline void writeText(const std::string& path, const std::string& text) {
    std::ofstream out(path, std::ios::binary);
    out << text;
    ASSERT_TRUE(out.good()) << path;
}

// A glTF cube (eight corners, twelve triangles) at `path` with its buffer beside it (`<stem>.bin`);
// `badIndex` >= 0: the sixth triangle's last corner becomes that index (past the eight vertices
// for 8 and up).
inline void writeGltfCube(const std::filesystem::path& path, int badIndex = -1) {
    const float corners[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    std::uint16_t indices[36] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                 2, 3, 7, 2, 7, 6, 1, 2, 6, 1, 6, 5, 0, 4, 7, 0, 7, 3};
    if (badIndex >= 0) indices[17] = static_cast<std::uint16_t>(badIndex);
    std::string buffer(reinterpret_cast<const char*>(indices), sizeof indices);
    buffer.append(reinterpret_cast<const char*>(corners), sizeof corners);
    const std::string bin = path.stem().string() + ".bin";
    writeText((path.parent_path() / bin).string(), buffer);
    writeText(path.string(),
              "{\"asset\": {\"version\": \"2.0\"}, \"scenes\": [{\"nodes\": [0]}], \"nodes\": [{\"mesh\": 0}],\n"
              " \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 1}, \"indices\": 0}]}],\n"
              " \"buffers\": [{\"byteLength\": 168, \"uri\": \"" + bin + "\"}],\n"
              " \"bufferViews\": [{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": 72},\n"
              "                 {\"buffer\": 0, \"byteOffset\": 72, \"byteLength\": 96}],\n"
              " \"accessors\": [{\"bufferView\": 0, \"componentType\": 5123, \"count\": 36, \"type\": \"SCALAR\"},\n"
              "               {\"bufferView\": 1, \"componentType\": 5126, \"count\": 8, \"type\": \"VEC3\",\n"
              "                \"min\": [0, 0, 0], \"max\": [1, 1, 1]}]}\n");
}

}  // namespace conus::test
