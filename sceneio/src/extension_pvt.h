// Private: a file name's extension as the readers compare it.
#pragma once

#include <cctype>
#include <filesystem>
#include <string>

namespace conus::sceneio {

// The extension of `path` with its dot, in lower case (".gltf" for "Model.GLTF"; "" for none).
inline std::string lowerExtension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

}  // namespace conus::sceneio
