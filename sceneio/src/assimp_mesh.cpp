// Mesh files through Assimp: the one file of CoNUS that includes an Assimp header. The scene is
// imported with node transforms baked in (PreTransformVertices), polygons triangulated, points and
// lines dropped, identical vertices joined, UVs flipped to CoNUS's top-left origin; then every
// mesh is copied into one conus::Mesh, checking the caps before anything large is allocated.
#include "conus/sceneio/mesh_file.h"

#include <assimp/DefaultLogger.hpp>
#include <assimp/DefaultIOSystem.h>
#include <assimp/IOStream.hpp>
#include <assimp/Importer.hpp>
#include <assimp/LogStream.hpp>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cstring>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <optional>
#include <iterator>
#include <set>
#include <stdexcept>
#include <sstream>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "conus/core/error.h"
#include "conus/imageio/image_file.h"
#include "conus/sceneio/named_files.h"
#include "extension_pvt.h"
#include "mesh_headers_pvt.h"
#include "scene_screen_pvt.h"

// Debian's Assimp keeps its internal assertions, which abort the process (a hostile PLY reaches
// one in the triangulation step). This definition takes the place of Assimp's own (the library
// calls it through its PLT): the violation becomes an exception that readMesh turns into a
// one-line conus::Error.
namespace Assimp {
void aiAssertViolation(const char* failed, const char* file, int line) {
    throw std::runtime_error(std::string("Assimp's check failed: ") + failed + " (" + file + ":" + std::to_string(line) + ")");
}
}  // namespace Assimp

namespace conus::sceneio {
namespace {

namespace fs = std::filesystem;


// Assimp says some things only in its log: that it dropped faces whose indices point past their
// mesh's vertices (glTF's importer does). While a file is read, its warnings and errors are kept
// here; the logger is Assimp's one global, so reads take turns.
struct AssimpLog : Assimp::LogStream {
    std::string text;
    void write(const char* message) override { text += message; }
};
std::mutex assimpLogMutex;

std::string trimmed(std::string text) {
    const auto space = [](char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; };
    while (!text.empty() && space(text.back())) text.pop_back();
    std::size_t first = 0;
    while (first < text.size() && space(text[first])) ++first;
    return text.substr(first);
}

// Assimp's MTL reader dereferences the material being defined, and dies (SIGSEGV) on a statement
// before a library's first `newmtl`. The first such statement's number among the non-empty lines
// of `library` (a file the policy already allowed), or 0. The statement itself is never quoted: a message shows no
// file's content.
int statementBeforeNewmtl(const fs::path& library) {
    std::error_code ec;
    if (!fs::is_regular_file(library, ec)) return 0;
    AssimpLines mtl(library.string(), std::min<std::uintmax_t>(fs::file_size(library, ec), kMaxNamedFileBytes));
    int number = 0;
    for (std::string statement; mtl.next(statement);) {
        ++number;
        statement = trimmed(statement);
        if (statement.empty() || statement[0] == '#') continue;
        if (statement.rfind("newmtl", 0) == 0) return 0;
        return number;
    }
    return 0;
}

std::string materialRefusal(const std::string& path, const std::string& named, int line) {
    return "mesh '" + path + "': its material library '" + named + "' has a statement before its first newmtl (non-empty line " +
           std::to_string(line) + ")";
}

// An OBJ's material libraries (its `mtllib` lines), as Assimp joins them to the scene's folder
// ("./" for none) as strings ("/m.mtl" is inside the folder): each that exists is checked by the
// policy (named_files.h) before a byte of it is read, then a library with a statement before its
// first newmtl is refused before Assimp reads the OBJ (an OBJ naming itself included). Every other
// file Assimp opens while such an OBJ is read is checked the same way (PolicyIoSystem). Returns
// whether the scene names material libraries at all.
bool checkMaterialLibraries(const std::string& path, std::uintmax_t bytes, const NamedFiles& policy) {
    const std::string folder = path.substr(0, path.find_last_of("\\/") + 1);
    AssimpLines obj(path, bytes);
    bool names = false;
    for (std::string line; obj.next(line);) {
        line = trimmed(line);
        if (line.rfind("mtllib", 0) != 0 || line.size() < 7 || !std::isspace(static_cast<unsigned char>(line[6]))) continue;
        names = true;
        const std::string named = trimmed(line.substr(7));
        const std::string joined = (folder.empty() ? std::string("./") : folder) + named;
        std::error_code ec;
        if (!fs::exists(joined, ec)) continue;  // missing: Assimp goes on without it
        const int statement = statementBeforeNewmtl(policy.check(joined));
        if (statement > 0) throw Error(ErrorCode::Corrupt, materialRefusal(path, named, statement));
    }
    return names;
}

// A binary glTF's header and chunk lengths, which Assimp allocates by: each inside the file.
void checkGlbLengths(const std::string& path, std::uintmax_t bytes) {
    std::ifstream in(path, std::ios::binary);
    unsigned char head[20] = {};
    if (!in.read(reinterpret_cast<char*>(head), sizeof head) || std::memcmp(head, "glTF", 4) != 0) return;
    const auto u32 = [](const unsigned char* p) {
        return std::uint64_t(p[0]) | std::uint64_t(p[1]) << 8 | std::uint64_t(p[2]) << 16 | std::uint64_t(p[3]) << 24;
    };
    const std::uint64_t declared = u32(head + 8);
    if (declared > bytes)
        fail(ErrorCode::Corrupt, path, "its GLB header declares " + std::to_string(declared) + " bytes in a file of " +
                                           std::to_string(bytes));
    // Chunks follow the 12-byte header: a length, a type, then the data (padded to 4 bytes).
    std::uint64_t at = 12;
    for (int chunk = 0; at + 8 <= bytes && chunk < 1024; ++chunk) {
        unsigned char c[8];
        in.seekg(static_cast<std::streamoff>(at));
        if (!in.read(reinterpret_cast<char*>(c), 8)) break;
        const std::uint64_t length = u32(c);
        if (length > bytes - at - 8)
            fail(ErrorCode::Corrupt, path, "GLB chunk " + std::to_string(chunk) + " declares " + std::to_string(length) +
                                               " bytes, past the end of the " + std::to_string(bytes) + "-byte file");
        at += 8 + length;
    }
}

// A .gltf names its buffers and images by URI: each that is not a data: URI is checked by the
// policy before Assimp reads the file, so that an absolute or escaping name is refused in the
// policy's words (the IOSystem below still guards every file Assimp actually opens).
void checkGltfUris(const std::string& path, const NamedFiles& named) {
    const std::string ext = lowerExtension(path);
    if (ext != ".gltf") return;
    std::ifstream in(path, std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const auto skipSpace = [&](std::size_t at) {
        while (at < text.size() && std::isspace(static_cast<unsigned char>(text[at]))) ++at;
        return at;
    };
    for (std::size_t at = 0; (at = text.find("\"uri\"", at)) != std::string::npos;) {
        at = skipSpace(at + 5);
        if (at >= text.size() || text[at] != ':') continue;
        at = skipSpace(at + 1);
        if (at >= text.size() || text[at] != '"') continue;
        std::string uri;
        for (++at; at < text.size() && text[at] != '"'; ++at) uri += text[at] == '\\' && at + 1 < text.size() ? text[++at] : text[at];
        if (uri.rfind("data:", 0) == 0) continue;
        std::error_code ec;
        if (!fs::path(uri).is_absolute() && !fs::exists(fs::path(named.folder()) / uri, ec)) continue;  // Assimp says it is missing
        named.resolve(uri);
    }
}

// A stream Assimp opened, registered with its IOSystem until it is deleted (Assimp's glTF
// importer leaves a buffer's stream open when it throws on a lying byteLength; the IOSystem
// deletes what is left when the importer is done).
class TrackedStream : public Assimp::IOStream {
public:
    TrackedStream(Assimp::IOStream* stream, std::set<TrackedStream*>& open) : m_stream(stream), m_open(open) {
        m_open.insert(this);
    }
    ~TrackedStream() override {
        m_open.erase(this);
        delete m_stream;
    }
    size_t Read(void* buffer, size_t size, size_t count) override { return m_stream->Read(buffer, size, count); }
    size_t Write(const void* buffer, size_t size, size_t count) override { return m_stream->Write(buffer, size, count); }
    aiReturn Seek(size_t offset, aiOrigin origin) override { return m_stream->Seek(offset, origin); }
    size_t Tell() const override { return m_stream->Tell(); }
    size_t FileSize() const override { return m_stream->FileSize(); }
    void Flush() override { m_stream->Flush(); }

private:
    Assimp::IOStream* m_stream;
    std::set<TrackedStream*>& m_open;
};

// Every file Assimp opens for the scene (glTF buffers, OBJ material libraries, ...) goes through
// here: the scene file itself, or a name the policy of named_files.h allows. A name it refuses is
// reported as missing to Assimp and remembered, so that the read fails with the policy's reason
// instead of going on without the file.
class PolicyIoSystem : public Assimp::DefaultIOSystem {
public:
    PolicyIoSystem(std::string scene, const NamedFiles& named, bool materialLibraries)
        : m_scene(std::move(scene)), m_named(named), m_materialLibraries(materialLibraries) {}
    ~PolicyIoSystem() override {
        while (!m_open.empty()) delete *m_open.begin();
    }

    bool Exists(const char* file) const override {
        const std::string resolved = allowed(file);
        return !resolved.empty() && DefaultIOSystem::Exists(resolved.c_str());
    }
    Assimp::IOStream* Open(const char* file, const char* mode) override {
        if (std::strpbrk(mode, "wa+")) return nullptr;  // a reader writes nothing
        const std::string resolved = allowed(file);
        Assimp::IOStream* stream = resolved.empty() ? nullptr : DefaultIOSystem::Open(resolved.c_str(), mode);
        return stream ? new TrackedStream(stream, m_open) : nullptr;
    }
    void Close(Assimp::IOStream* stream) override { delete stream; }
    const std::string& refusal() const { return m_refusal; }
    ErrorCode refusalCode() const { return m_refusalCode; }

private:
    // The path to open, or "" (a missing file is simply missing; a refusal is remembered).
    std::string allowed(const char* file) const {
        if (file == m_scene) return m_scene;
        std::error_code ec;
        if (!fs::exists(file, ec)) return {};
        try {
            const std::string resolved = m_named.check(file);
            if (static_cast<std::int64_t>(fs::file_size(resolved, ec)) > kMaxNamedFileBytes || ec)
                throw Error(ErrorCode::LimitExceeded, "mesh '" + m_scene + "': names '" + file + "', larger than the limit of " +
                                                          std::to_string(kMaxNamedFileBytes) + " bytes");
            // A scene that names material libraries is read as an OBJ: what Assimp opens for it
            // (a library, or its fallback) is a library to Assimp's MTL reader.
            const int statement = m_materialLibraries ? statementBeforeNewmtl(resolved) : 0;
            if (statement > 0) throw Error(ErrorCode::Corrupt, materialRefusal(m_scene, file, statement));
            return resolved;
        } catch (const Error& e) {
            if (m_refusal.empty()) {
                m_refusal = e.what();
                m_refusalCode = e.code();
            }
            return {};
        }
    }

    std::string m_scene;
    const NamedFiles& m_named;
    bool m_materialLibraries;
    mutable std::string m_refusal;
    mutable ErrorCode m_refusalCode = ErrorCode::Io;
    std::set<TrackedStream*> m_open;
};

// The file's own checks, before anything it names is looked at. Returns its size in bytes.
std::uintmax_t checkFile(const std::string& path, const MeshReadOptions& options) {
    std::error_code ec;
    const fs::file_status status = fs::status(path, ec);
    if (ec || !fs::exists(status)) fail(ErrorCode::Io, path, "no such file");
    if (!fs::is_regular_file(status)) fail(ErrorCode::Io, path, "not a regular file");
    const std::uintmax_t bytes = fs::file_size(path, ec);
    if (ec) fail(ErrorCode::Io, path, "cannot read its size: " + ec.message());
    if (bytes == 0) fail(ErrorCode::Corrupt, path, "the file is empty");
    if (static_cast<std::int64_t>(bytes) > options.maxFileBytes)
        fail(ErrorCode::LimitExceeded, path, std::to_string(bytes) + " bytes, more than the limit of " +
                                                 std::to_string(options.maxFileBytes));
    checkPlyCounts(path, bytes, options);
    checkOffCounts(path, bytes, options);
    checkGlbLengths(path, bytes);
    screenSceneText(path, bytes, {options.maxTriangles, kMaxSceneNodes, kMaxSceneDepth, kMaxMarkupDepth}, "mesh '" + path + "'");
    return bytes;
}

// The imported node tree, before PreTransformVertices copies each mesh once per node that names
// it: its depth, its nodes and the faces it instances, within the caps (walked without recursion).
void checkNodeTree(const aiScene& scene, const MeshReadOptions& options, const std::string& path) {
    if (!scene.mRootNode) return;
    std::vector<std::pair<const aiNode*, int>> stack{{scene.mRootNode, 1}};
    std::int64_t nodes = 0, faces = 0;
    while (!stack.empty()) {
        const auto [node, depth] = stack.back();
        stack.pop_back();
        if (depth > kMaxSceneDepth)
            fail(ErrorCode::LimitExceeded, path, "its node tree is more than " + std::to_string(kMaxSceneDepth) +
                                                     " nodes deep, the limit");
        if (++nodes > kMaxSceneNodes)
            fail(ErrorCode::LimitExceeded, path, "its node tree holds more than " + std::to_string(kMaxSceneNodes) +
                                                     " nodes, the limit");
        for (unsigned m = 0; m < node->mNumMeshes; ++m)
            if (node->mMeshes[m] < scene.mNumMeshes && scene.mMeshes[node->mMeshes[m]])
                faces += scene.mMeshes[node->mMeshes[m]]->mNumFaces;
        if (faces > options.maxTriangles)
            fail(ErrorCode::LimitExceeded, path, "its nodes instance more than " + std::to_string(options.maxTriangles) +
                                                     " faces, the limit (counted before any instance is expanded)");
        for (unsigned c = 0; c < node->mNumChildren; ++c)
            if (node->mChildren[c]) stack.emplace_back(node->mChildren[c], depth + 1);
    }
}

// glTF states its vertex colours in linear light; the older formats (PLY, OBJ extensions, OFF)
// store the display values their authors picked, i.e. sRGB.
bool coloursAreLinear(const std::string& path) {
    const std::string ext = lowerExtension(path);
    return ext == ".gltf" || ext == ".glb";
}

// The base-colour texture file of the first material that names one on disk, or "".
std::string textureFile(const aiScene& scene, const NamedFiles& named) {
    for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
        const aiMesh& mesh = *scene.mMeshes[m];
        if (!mesh.HasTextureCoords(0) || mesh.mMaterialIndex >= scene.mNumMaterials) continue;
        const aiMaterial& material = *scene.mMaterials[mesh.mMaterialIndex];
        for (aiTextureType type : {aiTextureType_BASE_COLOR, aiTextureType_DIFFUSE}) {
            aiString name;
            if (material.GetTextureCount(type) == 0 || material.GetTexture(type, 0, &name) != AI_SUCCESS) continue;
            std::string file = name.C_Str();
            if (file.empty() || file[0] == '*') continue;  // embedded textures are not read (yet)
            for (char& c : file)
                if (c == '\\') c = '/';
            // A texture that is not there is left out; one the policy refuses refuses the mesh.
            std::error_code ec;
            if (!fs::path(file).is_absolute() && !fs::exists(fs::path(named.folder()) / file, ec)) continue;
            return named.resolve(file);
        }
    }
    return {};
}

// Drops exact duplicate triangles (the same three corner positions, in any order or orientation),
// keeping the first; returns how many went. Equal positions are welded by sorting, so the work is
// O(n log n) whatever the file holds.
std::int64_t dropDuplicateTriangles(Mesh& mesh) {
    const std::size_t vertices = mesh.positions.size(), triangles = mesh.indices.size() / 3;
    const auto position = [&](std::uint32_t i) {
        const glm::vec3& p = mesh.positions[i];
        return std::array<float, 3>{p.x, p.y, p.z};
    };
    std::vector<std::uint32_t> order(vertices), weld(vertices);
    for (std::size_t i = 0; i < vertices; ++i) order[i] = static_cast<std::uint32_t>(i);
    std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return position(a) < position(b); });
    for (std::size_t k = 0; k < vertices; ++k)
        weld[order[k]] = k > 0 && position(order[k]) == position(order[k - 1]) ? weld[order[k - 1]] : order[k];
    struct Corners {
        std::array<std::uint32_t, 3> welded;
        std::uint32_t triangle;
    };
    std::vector<Corners> keys(triangles);
    for (std::size_t t = 0; t < triangles; ++t) {
        keys[t] = {{weld[mesh.indices[t * 3]], weld[mesh.indices[t * 3 + 1]], weld[mesh.indices[t * 3 + 2]]},
                   static_cast<std::uint32_t>(t)};
        std::sort(keys[t].welded.begin(), keys[t].welded.end());
    }
    std::sort(keys.begin(), keys.end(), [](const Corners& a, const Corners& b) {
        return a.welded != b.welded ? a.welded < b.welded : a.triangle < b.triangle;
    });
    std::vector<bool> duplicate(triangles, false);
    std::int64_t dropped = 0;
    for (std::size_t k = 1; k < triangles; ++k)
        if (keys[k].welded == keys[k - 1].welded) {
            duplicate[keys[k].triangle] = true;
            ++dropped;
        }
    if (dropped == 0) return 0;
    std::size_t kept = 0;
    for (std::size_t t = 0; t < triangles; ++t) {
        if (duplicate[t]) continue;
        for (int c = 0; c < 3; ++c) mesh.indices[kept * 3 + c] = mesh.indices[t * 3 + c];
        ++kept;
    }
    mesh.indices.resize(kept * 3);
    return dropped;
}

}  // namespace

Mesh readMesh(const std::string& path, const MeshReadOptions& options, MeshReadReport* report) {
    MeshReadReport counts;
    const std::uintmax_t bytes = checkFile(path, options);
    const NamedFiles named(path, options.allowedDirs, "mesh '" + path + "'");
    const bool materialLibraries = checkMaterialLibraries(path, bytes, named);
    checkGltfUris(path, named);
    Assimp::Importer importer;
    auto* io = new PolicyIoSystem(path, named, materialLibraries);
    importer.SetIOHandler(io);  // the importer owns it
    // Points and lines are not surfaces: SortByPType drops them.
    importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    const unsigned flags = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_SortByPType |
                           aiProcess_PreTransformVertices | aiProcess_FlipUVs | aiProcess_ValidateDataStructure;
    const aiScene* scene = nullptr;
    AssimpLog log;
    std::string thrown;  // Assimp's own exceptions (its asserts among them), said after the logger is detached
    std::optional<Error> refused;  // ours
    {
        const std::lock_guard<std::mutex> lock(assimpLogMutex);
        const bool created = Assimp::DefaultLogger::isNullLogger();
        if (created) Assimp::DefaultLogger::create("", Assimp::Logger::NORMAL, 0);
        Assimp::DefaultLogger::get()->attachStream(&log, Assimp::Logger::Warn | Assimp::Logger::Err);
        try {
            // Imported as it is, its node tree checked, then post-processed: the same steps in the
            // same order as ReadFile(path, flags), but PreTransformVertices (which copies a mesh
            // once per node that uses it) only runs on a tree within the caps.
            scene = importer.ReadFile(path, 0);
            if (scene) {
                checkNodeTree(*scene, options, path);
                scene = importer.ApplyPostProcessing(flags);
            }
        } catch (const Error& e) {
            refused = e;
        } catch (const std::exception& e) {
            thrown = e.what();
        }
        Assimp::DefaultLogger::get()->detachStream(&log, Assimp::Logger::Warn | Assimp::Logger::Err);
        if (created) Assimp::DefaultLogger::kill();
    }
    if (refused) throw *refused;
    if (!thrown.empty()) fail(ErrorCode::Corrupt, path, thrown);
    if (!io->refusal().empty()) throw Error(io->refusalCode(), io->refusal());
    if (scene && log.text.find("out-of-range indices") != std::string::npos)
        fail(ErrorCode::Corrupt, path, "a face indexes past its mesh's vertices");
    if (!scene) {
        std::string why = importer.GetErrorString();
        if (why.empty()) why = "Assimp could not read it";
        // Assimp says "No suitable reader found" for formats it does not know.
        const bool unknown = why.find("suitable reader") != std::string::npos;
        if (why.find("bad_alloc") != std::string::npos)
            fail(ErrorCode::LimitExceeded, path, "it asks for more memory than there is (" + why + ")");
        fail(unknown ? ErrorCode::Io : ErrorCode::Corrupt, path, why);
    }

    // Count first, in 64 bits, against the caps.
    std::int64_t vertices = 0, triangles = 0;
    bool allNormals = true, anyColours = false;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
        const aiMesh& mesh = *scene->mMeshes[m];
        if (!(mesh.mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
        vertices += mesh.mNumVertices;
        triangles += mesh.mNumFaces;
        allNormals = allNormals && mesh.HasNormals();
        anyColours = anyColours || mesh.HasVertexColors(0);
    }
    if (triangles == 0) fail(ErrorCode::Corrupt, path, "the file holds no triangles");
    if (triangles > options.maxTriangles)
        fail(ErrorCode::LimitExceeded, path, std::to_string(triangles) + " triangles, more than the limit of " +
                                                 std::to_string(options.maxTriangles));
    if (vertices > options.maxVertices || vertices > std::int64_t{UINT32_MAX})
        fail(ErrorCode::LimitExceeded, path, std::to_string(vertices) + " vertices, more than the limit of " +
                                                 std::to_string(options.maxVertices));

    const std::string texturePath = options.readTexture ? textureFile(*scene, named) : std::string();
    Mesh out;
    out.positions.reserve(static_cast<std::size_t>(vertices));
    out.indices.reserve(static_cast<std::size_t>(triangles) * 3);
    if (allNormals) out.normals.reserve(static_cast<std::size_t>(vertices));
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
        const aiMesh& mesh = *scene->mMeshes[m];
        if (!(mesh.mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
        const std::uint32_t base = static_cast<std::uint32_t>(out.positions.size());
        for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
            const aiVector3D& p = mesh.mVertices[v];
            out.positions.emplace_back(p.x, p.y, p.z);
            if (allNormals) out.normals.emplace_back(mesh.mNormals[v].x, mesh.mNormals[v].y, mesh.mNormals[v].z);
            if (anyColours) {
                const aiColor4D c = mesh.HasVertexColors(0) ? mesh.mColors[0][v] : aiColor4D(1, 1, 1, 1);
                out.colours.emplace_back(c.r, c.g, c.b);
            }
            if (!texturePath.empty()) {
                const aiVector3D uv = mesh.HasTextureCoords(0) ? mesh.mTextureCoords[0][v] : aiVector3D(0, 0, 0);
                out.uvs.emplace_back(uv.x, uv.y);
            }
        }
        for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
            const aiFace& face = mesh.mFaces[f];
            if (face.mNumIndices != 3) continue;
            bool inRange = true;
            for (int k = 0; k < 3; ++k) inRange = inRange && face.mIndices[k] < mesh.mNumVertices;
            if (!inRange) fail(ErrorCode::Corrupt, path, "a face indexes past its mesh's vertices");
            const std::uint32_t a = base + face.mIndices[0], b = base + face.mIndices[1], c = base + face.mIndices[2];
            // Degenerate triangles (a repeated corner or no area) are dropped: they cover nothing.
            const glm::vec3 n = glm::cross(out.positions[b] - out.positions[a], out.positions[c] - out.positions[a]);
            if (a == b || b == c || a == c || !(glm::dot(n, n) > 0.0f)) {
                ++counts.degenerateTriangles;
                continue;
            }
            out.indices.insert(out.indices.end(), {a, b, c});
        }
    }
    for (const glm::vec3& p : out.positions)
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            fail(ErrorCode::Corrupt, path, "a vertex position is not finite");
    if (out.indices.empty()) fail(ErrorCode::Corrupt, path, "every triangle is degenerate (no area)");
    if (counts.degenerateTriangles > 0 && options.warn)
        options.warn("mesh '" + path + "': dropped " + std::to_string(counts.degenerateTriangles) + " of " +
                     std::to_string(triangles) + " triangles, degenerate (a repeated corner or no area)");
    counts.duplicateTriangles = dropDuplicateTriangles(out);
    if (report) *report = counts;

    // The file's normals, unit; one unusable normal and they are all computed instead, so a
    // surface never mixes two rules.
    for (glm::vec3& n : out.normals) {
        const float length = glm::length(n);
        if (!(length > 0.0f) || !std::isfinite(length)) {
            out.normals.clear();
            break;
        }
        n /= length;
    }
    if (out.normals.empty()) computeVertexNormals(out);

    if (!out.colours.empty() && !coloursAreLinear(path)) {
        // Through imageio's conversion (OpenImageIO's), as an image of rows of 4096 colours.
        const int width = static_cast<int>(std::min<std::size_t>(out.colours.size(), 4096));
        const int height = static_cast<int>((out.colours.size() + width - 1) / width);
        Image colours = makeImage(width, height, {"R", "G", "B"});
        for (std::size_t i = 0; i < out.colours.size(); ++i)
            for (int c = 0; c < 3; ++c) colours.pixels[i * 3 + c] = out.colours[i][c];
        imageio::linearize(colours);
        for (std::size_t i = 0; i < out.colours.size(); ++i)
            out.colours[i] = {colours.pixels[i * 3], colours.pixels[i * 3 + 1], colours.pixels[i * 3 + 2]};
    }
    if (!texturePath.empty()) {
        imageio::ReadOptions read;
        out.texture = imageio::readImageFile(texturePath, read).image;
    }
    checkMesh(out, ("mesh '" + path + "'").c_str());
    return out;
}

}  // namespace conus::sceneio
