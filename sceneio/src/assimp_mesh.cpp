// Mesh files through Assimp: the one file of CoNUS that includes an Assimp header. The scene is
// imported with node transforms baked in (PreTransformVertices), polygons triangulated, points and
// lines dropped, identical vertices joined, UVs flipped to CoNUS's top-left origin; then every
// mesh is copied into one conus::Mesh, checking the caps before anything large is allocated.
#include "conus/sceneio/mesh_file.h"

#include <assimp/DefaultLogger.hpp>
#include <assimp/Importer.hpp>
#include <assimp/LogStream.hpp>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <string>
#include <system_error>

#include "conus/core/error.h"
#include "conus/imageio/image_file.h"

namespace conus::sceneio {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void fail(ErrorCode code, const std::string& path, const std::string& why) {
    throw Error(code, "mesh '" + path + "': " + why);
}

// Assimp says some things only in its log: that it dropped faces whose indices point past their
// mesh's vertices (glTF's importer does). While a file is read, its warnings and errors are kept
// here; the logger is Assimp's one global, so reads take turns.
struct AssimpLog : Assimp::LogStream {
    std::string text;
    void write(const char* message) override { text += message; }
};
std::mutex assimpLogMutex;

// PLY headers declare their element counts up front and Assimp reserves memory for them before
// reading a single vertex; a count no file of this size can hold (every element takes at least a
// byte) or one past the caps is refused here, before Assimp sees the file.
void checkPlyCounts(const std::string& path, std::uintmax_t bytes, const MeshReadOptions& options) {
    std::ifstream in(path, std::ios::binary);
    std::string line;
    if (!std::getline(in, line) || (line != "ply" && line != "ply\r" && line != "PLY" && line != "PLY\r")) return;
    for (int n = 0; n < 10000 && std::getline(in, line); ++n) {
        if (line.rfind("end_header", 0) == 0) return;
        std::istringstream words(line);
        std::string keyword, element;
        long double count = 0;
        if (!(words >> keyword >> element >> count) || keyword != "element") continue;
        const std::int64_t cap = element == "vertex" ? options.maxVertices : element == "face" ? options.maxTriangles : -1;
        if (count > static_cast<long double>(bytes))
            fail(ErrorCode::Corrupt, path, "its header declares " + numberText(double(count)) + " " + element +
                                               " elements in a file of " + std::to_string(bytes) + " bytes");
        if (cap >= 0 && count > static_cast<long double>(cap))
            fail(ErrorCode::LimitExceeded, path, "its header declares " + numberText(double(count)) + " " + element +
                                                     " elements, more than the limit of " + std::to_string(cap));
    }
}

void checkFile(const std::string& path, const MeshReadOptions& options) {
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
}

// glTF states its vertex colours in linear light; the older formats (PLY, OBJ extensions, OFF)
// store the display values their authors picked, i.e. sRGB.
bool coloursAreLinear(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return ext == ".gltf" || ext == ".glb";
}

// The base-colour texture file of the first material that names one on disk, or "".
std::string textureFile(const aiScene& scene, const std::string& path) {
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
            const fs::path full = fs::path(path).parent_path() / file;
            std::error_code ec;
            if (fs::is_regular_file(full, ec)) return full.string();
        }
    }
    return {};
}

}  // namespace

Mesh readMesh(const std::string& path, const MeshReadOptions& options) {
    checkFile(path, options);

    Assimp::Importer importer;
    // Points and lines are not surfaces: SortByPType drops them.
    importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    const unsigned flags = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_SortByPType |
                           aiProcess_PreTransformVertices | aiProcess_FlipUVs | aiProcess_ValidateDataStructure;
    const aiScene* scene = nullptr;
    AssimpLog log;
    {
        const std::lock_guard<std::mutex> lock(assimpLogMutex);
        const bool created = Assimp::DefaultLogger::isNullLogger();
        if (created) Assimp::DefaultLogger::create("", Assimp::Logger::NORMAL, 0);
        Assimp::DefaultLogger::get()->attachStream(&log, Assimp::Logger::Warn | Assimp::Logger::Err);
        scene = importer.ReadFile(path, flags);
        Assimp::DefaultLogger::get()->detachStream(&log, Assimp::Logger::Warn | Assimp::Logger::Err);
        if (created) Assimp::DefaultLogger::kill();
    }
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

    const std::string texturePath = options.readTexture ? textureFile(*scene, path) : std::string();
    Mesh out;
    out.positions.reserve(static_cast<std::size_t>(vertices));
    out.indices.reserve(static_cast<std::size_t>(triangles) * 3);
    std::int64_t degenerate = 0;
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
                ++degenerate;
                continue;
            }
            out.indices.insert(out.indices.end(), {a, b, c});
        }
    }
    for (const glm::vec3& p : out.positions)
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            fail(ErrorCode::Corrupt, path, "a vertex position is not finite");
    if (out.indices.empty()) fail(ErrorCode::Corrupt, path, "every triangle is degenerate (no area)");
    if (degenerate > 0 && options.warn)
        options.warn("mesh '" + path + "': dropped " + std::to_string(degenerate) + " of " + std::to_string(triangles) +
                     " triangles, degenerate (a repeated corner or no area)");

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
