// The checks every volume reader shares, the raw specification's syntax and the dispatch by form.
#include "conus/sceneio/volume_file.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "conus/core/atomic_file.h"
#include "conus/core/error.h"
#include "extension_pvt.h"

namespace conus::sceneio {
namespace {

std::vector<std::string> split(const std::string& text, char separator) {
    std::vector<std::string> parts;
    std::size_t start = 0;
    for (std::size_t at; (at = text.find(separator, start)) != std::string::npos; start = at + 1)
        parts.push_back(text.substr(start, at - start));
    parts.push_back(text.substr(start));
    return parts;
}

// A whole positive number, or nullopt-like -1.
long long wholeNumber(const std::string& text) {
    if (text.empty() || text.size() > 12 ||
        !std::all_of(text.begin(), text.end(), [](unsigned char c) { return std::isdigit(c); }))
        return -1;
    return std::stoll(text);
}

double positiveNumber(const std::string& text, const std::string& spec) {
    char* end = nullptr;
    const double value = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0' || !std::isfinite(value) || value <= 0.0)
        throw Error(ErrorCode::InvalidArgument, "raw volume '" + spec + "': spacing '" + text +
                                                    "' is not a positive number");
    return value;
}

}  // namespace

void checkDimensions(const std::string& what, std::int64_t width, std::int64_t height, std::int64_t depth,
                     std::int64_t maxVoxels) {
    const auto sizeText = [&] {
        return std::to_string(width) + "x" + std::to_string(height) + "x" + std::to_string(depth);
    };
    for (const std::int64_t side : {width, height, depth}) {
        if (side < 2) throw Error(ErrorCode::InvalidArgument, what + ": size " + sizeText() + " has a side below 2");
        if (side > kMaxVolumeSide)
            throw Error(ErrorCode::LimitExceeded, what + ": size " + sizeText() + " has a side past the limit of " +
                                                      std::to_string(kMaxVolumeSide));
    }
    // Each side is at most 2^14, so the product fits in 64 bits.
    const std::int64_t voxels = width * height * depth;
    if (voxels > maxVoxels)
        throw Error(ErrorCode::LimitExceeded, what + ": " + std::to_string(voxels) + " samples, more than the limit of " +
                                                  std::to_string(maxVoxels));
}

void checkFileVolume(const Volume& volume, const std::string& what) {
    try {
        checkVolume(volume, what);
    } catch (const Error& e) {
        throw Error(e.code() == ErrorCode::InvalidArgument ? ErrorCode::Corrupt : e.code(), e.what());
    }
    const glm::dvec3 extent = volume.extent();
    if (!(std::isfinite(extent.x) && std::isfinite(extent.y) && std::isfinite(extent.z)))
        throw Error(ErrorCode::Corrupt, what + ": spacing " + numberText(volume.spacing.x) + "," +
                                            numberText(volume.spacing.y) + "," + numberText(volume.spacing.z) +
                                            " makes the volume's extent infinite");
}

std::string rawVolumeForm() {
    std::string types;
    for (const std::string& name : enumNames<RawType>()) types.append(types.empty() ? "" : "|").append(name);
    return "raw:WxHxD:" + types + "[:spacing]:path";
}

RawSpec parseRawSpec(const std::string& spec) {
    const auto bad = [&](const std::string& why) {
        return Error(ErrorCode::InvalidArgument, "raw volume '" + spec + "': " + why + " (expected " + rawVolumeForm() + ")");
    };
    if (spec.rfind("raw:", 0) != 0) throw bad("does not start with 'raw:'");
    // The path is everything after the third (or fourth, with a spacing) colon: it may hold colons.
    std::vector<std::string> fields = split(spec.substr(4), ':');
    if (fields.size() < 3) throw bad("too few fields");
    RawSpec out;
    const std::vector<std::string> dims = split(fields[0], 'x');
    if (dims.size() != 3) throw bad("size '" + fields[0] + "' is not WxHxD");
    long long sides[3];
    for (int a = 0; a < 3; ++a) {
        sides[a] = wholeNumber(dims[a]);
        if (sides[a] < 0) throw bad("size '" + fields[0] + "' is not three whole numbers");
    }
    checkDimensions("raw volume '" + spec + "'", sides[0], sides[1], sides[2], std::int64_t{1} << 62);
    out.layout.width = int(sides[0]);
    out.layout.height = int(sides[1]);
    out.layout.depth = int(sides[2]);
    std::string type = fields[1];
    if (type.size() > 3 && type.substr(type.size() - 3) == "-be") {
        out.layout.bigEndian = true;
        type.resize(type.size() - 3);
    }
    if (const std::optional<RawType> parsed = tryParseEnum<RawType>(type)) out.layout.type = *parsed;
    else throw bad("type '" + fields[1] + "' is not one of " + enumChoices<RawType>());
    std::size_t pathField = 2;
    // A spacing field is numbers and commas; a path rarely is, and "./" disambiguates one that is.
    if (fields.size() >= 4 && !fields[2].empty() &&
        fields[2].find_first_not_of("0123456789.,eE+-") == std::string::npos) {
        const std::vector<std::string> s = split(fields[2], ',');
        if (s.size() == 1) out.layout.spacing = glm::dvec3(positiveNumber(s[0], spec));
        else if (s.size() == 3)
            out.layout.spacing = {positiveNumber(s[0], spec), positiveNumber(s[1], spec), positiveNumber(s[2], spec)};
        else throw bad("spacing '" + fields[2] + "' is not one or three numbers");
        pathField = 3;
    }
    for (std::size_t i = pathField; i < fields.size(); ++i) out.path += (i > pathField ? ":" : "") + fields[i];
    if (out.path.empty()) throw bad("no path");
    return out;
}

Volume readVolume(const std::string& spec, const VolumeReadOptions& options) {
    if (spec.rfind("raw:", 0) == 0) {
        const RawSpec raw = parseRawSpec(spec);
        protectInput(raw.path);  // named inside the spec: an input all the same
        return readRawVolume(raw.path, raw.layout, options);
    }
    const std::string ext = lowerExtension(spec);
    if (ext == ".den") return readDenVolume(spec, options);
    if (ext == ".nrrd" || ext == ".nhdr") return readNrrdVolume(spec, options);
    if (ext == ".vdb") return readVdbVolume(spec, options);
    throw Error(ErrorCode::Unsupported, "volume '" + spec +
                                            "': unknown form; read are .vdb, .nrrd, .nhdr, .den and " + rawVolumeForm());
}

}  // namespace conus::sceneio
