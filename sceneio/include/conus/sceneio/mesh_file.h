// Scene files read into CoNUS's value types: triangle meshes through Assimp (OBJ, PLY, STL, glTF,
// FBX, ... whatever the installed Assimp reads), kept inside sceneio/src/assimp_mesh.cpp; no
// Assimp type leaves it. Volume files will join them here.
//
// What a mesh file gives (core/mesh.h): every mesh of the file, in world space (the node
// transforms applied), merged into one conus::Mesh; positions; unit normals per vertex (the
// file's, or computed, area-weighted, when it has none); per-vertex colours (linear, alpha
// dropped) when the file has them; UVs ((0,0) top-left) and the base-colour texture of the first
// textured material, read through imageio (linear light), when the file names one that exists.
// Faces with fewer than three corners (points, lines) are dropped; polygons are triangulated;
// degenerate triangles and exact duplicates (the same three corner positions, in any order or
// orientation) are dropped, so that coincident copies cannot make every ray test every copy.
// Files the mesh file names (buffers, material libraries, textures) follow named_files.h.
//
// Degenerate triangles (a repeated corner or no area) are dropped, and MeshReadOptions::warn says
// how many; exact duplicates are dropped and MeshReadReport counts them.
//
// Errors are one-line conus::Error naming the path: Io (missing, unreadable, a format Assimp
// does not know, or a named file the policy refuses), Corrupt (Assimp refused the contents, a face
// indexes past its mesh's vertices, a vertex is not finite, or nothing but degenerate triangles),
// LimitExceeded (past the file-size or triangle cap, checked before the mesh is copied).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "conus/core/limits.h"
#include "conus/core/mesh.h"

namespace conus::sceneio {

// The default caps of readMesh (core/limits.h); a caller may lower them.
using conus::kMaxMeshFileBytes;
using conus::kMaxMeshTriangles;
using conus::kMaxMeshVertices;

struct MeshReadOptions {
    std::int64_t maxFileBytes = kMaxMeshFileBytes;
    std::int64_t maxTriangles = kMaxMeshTriangles;
    std::int64_t maxVertices = kMaxMeshVertices;
    bool readTexture = true;  // false: UVs are kept but no texture file is opened
    // Told, in one line, what was dropped and how much (degenerate triangles); null: not told.
    std::function<void(const std::string&)> warn;
    std::vector<std::string> allowedDirs;  // folders besides the file's own it may name files in (named_files.h)
};

// What readMesh left out, for the caller to say.
struct MeshReadReport {
    std::int64_t duplicateTriangles = 0;   // exact copies of an earlier triangle (same three corner positions)
    std::int64_t degenerateTriangles = 0;  // a repeated corner or no area
};

// Reads the mesh file at `path`. The result always has normals, and holds at least one
// non-degenerate triangle.
Mesh readMesh(const std::string& path, const MeshReadOptions& options = {}, MeshReadReport* report = nullptr);

}  // namespace conus::sceneio
