#include "arguments.h"

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <vector>

#include "conus/codec/depth/heightfield.h"
#include "conus/codec/image/encode.h"
#include "conus/core/error.h"
#include "conus/core/limits.h"
#include "conus/imageio/image_file.h"
#include "image_files.h"
#include "progress.h"

namespace conus::cli {
namespace {

[[noreturn]] void invalid(const std::string& what) { throw Error(ErrorCode::InvalidArgument, what); }

std::vector<double> parseNumbers(const std::string& text, char separator) {
    std::vector<double> values;
    std::stringstream stream(text);
    std::string item;
    while (std::getline(stream, item, separator)) {
        char* end = nullptr;
        const double value = std::strtod(item.c_str(), &end);
        if (item.empty() || end != item.c_str() + item.size() || !std::isfinite(value))
            invalid("'" + text + "': '" + item + "' is not a number");
        values.push_back(value);
    }
    return values;
}

}  // namespace

Size parseSize(const std::string& text) {
    const auto values = parseNumbers(text, 'x');
    if (values.size() != 2 || text.back() == 'x') invalid("size '" + text + "' is not of the form WxH");
    for (double v : values)
        if (v != std::floor(v) || v < 1 || v > kMaxImageSide)
            invalid("size '" + text + "': each side must be a whole number in [1, 65536]");
    return {static_cast<int>(values[0]), static_cast<int>(values[1])};
}

CLI::Validator sizeCheck(std::function<std::string(const std::string&, Size)> rule) {
    return CLI::Validator(
        [rule = std::move(rule)](std::string& text) -> std::string {
            try {
                const Size size = parseSize(text);
                return rule ? rule(text, size) : std::string();
            } catch (const Error& e) {
                return e.what();
            }
        },
        "WxH");
}

codec::View parseView(const std::string& text) {
    const auto values = parseNumbers(text, ',');
    if (values.size() != 4) invalid("view '" + text + "' is not of the form u0,v0,u1,v1");
    const codec::View view{values[0], values[1], values[2], values[3]};
    codec::checkView(view, "'" + text + "'");
    return view;
}

CameraText parseCamera(const std::string& text) {
    const auto v = parseNumbers(text, ',');
    if (v.size() != 7 || text.back() == ',') invalid("camera '" + text + "' needs 7 values x,y,z,lx,ly,lz,fovDeg");
    if (!(v[6] > 0 && v[6] < 180)) invalid("camera '" + text + "': the field of view must lie in (0, 180) degrees");
    return {{v[0], v[1], v[2]}, {v[3], v[4], v[5]}, v[6]};
}

Camera givenCamera(const CameraText& given, glm::dvec3 up, const AxisBox& box, double aspect, const std::string& what) {
    try {
        return lookingAtBox(box, given.eye, given.target, up, given.fovYDegrees, aspect, what);
    } catch (const Error& e) {
        throw Error(e.code(), std::string("--camera: ") + e.what());
    }
}

glm::dvec3 parseVector3(const std::string& text, const std::string& what) {
    const auto v = parseNumbers(text, ',');
    if (v.size() != 3 || text.back() == ',') invalid(what + " '" + text + "' needs 3 values x,y,z");
    return {v[0], v[1], v[2]};
}

CLI::Option* addCompressionOption(CLI::App& command, std::string& compression) {
    return command.add_option("--compression", compression, "how the file's pixels are compressed (dwaa: lossy)")
        ->default_val(enumName(format::Compression::Zip))
        ->check(CLI::IsMember(enumNames<format::Compression>()));
}

sceneio::Dem demFrom(const std::string& source, double heightScale) {
    const std::optional<codec::TerrainOptions> terrain = codec::proceduralTerrain(source);
    if (!terrain) return sceneio::readDem(source, heightScale);
    return sceneio::demFromHeights(codec::generateTerrain(*terrain), heightScale,
                                   "procedural terrain " + std::to_string(terrain->width) + "x" +
                                       std::to_string(terrain->height) + " seed " + std::to_string(terrain->seed));
}

Image demColour(const sceneio::Dem& dem, const std::string& texture, glm::dvec2 extent, SourceEncoding* encoding) {
    if (texture.empty()) {
        if (encoding) *encoding = {Transfer::Srgb, SampleType::Uint8, kRec709Chromaticities, {}, {}};
        return codec::demColour(dem.heights, extent);
    }
    imageio::ImageFile file = readSource(texture, {});
    if (encoding) *encoding = file.info.encoding;
    return codec::demColour(dem.heights, extent, std::move(file.image), texture);
}

Mesh readSceneMesh(const std::string& path, const std::vector<std::string>& allowDirs) {
    Progress loading("read " + path);
    sceneio::MeshReadOptions read;
    read.allowedDirs = allowDirs;
    read.warn = warn;
    Mesh mesh = sceneio::readMesh(path, read);
    loading.done();
    return mesh;
}

}  // namespace conus::cli
