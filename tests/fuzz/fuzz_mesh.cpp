// Fuzz harness: the mesh reader (sceneio::readMesh, Assimp behind it) on arbitrary bytes, written
// as a file whose extension follows its content (glTF, GLB, PLY, STL, OFF, OBJ, COLLADA, X3D, FBX,
// 3DS; else the first byte picks one) in a folder with files it may name and traps it must not
// open (scene_fixture.h).
// A mesh that reads must satisfy checkMesh, stay within the caps given, and hold no exact
// duplicate triangle; anything else must be a one-line conus::Error.
#include <algorithm>
#include <array>
#include <cmath>
#include <set>
#include <string>

#include "conus/codec/mesh/overdraw.h"
#include "conus/core/error.h"
#include "conus/sceneio/mesh_file.h"
#include "fuzz.h"
#include "scene_fixture.h"

namespace {

std::string extensionOf(const std::uint8_t* data, std::size_t size) {
    if (startsWith(data, size, "glTF")) return "glb";
    if (startsWith(data, size, "{")) return "gltf";
    if (startsWith(data, size, "ply")) return "ply";
    if (startsWith(data, size, "solid")) return "stl";
    if (startsWith(data, size, "OFF")) return "off";
    if (startsWith(data, size, "v ") || startsWith(data, size, "#") || startsWith(data, size, "mtllib")) return "obj";
    if (startsWith(data, size, "<?xml") || startsWith(data, size, "<")) {  // X3D or COLLADA by the root element
        const std::string head(reinterpret_cast<const char*>(data), std::min<std::size_t>(size, 512));
        return head.find("<X3D") != std::string::npos ? "x3d" : "dae";
    }
    if (startsWith(data, size, "Kaydara FBX Binary") || startsWith(data, size, "; FBX")) return "fbx";
    if (startsWith(data, size, "MM")) return "3ds";
    static const char* kAny[] = {"obj", "ply", "stl", "gltf", "glb", "off", "dae", "x3d", "fbx", "3ds"};
    return size == 0 ? "obj" : kAny[data[0] % (sizeof kAny / sizeof *kAny)];
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const SceneFixture fixture("mesh");
    const std::string path = fixture.write(extensionOf(data, size), data, size);
    conus::sceneio::MeshReadOptions options;
    options.maxFileBytes = 1 << 16;
    options.maxTriangles = 1 << 16;
    options.maxVertices = 1 << 17;
    return readOrRefuse([&] {
        const conus::Mesh mesh = conus::sceneio::readMesh(path, options);
        conus::checkMesh(mesh, "fuzzed mesh");
        CONUS_FUZZ_CHECK(mesh.indices.size() / 3 <= std::size_t(options.maxTriangles), "triangle cap");
        CONUS_FUZZ_CHECK(!mesh.indices.empty(), "a mesh that reads has a triangle");
        std::set<std::array<float, 9>> seen;
        for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
            std::array<std::array<float, 3>, 3> corners;
            for (int c = 0; c < 3; ++c) {
                const glm::vec3& p = mesh.positions[mesh.indices[t + c]];
                corners[c] = {p.x, p.y, p.z};
            }
            std::sort(corners.begin(), corners.end());
            std::array<float, 9> key;
            for (int c = 0; c < 9; ++c) key[c] = corners[c / 3][c % 3];
            CONUS_FUZZ_CHECK(seen.insert(key).second, "no exact duplicate triangle survives");
        }
        // What the GL renders check first: a finite count, one surface at most for one triangle.
        const double overdraw = conus::codec::meshOverdraw(mesh);
        CONUS_FUZZ_CHECK(std::isfinite(overdraw) && overdraw >= 0, "meshOverdraw is a finite count");
        CONUS_FUZZ_CHECK(mesh.indices.size() != 3 || overdraw <= 1.0 + 1e-6, "one triangle is one surface");
    });
}
