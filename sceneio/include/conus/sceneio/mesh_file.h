// Scene files read into CoNUS's value types: triangle meshes through Assimp (OBJ, PLY, STL, glTF,
// FBX, ... whatever the installed Assimp reads), kept inside sceneio/src/assimp_mesh.cpp; no
// Assimp type leaves it. Volume files will join them here.
//
// What a mesh file gives (core/mesh.h): every mesh of the file, in world space (the node
// transforms applied), merged into one conus::Mesh; positions; unit normals per vertex (the
// file's, or computed, area-weighted, when it has none); per-vertex colours (linear, alpha
// dropped) when the file has them; UVs ((0,0) top-left) and the base-colour texture of the first
// textured material, read through imageio (linear light), when the file names one that exists.
// Faces with fewer than three corners (points, lines) are dropped; polygons are triangulated.
//
// Degenerate triangles (a repeated corner or no area) are dropped, and MeshReadOptions::warn says
// how many.
//
// Errors are one-line conus::Error naming the path: Io (missing, unreadable, or a format Assimp
// does not know), Corrupt (Assimp refused the contents, a face indexes past its mesh's vertices,
// a vertex is not finite, or nothing but degenerate triangles),
// LimitExceeded (past the file-size or triangle cap, checked before the mesh is copied).
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "conus/core/mesh.h"

namespace conus::sceneio {

// The default caps of readMesh; a caller may lower them.
inline constexpr std::int64_t kMaxMeshFileBytes = std::int64_t{1} << 30;  // bytes of one mesh file
inline constexpr std::int64_t kMaxMeshTriangles = std::int64_t{1} << 24;  // triangles after triangulation
inline constexpr std::int64_t kMaxMeshVertices = std::int64_t{1} << 25;   // vertices after merging meshes

struct MeshReadOptions {
    std::int64_t maxFileBytes = kMaxMeshFileBytes;
    std::int64_t maxTriangles = kMaxMeshTriangles;
    std::int64_t maxVertices = kMaxMeshVertices;
    bool readTexture = true;  // false: UVs are kept but no texture file is opened
    // Told, in one line, what was dropped and how much (degenerate triangles); null: not told.
    std::function<void(const std::string&)> warn;
};

// Reads the mesh file at `path`. The result always has normals, and holds at least one
// non-degenerate triangle.
Mesh readMesh(const std::string& path, const MeshReadOptions& options = {});

}  // namespace conus::sceneio
