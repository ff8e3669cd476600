// The policy for files a scene file names (sceneio/named_files.h), through each loader that opens
// such files: glTF buffers (Assimp's IOSystem), OBJ material libraries, textures, NRRD data files
// (checked before teem opens anything). Each escape (absolute, "..", a symbolic link out of the
// folder), each non-regular file (FIFO, device) and each lying length is refused with a one-line
// conus::Error naming the scene file; an allowed folder lets the same file read.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <zlib.h>

#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "conus/core/error.h"
#include "conus/sceneio/mesh_file.h"
#include "conus/sceneio/named_files.h"
#include "conus/sceneio/volume_file.h"
#include "test_dir.h"

namespace conus::sceneio {
namespace {

namespace fs = std::filesystem;
using test::TestDir;

void writeBytes(const fs::path& path, const std::string& bytes) {
    std::ofstream(path, std::ios::binary) << bytes;
}

// Three float32 corners of one triangle: (0,0,0), (2,0,0), (0,3,0).
std::string trianglePositions() {
    const float p[9] = {0, 0, 0, 2, 0, 0, 0, 3, 0};
    return std::string(reinterpret_cast<const char*>(p), sizeof p);
}

std::string gltfNaming(const std::string& uri, int byteLength = 36) {
    return R"({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "scene": 0, "nodes": [{"mesh": 0}],
 "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}], "buffers": [{"uri": ")" + uri +
           R"(", "byteLength": )" + std::to_string(byteLength) + R"(}],
 "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}],
 "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [2, 3, 0]}]})";
}

// A name a scene file may not give a file it reads, with the reason its refusal says.
struct BadName {
    std::string name, reason;
};
// Each escape: absolute, "..", a symbolic link out of the folder, a FIFO (a reader would block on
// it forever); the folder beside the scene's is added by each test, with its own file.
std::vector<BadName> namesOutOfFolder(const std::string& besideFile) {
    return {{"/etc/passwd", "an absolute path"},
            {"/dev/zero", "an absolute path"},
            {"../../../../../../../../etc/passwd", "outside its folder"},
            {"../outside/" + besideFile, "outside its folder"},
            {"link.bin", "outside its folder"},
            {"fifo.bin", "not a regular file"}};
}

struct Refusal {
    ErrorCode code = ErrorCode::InvalidArgument;
    std::string message;
};

template <class F>
Refusal refusal(F&& read) {
    try {
        read();
    } catch (const Error& e) {
        return {e.code(), e.what()};
    }
    ADD_FAILURE() << "read";
    return {};
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

// model/ holds the scene files and a good buffer; outside/ a buffer out of model/'s reach.
class NamedFilesTest : public ::testing::Test {
protected:
    void SetUp() override {
        fs::create_directories(model());
        fs::create_directories(outside());
        writeBytes(model() / "tri.bin", trianglePositions());
        writeBytes(outside() / "tri.bin", trianglePositions());
        fs::create_symlink(outside() / "tri.bin", model() / "link.bin");
        ASSERT_EQ(::mkfifo((model() / "fifo.bin").c_str(), 0600), 0);
    }
    fs::path model() const { return m_dir.path() / "model"; }
    fs::path outside() const { return m_dir.path() / "outside"; }
    std::string scene(const std::string& name, const std::string& text) const {
        writeBytes(model() / name, text);
        return (model() / name).string();
    }
    // A refusal of a mesh or volume read: Io, one line, naming the scene file.
    static void expectRefused(const Refusal& r, const std::string& path, const std::string& reason) {
        EXPECT_EQ(r.code, ErrorCode::Io) << r.message;
        EXPECT_FALSE(contains(r.message, "\n")) << r.message;
        EXPECT_TRUE(contains(r.message, path)) << r.message;
        EXPECT_TRUE(contains(r.message, reason)) << r.message;
    }

    TestDir m_dir{"conus-named-files"};
};

TEST_F(NamedFilesTest, AGltfBufferInTheModelsFolderReads) {
    const Mesh mesh = readMesh(scene("tri.gltf", gltfNaming("tri.bin")));
    ASSERT_EQ(mesh.indices.size(), 3u);
    EXPECT_EQ(mesh.positions[mesh.indices[1]], glm::vec3(2, 0, 0));
    EXPECT_EQ(mesh.positions[mesh.indices[2]], glm::vec3(0, 3, 0));
}

TEST_F(NamedFilesTest, AGltfBufferOutsideTheFolderIsRefused) {
    for (const BadName& c : namesOutOfFolder("tri.bin")) {
        SCOPED_TRACE(c.name);
        const std::string path = scene("escape.gltf", gltfNaming(c.name));
        expectRefused(refusal([&] { readMesh(path); }), path, c.reason);
    }
}

TEST_F(NamedFilesTest, AnAllowedFolderLetsAGltfBufferRead) {
    const std::string path = scene("allowed.gltf", gltfNaming("../outside/tri.bin"));
    MeshReadOptions options;
    options.allowedDirs = {outside().string()};
    EXPECT_EQ(readMesh(path, options).indices.size(), 3u);
    options.allowedDirs = {(m_dir.path() / "missing").string()};
    EXPECT_EQ(refusal([&] { readMesh(path, options); }).code, ErrorCode::InvalidArgument);
}

TEST_F(NamedFilesTest, AnObjMaterialLibraryOrTextureOutsideTheFolderIsRefused) {
    const std::string cube = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl a\nf 1/1 2/2 3/3\n";
    writeBytes(outside() / "m.mtl", "newmtl a\nKd 1 0 0\n");
    std::string path = scene("lib.obj", "mtllib ../outside/m.mtl\n" + cube);
    expectRefused(refusal([&] { readMesh(path); }), path, "outside its folder");
    path = scene("tex.obj", "mtllib t.mtl\n" + cube);
    writeBytes(model() / "t.mtl", "newmtl a\nKd 1 1 1\nmap_Kd /etc/hostname\n");
    expectRefused(refusal([&] { readMesh(path); }), path, "an absolute path");
    writeBytes(model() / "t.mtl", "newmtl a\nKd 1 1 1\nmap_Kd fifo.bin\n");
    expectRefused(refusal([&] { readMesh(path); }), path, "not a regular file");
    // A texture that is not there is left out, as before.
    writeBytes(model() / "t.mtl", "newmtl a\nKd 1 1 1\nmap_Kd missing.png\n");
    EXPECT_FALSE(readMesh(path).texture.has_value());
}

TEST_F(NamedFilesTest, GlbChunkLengthsMustLieInsideTheFile) {
    std::string json = R"({"asset": {"version": "2.0"}})";
    json.resize((json.size() + 3) / 4 * 4, ' ');
    const auto u32 = [](std::uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
    const std::string good = "glTF" + u32(2) + u32(std::uint32_t(20 + json.size())) + u32(std::uint32_t(json.size())) + "JSON" + json;
    std::string lying = good;
    lying.replace(12, 4, u32(0xfffffff0u));
    const std::string path = scene("lying.glb", lying);
    const Refusal r = refusal([&] { readMesh(path); });
    EXPECT_EQ(r.code, ErrorCode::Corrupt) << r.message;
    EXPECT_TRUE(contains(r.message, "GLB chunk 0 declares 4294967280 bytes")) << r.message;
    std::string total = good;
    total.replace(8, 4, u32(1u << 30));
    const std::string path2 = scene("total.glb", total);
    EXPECT_TRUE(contains(refusal([&] { readMesh(path2); }).message, "header declares 1073741824 bytes"));
}

// Assimp's ASCII PLY reader looped forever on this 94-byte header (the mesh harness found it).
TEST_F(NamedFilesTest, APlyHeaderWithoutAnEndIsRefused) {
    const std::string path = scene("endless.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                                                  "property float y\nprop0 0\n0 1 0\n3 0 1 2\n");
    const Refusal r = refusal([&] { readMesh(path); });
    EXPECT_EQ(r.code, ErrorCode::Corrupt) << r.message;
    EXPECT_TRUE(contains(r.message, "its PLY header has a line that is not")) << r.message;
    const std::string odd = scene("odd.ply", "ply@\nformat ascii 1.0\nelement vertex 3\nproperty float x\n");
    EXPECT_TRUE(contains(refusal([&] { readMesh(odd); }).message, "no end_header"));
}

// Assimp tries a .glb or .gltf its own importer refuses as a PLY, reading the header as lines ended by
// \n, \r, \0 or \f after skipping empty ones: a 241-byte .glb of that kind held its PLY reader for
// minutes (the mesh harness found it). The header check reads the lines as Assimp does, whatever
// the file's name.
TEST_F(NamedFilesTest, APlyHeaderBehindLineEndsIsCheckedWhateverTheName) {
    const std::string header = std::string("\n\rply\nformat ascii 1.0\nelement vertex 3") + '\0' +
                               "x 3\nproperty float x\nend_header\n0\n1\n2\n";
    for (const char* name : {"hidden.glb", "hidden.gltf", "hidden.ply"}) {
        const Refusal r = refusal([&] { readMesh(scene(name, header)); });
        EXPECT_EQ(r.code, ErrorCode::Corrupt) << name << ": " << r.message;
        EXPECT_TRUE(contains(r.message, "its PLY header has a line that is not")) << name << ": " << r.message;
    }
    // A list of a type the format does not define held Assimp's reader too; so would a format 2.0.
    const std::string list = "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar\xf0\x90 vertex_indices\n"
                             "end_header\n8 0 0\n";
    EXPECT_TRUE(contains(refusal([&] { readMesh(scene("list.ply", list)); }).message, "a property line the format"));
    const std::string format = "ply\nformat ascii 2.0\nelement vertex 1\nproperty float x\nend_header\n0\n";
    EXPECT_TRUE(contains(refusal([&] { readMesh(scene("format.ply", format)); }).message, "a format line the format"));
    // A whole header with \r\n line ends still reads.
    const std::string fine = "ply\r\nformat ascii 1.0\r\nelement vertex 3\r\nproperty float x\r\nproperty float y\r\n"
                             "property float z\r\nelement face 1\r\nproperty list uchar int vertex_indices\r\n"
                             "end_header\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1 2\r\n";
    EXPECT_EQ(readMesh(scene("fine.ply", fine)).indices.size(), 3u);
}

// Assimp's MTL reader died (SIGSEGV) on a statement before a library's first newmtl, whether the
// library was a .mtl or the OBJ itself (the mesh harness found the second on a GPU machine's cores).
// The refusal names the line, never the statement: a message shows no file's content.
TEST_F(NamedFilesTest, AMaterialLibraryWithAStatementBeforeNewmtlIsRefused) {
    const std::string triangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    scene("early.mtl", "# made by hand\n\nmap_d x.png\nnewmtl red\n");
    Refusal r = refusal([&] { readMesh(scene("early.obj", "mtllib early.mtl\n" + triangle)); });
    EXPECT_EQ(r.code, ErrorCode::Corrupt) << r.message;
    EXPECT_TRUE(contains(r.message, "material library 'early.mtl' has a statement before its first newmtl (non-empty line 2)")) << r.message;
    r = refusal([&] { readMesh(scene("self.obj", std::string("mtllib self.obj") + '\0' + "map_d\n" + triangle)); });
    EXPECT_TRUE(contains(r.message, "material library 'self.obj' has a statement before its first newmtl (non-empty line 1)")) << r.message;
    // Comments and blank lines may come first; a missing library is Assimp's to go on without.
    scene("good.mtl", "# made by hand\r\n\r\nnewmtl red\nKd 1 0 0\nmap_d x.png\n");
    EXPECT_EQ(readMesh(scene("good.obj", "mtllib good.mtl\n" + triangle)).indices.size(), 3u);
    EXPECT_EQ(readMesh(scene("gone.obj", "mtllib gone.mtl\n" + triangle)).indices.size(), 3u);
}

TEST_F(NamedFilesTest, ExactDuplicateTrianglesAreDroppedAndCounted) {
    // One triangle in 50 copies (some reversed, some through repeated vertices) and one other.
    std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 0 0\nv 5 5 5\n";
    for (int i = 0; i < 50; ++i) obj += i % 3 == 0 ? "f 1 2 3\n" : i % 3 == 1 ? "f 3 2 1\n" : "f 1 4 3\n";
    obj += "f 2 5 3\n";
    MeshReadReport report;
    const Mesh mesh = readMesh(scene("copies.obj", obj), {}, &report);
    EXPECT_EQ(mesh.indices.size(), 6u);
    EXPECT_EQ(report.duplicateTriangles, 49);
    EXPECT_EQ(report.degenerateTriangles, 0);
}

// ---- NRRD data files ----

std::string nrrdHeader(const std::string& type, const std::string& sizes, const std::string& encoding) {
    return "NRRD0004\ntype: " + type + "\ndimension: 3\nsizes: " + sizes + "\nencoding: " + encoding + "\n";
}

TEST_F(NamedFilesTest, AnNrrdDataFileInTheFolderReads) {
    writeBytes(model() / "cube.raw", std::string(64, '\x07'));
    const Volume v = readVolume(scene("cube.nhdr", nrrdHeader("uchar", "4 4 4", "raw") + "data file: cube.raw\n"));
    EXPECT_EQ(v.width, 4);
    EXPECT_EQ(v.values.front(), 7.0f);
    // The list form: two files of 32 samples each.
    writeBytes(model() / "a.raw", std::string(32, '\x01'));
    writeBytes(model() / "b.raw", std::string(32, '\x02'));
    const Volume list = readVolume(scene("list.nhdr", nrrdHeader("uchar", "4 4 4", "raw") + "data file: LIST 3\na.raw\nb.raw\n"));
    EXPECT_EQ(list.values.front(), 1.0f);
    EXPECT_EQ(list.values.back(), 2.0f);
}

TEST_F(NamedFilesTest, AnNrrdDataFileOutsideTheFolderOrNotRegularIsRefused) {
    writeBytes(outside() / "cube.raw", std::string(64, '\x07'));
    for (const BadName& c : namesOutOfFolder("cube.raw")) {
        SCOPED_TRACE(c.name);
        const std::string path = scene("escape.nhdr", nrrdHeader("uchar", "4 4 4", "raw") + "data file: " + c.name + "\n");
        expectRefused(refusal([&] { readVolume(path); }), path, c.reason);
    }
    const std::string path = scene("allowed.nhdr", nrrdHeader("uchar", "4 4 4", "raw") + "data file: ../outside/cube.raw\n");
    VolumeReadOptions options;
    options.allowedDirs = {outside().string()};
    EXPECT_EQ(readVolume(path, options).values.back(), 7.0f);
}

// A gzip payload that claims more than deflate can give, or a type whose buffer with the float
// samples passes the read budget, is refused before teem allocates.
TEST_F(NamedFilesTest, NrrdSizesAreCountedBeforeTeemAllocates) {
    std::string zeros(4096, '\0');
    uLongf packedSize = compressBound(zeros.size());
    std::string packed(packedSize, '\0');
    ASSERT_EQ(compress2(reinterpret_cast<Bytef*>(packed.data()), &packedSize, reinterpret_cast<const Bytef*>(zeros.data()),
                        zeros.size(), 9), Z_OK);
    packed.resize(packedSize);
    std::string path = scene("bomb.nrrd", nrrdHeader("uchar", "512 512 512", "gzip") + "\n" + packed);
    Refusal r = refusal([&] { readVolume(path); });
    EXPECT_EQ(r.code, ErrorCode::Corrupt) << r.message;
    EXPECT_TRUE(contains(r.message, "need at least")) << r.message;
    path = scene("doubles.nrrd", nrrdHeader("double", "1024 1024 256", "raw") + "endian: little\n\n");
    r = refusal([&] { readVolume(path); });
    EXPECT_EQ(r.code, ErrorCode::LimitExceeded) << r.message;
    EXPECT_TRUE(contains(r.message, "more than the limit of " + std::to_string(kMaxVolumeReadBytes))) << r.message;
}

TEST_F(NamedFilesTest, BadNrrdGeometryIsBadData) {
    const std::string zero = scene("zero.nrrd", nrrdHeader("uchar", "4 4 4", "raw") +
                                                     "space dimension: 3\nspace directions: (0,0,0) (0,1,0) (0,0,1)\n\n" +
                                                     std::string(64, '\1'));
    EXPECT_EQ(refusal([&] { readVolume(zero); }).code, ErrorCode::Corrupt);
    const std::string huge = scene("huge.nrrd", nrrdHeader("uchar", "4 4 4", "raw") + "spacings: 1e308 1e308 1\n\n" +
                                                     std::string(64, '\1'));
    const Refusal r = refusal([&] { readVolume(huge); });
    EXPECT_EQ(r.code, ErrorCode::Corrupt) << r.message;
    EXPECT_TRUE(contains(r.message, "extent infinite")) << r.message;
}

}  // namespace
}  // namespace conus::sceneio
