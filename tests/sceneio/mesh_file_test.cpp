// readMesh on the five shared models, on procedural shapes with known normals, on textures and
// vertex colours, and on broken or hostile files written here: each refused with a one-line
// conus::Error, never a crash.
#include <gtest/gtest.h>

#include <fstream>
#include <random>
#include <sstream>

#include "conus/core/error.h"
#include "conus/imageio/image_file.h"
#include "conus/sceneio/mesh_file.h"
#include "sceneio/test_meshes.h"
#include "test_dir.h"

namespace conus::sceneio {
namespace {

using test::TestDir;

// Triangles an OBJ's faces make once triangulated (n - 2 for an n-gon).
std::size_t objTriangles(const std::filesystem::path& path) {
    std::ifstream in(path);
    std::string line;
    std::size_t triangles = 0;
    while (std::getline(in, line)) {
        if (line.rfind("f ", 0) != 0) continue;
        std::istringstream words(line.substr(2));
        std::string word;
        int corners = 0;
        while (words >> word) ++corners;
        triangles += corners >= 3 ? corners - 2 : 0;
    }
    return triangles;
}

void expectWellFormed(const Mesh& mesh) {
    EXPECT_NO_THROW(checkMesh(mesh, "test"));
    ASSERT_EQ(mesh.normals.size(), mesh.positions.size());
    for (const glm::vec3& n : mesh.normals) ASSERT_NEAR(glm::length(n), 1.0f, 1e-4f);
}

ErrorCode errorOf(const std::string& path, const MeshReadOptions& options = {}) {
    try {
        readMesh(path, options);
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << "the message names the file: " << e.what();
        return e.code();
    }
    ADD_FAILURE() << path << " was read";
    return ErrorCode::InvalidArgument;
}

TEST(ReadMesh, TheFiveSharedModels) {
    CONUS_REQUIRE_SHARED_MESHES();
    for (const std::string& name : test::sharedMeshNames()) {
        SCOPED_TRACE(name);
        const auto path = test::sharedMeshes() / name;
        const Mesh mesh = readMesh(path.string());
        expectWellFormed(mesh);
        // Every face of the file is there, triangulated, but for degenerate ones (no area).
        const std::size_t expected = objTriangles(path);
        EXPECT_LE(mesh.triangleCount(), expected);
        EXPECT_GE(mesh.triangleCount(), expected * 99 / 100);
        // Normals point outward on average: the sum over vertices of n . (p - centroid) is positive
        // for these closed-ish models, whichever normals (the file's or computed).
        glm::dvec3 centroid(0.0);
        for (const glm::vec3& p : mesh.positions) centroid += glm::dvec3(p);
        centroid /= double(mesh.positions.size());
        double outward = 0;
        for (std::size_t i = 0; i < mesh.positions.size(); ++i)
            outward += glm::dot(glm::dvec3(mesh.normals[i]), glm::dvec3(mesh.positions[i]) - centroid);
        EXPECT_GT(outward, 0);
        EXPECT_FALSE(mesh.texture.has_value());  // none of them names a texture
    }
}

TEST(ReadMesh, TheBunnyHasItsKnownSize) {
    CONUS_REQUIRE_SHARED_MESHES();
    const Mesh bunny = readMesh((test::sharedMeshes() / "stanford-bunny.obj").string());
    EXPECT_GT(bunny.triangleCount(), 60000u);
    EXPECT_GT(bunny.positions.size(), 30000u);
}

TEST(ReadMesh, ComputedNormalsOfASphereAreRadial) {
    TestDir dir("sceneio");
    const glm::vec3 centre(1.0f, -0.5f, 3.0f);
    const Mesh sphere = test::uvSphere(centre, 2.0f, 48, 96);
    test::writeText(dir.file("sphere.obj"), test::objText(sphere));
    const Mesh read = readMesh(dir.file("sphere.obj"));
    expectWellFormed(read);
    ASSERT_EQ(read.positions.size(), sphere.positions.size());
    for (std::size_t i = 0; i < read.positions.size(); ++i) {
        const glm::vec3 radial = glm::normalize(read.positions[i] - centre);
        EXPECT_GT(glm::dot(read.normals[i], radial), 0.999f) << i;
    }
}

TEST(ReadMesh, ComputedNormalsOfABoxFaceAreTheFaceNormal) {
    // Each face's corners carry their own UV, so no corner is shared between faces and every
    // vertex normal is its face's normal exactly.
    TestDir dir("sceneio");
    std::string obj = "v 0 0 0\nv 2 0 0\nv 0 3 0\nv 2 3 0\nv 0 0 5\nv 2 0 5\nv 0 3 5\nv 2 3 5\n";
    for (int i = 0; i < 24; ++i) obj += "vt " + std::to_string(i / 24.0) + " 0.5\n";
    const int quads[6][4] = {{1, 5, 7, 3}, {2, 4, 8, 6}, {1, 2, 6, 5}, {3, 7, 8, 4}, {1, 3, 4, 2}, {5, 6, 8, 7}};
    for (int f = 0; f < 6; ++f) {
        obj += "f";
        for (int k = 0; k < 4; ++k) obj += " " + std::to_string(quads[f][k]) + "/" + std::to_string(f * 4 + k + 1);
        obj += "\n";
    }
    test::writeText(dir.file("box.obj"), obj);
    const Mesh box = readMesh(dir.file("box.obj"));
    expectWellFormed(box);
    EXPECT_EQ(box.triangleCount(), 12u);
    EXPECT_EQ(box.positions.size(), 24u);
    const glm::vec3 centre(1.0f, 1.5f, 2.5f);
    for (std::size_t i = 0; i < box.positions.size(); ++i) {
        // The face normal: the axis along which the vertex is farthest from the centre, relative
        // to the half size; the normal must be exactly that axis.
        const glm::vec3 n = box.normals[i];
        const float ax = std::abs(n.x), ay = std::abs(n.y), az = std::abs(n.z);
        ASSERT_NEAR(std::max({ax, ay, az}), 1.0f, 1e-6f) << i;
        const int axis = ax > 0.5f ? 0 : ay > 0.5f ? 1 : 2;
        const float side = box.positions[i][axis] - centre[axis];
        EXPECT_GT(side * n[axis], 0) << "vertex " << i << " normal points outward";
    }
}

TEST(ReadMesh, ComputedNormalsAreAreaWeighted) {
    // Two triangles share the edge from (0,0,0) to (0,0,1): one in the plane y = 0 with area 4
    // (normal +y), one in the plane x = 0 with area 1 (normal +x... its winding makes it -x).
    TestDir dir("sceneio");
    test::writeText(dir.file("hinge.obj"), "v 0 0 0\nv 0 0 1\nv 8 0 0\nv 0 2 0\nf 1 2 3\nf 2 1 4\n");
    const Mesh m = readMesh(dir.file("hinge.obj"));
    ASSERT_EQ(m.positions.size(), 4u);
    // cross((0,0,1), (8,0,0)) = (0, 8, 0): area 4, +y. cross((0,0,-1), (0,2,-1)) = (2, 0, 0): area 1, +x.
    const glm::vec3 expected = glm::normalize(glm::vec3(2, 8, 0));
    for (std::size_t i = 0; i < m.positions.size(); ++i)
        if (m.positions[i].x == 0 && m.positions[i].y == 0) {
            EXPECT_NEAR(m.normals[i].x, expected.x, 1e-6f);
            EXPECT_NEAR(m.normals[i].y, expected.y, 1e-6f);
            EXPECT_NEAR(m.normals[i].z, 0.0f, 1e-6f);
        }
}

TEST(ReadMesh, TheFilesNormalsAreKeptAndNormalized) {
    TestDir dir("sceneio");
    test::writeText(dir.file("n.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 3\nvn 0.6 0 0.8\nvn 0 -2 0\nf 1//1 2//2 3//3\n");
    const Mesh m = readMesh(dir.file("n.obj"));
    ASSERT_EQ(m.positions.size(), 3u);
    for (std::size_t i = 0; i < 3; ++i) {
        const glm::vec3 p = m.positions[i], n = m.normals[i];
        const glm::vec3 want = p.x > 0.5f ? glm::vec3(0.6f, 0, 0.8f) : p.y > 0.5f ? glm::vec3(0, -1, 0) : glm::vec3(0, 0, 1);
        EXPECT_NEAR(glm::length(n - want), 0.0f, 1e-6f) << i;
    }
}

TEST(ReadMesh, VertexColoursBecomeLinear) {
    // OBJ's vertex-colour extension ("v x y z r g b") holds display (sRGB) values.
    TestDir dir("sceneio");
    test::writeText(dir.file("c.obj"), "v 0 0 0 1 0 0\nv 1 0 0 0 0.5 0\nv 0 1 0 0 0 0.2\nf 1 2 3\n");
    const Mesh m = readMesh(dir.file("c.obj"));
    ASSERT_EQ(m.colours.size(), 3u);
    auto linear = [](double s) { return s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4); };
    for (std::size_t i = 0; i < 3; ++i) {
        const glm::vec3 p = m.positions[i], c = m.colours[i];
        if (p.x > 0.5f) EXPECT_NEAR(c.g, linear(0.5), 2e-3) << "green 0.5 in sRGB";
        else if (p.y > 0.5f) EXPECT_NEAR(c.b, linear(0.2), 2e-3);
        else EXPECT_NEAR(c.r, 1.0, 1e-4);
    }
}

TEST(ReadMesh, ATexturedQuadGetsItsTextureAndTopLeftUvs) {
    TestDir dir("sceneio");
    // A 4x2 texture, sRGB PNG: a ramp in red, the bottom row blue.
    Image texture = makeImage(4, 2, {"R", "G", "B"});
    for (int x = 0; x < 4; ++x) {
        texture.at(x, 0, 0) = x / 3.0f;
        texture.at(x, 1, 2) = 1.0f;
    }
    imageio::writeImageFile(dir.file("tex.png"), texture);
    test::writeText(dir.file("quad.mtl"), "newmtl checker\nKd 1 1 1\nmap_Kd tex.png\n");
    test::writeText(dir.file("quad.obj"),
                    "mtllib quad.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                    "usemtl checker\nf 1/1 2/2 3/3 4/4\n");
    const Mesh m = readMesh(dir.file("quad.obj"));
    expectWellFormed(m);
    ASSERT_TRUE(m.texture.has_value());
    EXPECT_EQ(m.texture->width, 4);
    EXPECT_EQ(m.texture->height, 2);
    EXPECT_NEAR(m.texture->at(3, 0, 0), 1.0f, 1e-3f);
    EXPECT_NEAR(m.texture->at(1, 1, 2), 1.0f, 1e-3f);
    ASSERT_EQ(m.uvs.size(), m.positions.size());
    for (std::size_t i = 0; i < m.positions.size(); ++i) {
        // OBJ's v grows upward; CoNUS's UV origin is the top-left: v' = 1 - v.
        EXPECT_NEAR(m.uvs[i].x, m.positions[i].x, 1e-6f);
        EXPECT_NEAR(m.uvs[i].y, 1.0f - m.positions[i].y, 1e-6f);
    }
    MeshReadOptions noTexture;
    noTexture.readTexture = false;
    EXPECT_FALSE(readMesh(dir.file("quad.obj"), noTexture).texture.has_value());
}

TEST(ReadMesh, MissingAndUnreadableFiles) {
    TestDir dir("sceneio");
    EXPECT_EQ(errorOf(dir.file("absent.obj")), ErrorCode::Io);
    EXPECT_EQ(errorOf(dir.path().string()), ErrorCode::Io);  // a folder
    test::writeText(dir.file("empty.obj"), "");
    EXPECT_EQ(errorOf(dir.file("empty.obj")), ErrorCode::Corrupt);
    test::writeText(dir.file("comments.obj"), "# nothing but a comment\n\n");
    EXPECT_EQ(errorOf(dir.file("comments.obj")), ErrorCode::Corrupt);
    test::writeText(dir.file("points.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\np 1 2 3\nl 1 2\n");
    EXPECT_EQ(errorOf(dir.file("points.obj")), ErrorCode::Corrupt);  // no surface at all
    test::writeText(dir.file("flat.obj"), "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\nf 1 2 3\nf 2 3 4\n");
    EXPECT_EQ(errorOf(dir.file("flat.obj")), ErrorCode::Corrupt);  // every triangle degenerate
}

TEST(ReadMesh, HostileFilesAreRefused) {
    TestDir dir("sceneio");
    // Random bytes under several extensions.
    std::mt19937 rng(7);
    std::string garbage(4096, '\0');
    for (char& c : garbage) c = char(rng() & 0xFF);
    for (const char* name : {"garbage.obj", "garbage.ply", "garbage.stl", "garbage.gltf", "garbage.xyz"}) {
        SCOPED_TRACE(name);
        test::writeText(dir.file(name), garbage);
        errorOf(dir.file(name));
    }
    // Faces that index past the vertices.
    test::writeText(dir.file("past.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 999999\n");
    errorOf(dir.file("past.obj"));
    test::writeText(dir.file("negative.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -40\n");
    errorOf(dir.file("negative.obj"));
    // A PLY declaring four billion vertices, holding three.
    test::writeText(dir.file("huge.ply"), "ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\n"
                                          "property float y\nproperty float z\nelement face 1\n"
                                          "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    EXPECT_EQ(errorOf(dir.file("huge.ply")), ErrorCode::Corrupt);
    MeshReadOptions fewVertices;
    fewVertices.maxVertices = 2;
    test::writeText(dir.file("three.ply"), "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                                           "property float y\nproperty float z\nelement face 1\n"
                                           "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    EXPECT_EQ(errorOf(dir.file("three.ply"), fewVertices), ErrorCode::LimitExceeded);
    EXPECT_EQ(readMesh(dir.file("three.ply")).triangleCount(), 1u);
    // A binary STL whose header declares 2^31 triangles in a file of one.
    std::string stl(80, ' ');
    const std::uint32_t count = 0x80000000u;
    stl.append(reinterpret_cast<const char*>(&count), 4);
    stl.append(50, '\0');
    test::writeText(dir.file("huge.stl"), stl);
    errorOf(dir.file("huge.stl"));
}

// A glTF face that indexes past its vertices: Assimp drops it and says so only in its log; the
// read refuses the file instead. The same cube with every index in range reads whole.
TEST(ReadMesh, GltfIndicesPastTheVerticesAreRefused) {
    TestDir dir("sceneio");
    test::writeGltfCube(dir.file("cube.gltf"));
    EXPECT_EQ(readMesh(dir.file("cube.gltf")).triangleCount(), 12u);
    test::writeGltfCube(dir.file("past.gltf"), 9);
    try {
        readMesh(dir.file("past.gltf"));
        ADD_FAILURE() << "read";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::Corrupt);
        EXPECT_NE(std::string(e.what()).find("indexes past"), std::string::npos) << e.what();
        EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    }
    // Read again in range afterwards: nothing of the first read's log is left over.
    EXPECT_EQ(readMesh(dir.file("cube.gltf")).triangleCount(), 12u);
}

// Degenerate triangles are dropped and the warning says how many of how many.
TEST(ReadMesh, DroppedDegenerateTrianglesAreCounted) {
    TestDir dir("sceneio");
    test::writeText(dir.file("some.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\nf 2 3 3\nf 1 4 3\n");
    std::vector<std::string> said;
    MeshReadOptions options;
    options.warn = [&](const std::string& text) { said.push_back(text); };
    EXPECT_EQ(readMesh(dir.file("some.obj"), options).triangleCount(), 2u);
    ASSERT_EQ(said.size(), 1u);
    EXPECT_NE(said[0].find("dropped 2 of 4 triangles"), std::string::npos) << said[0];
    said.clear();
    test::writeText(dir.file("fine.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    readMesh(dir.file("fine.obj"), options);
    EXPECT_TRUE(said.empty());
}

TEST(ReadMesh, CapsOnBytesAndTriangles) {
    TestDir dir("sceneio");
    const Mesh sphere = test::uvSphere({0, 0, 0}, 1.0f, 16, 32);
    test::writeText(dir.file("s.obj"), test::objText(sphere));
    MeshReadOptions small;
    small.maxFileBytes = 100;
    EXPECT_EQ(errorOf(dir.file("s.obj"), small), ErrorCode::LimitExceeded);
    MeshReadOptions few;
    few.maxTriangles = std::int64_t(sphere.triangleCount()) - 1;
    EXPECT_EQ(errorOf(dir.file("s.obj"), few), ErrorCode::LimitExceeded);
    few.maxTriangles = std::int64_t(sphere.triangleCount());
    EXPECT_EQ(readMesh(dir.file("s.obj"), few).triangleCount(), sphere.triangleCount());
    MeshReadOptions fewVertices;
    fewVertices.maxVertices = 10;
    EXPECT_EQ(errorOf(dir.file("s.obj"), fewVertices), ErrorCode::LimitExceeded);
}

}  // namespace
}  // namespace conus::sceneio
