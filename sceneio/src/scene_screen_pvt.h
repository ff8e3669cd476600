// Checks on a scene file's own text before a library parses it: how deep its JSON or XML nests
// (the parsers Assimp uses recurse once per level), and for glTF, the node tree's depth and what
// instancing expands it to (nodes and triangles, counted over the shared nodes without expanding
// them). A refusal is conus::Error naming the file and the limit, never the file's content.
#pragma once

#include <cstdint>
#include <string>

namespace conus::sceneio {

struct SceneCaps {
    std::int64_t maxTriangles;  // triangles after instancing
    std::int64_t maxNodes;      // nodes after instancing
    int maxDepth;               // nodes along one path
    int maxMarkupDepth;         // JSON / XML nesting
};

// The file's text nesting, when it is JSON (a .gltf, or a .glb's JSON chunk) or XML (COLLADA,
// X3D, any file whose first character is '<'); then, for glTF, its node tree. `what` names the
// file in messages ("mesh 'x.gltf'").
void screenSceneText(const std::string& path, std::uintmax_t bytes, const SceneCaps& caps, const std::string& what);

}  // namespace conus::sceneio
