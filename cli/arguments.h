// Parsing of the values the subcommands share: sizes "WxH", views "u0,v0,u1,v1", enumerations.
// Each parser throws conus::Error(InvalidArgument) with a reason that names the bad text.
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <glm/glm.hpp>

#include "conus/codec/image/decode.h"
#include "conus/format/container.h"

namespace conus::cli {

struct Size {
    int width = 0, height = 0;
};

Size parseSize(const std::string& text);        // "1024x768"; each side in [1, 65536]
codec::View parseView(const std::string& text);  // "u0,v0,u1,v1" with u0 < u1, v0 < v1, all finite

// "x,y,z,lx,ly,lz,fovDeg": eye, look-at point, vertical field of view in degrees (what
// `heightfield render` and `mesh render` take as --camera).
struct CameraText {
    glm::dvec3 eye{0.0}, target{0.0};
    double fovYDegrees = 50;
};
CameraText parseCamera(const std::string& text);
glm::dvec3 parseVector3(const std::string& text, const std::string& what);  // "x,y,z", all finite

// A CLI11 check for a number option: finite, above `low` (or equal to it when `lowIncluded`) and
// below `high`. CLI::Range lets NaN through (every comparison with NaN is false); this does not,
// so a bad value is a usage error (exit 2) instead of a silent fallback.
CLI::Validator finiteRange(double low, double high, bool lowIncluded = false);

// --compression (format::Compression's names; default zip) for the commands that write a CoNUS file.
CLI::Option* addCompressionOption(CLI::App& command, std::string& compression);

// --allow-dir DIR (repeatable): a folder, besides a scene file's own, that the files it names
// (glTF buffers, material libraries, NRRD data files) may lie in (sceneio/named_files.h).
void addAllowDirOption(CLI::App& command, std::vector<std::string>& dirs);

}  // namespace conus::cli
