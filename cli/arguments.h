// Parsing of the values the subcommands share: sizes "WxH", views "u0,v0,u1,v1", enumerations.
// Each parser throws conus::Error(InvalidArgument) with a reason that names the bad text.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <glm/glm.hpp>

#include "conus/cli/option_checks.h"
#include "conus/codec/image/decode.h"
#include "conus/core/camera.h"
#include "conus/format/container.h"
#include "conus/sceneio/dem_file.h"
#include "conus/sceneio/mesh_file.h"

namespace conus::cli {

struct Size {
    int width = 0, height = 0;
};

Size parseSize(const std::string& text);        // "1024x768"; each side in [1, 65536]
// parseSize as a CLI11 check, a usage error before any work; `rule` (the text, the size parsed from
// it) adds a command's own bounds: what it returns, when not empty, is the error.
CLI::Validator sizeCheck(std::function<std::string(const std::string&, Size)> rule = {});
codec::View parseView(const std::string& text);  // "u0,v0,u1,v1" with u0 < u1, v0 < v1, all finite

// "x,y,z,lx,ly,lz,fovDeg": eye, look-at point, vertical field of view in degrees (what
// `render heightfield` and `render mesh` take as --camera).
struct CameraText {
    glm::dvec3 eye{0.0}, target{0.0};
    double fovYDegrees = 50;
};
CameraText parseCamera(const std::string& text);
// That camera with `up`, clipped to `box` (core's lookingAtBox; `what` names the box); its errors
// name --camera.
Camera givenCamera(const CameraText& given, glm::dvec3 up, const AxisBox& box, double aspect, const std::string& what);
glm::dvec3 parseVector3(const std::string& text, const std::string& what);  // "x,y,z", all finite

// The elevation model a DEM argument names: procedural[:SIZE[:SEED]] (codec's terrain, SIZE x SIZE
// samples) or a file (sceneio::readDem), its heights times `heightScale`.
sceneio::Dem demFrom(const std::string& source, double heightScale);
// The DEM's colour (codec::demColour) of the image file `texture`, or of codec's height/slope ramp
// when it is empty; `encoding` receives what the colour came from.
Image demColour(const sceneio::Dem& dem, const std::string& texture, glm::dvec2 extent, SourceEncoding* encoding = nullptr);

// The mesh a scene argument names (sceneio::readMesh: files it names may also lie in `allowDirs`;
// its warnings said), read as a progress stage.
Mesh readSceneMesh(const std::string& path, const std::vector<std::string>& allowDirs);

// --compression (format::Compression's names; default zip) for the commands that write a CoNUS file.
CLI::Option* addCompressionOption(CLI::App& command, std::string& compression);

}  // namespace conus::cli
