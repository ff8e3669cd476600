// Private to format/: a neutral description of a CoNUS file's parts and attributes, filled either
// from OpenEXR headers (exr_io.cpp) or from an in-memory ConusFile (validate_file.cpp), so the
// header rules V2..V7 and V12..V15 are written once and checked the same way for both.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "conus/format/container.h"

namespace conus::format::detail {

// An attribute as found: absent, present with the wrong EXR type, or present with a value.
template <class T>
struct Attr {
    bool present = false;
    bool typeOk = false;
    std::string typeName;  // the EXR type it had, for messages
    T value{};
    bool ok() const { return present && typeOk; }
};

enum class ChannelType { Uint, Half, Float };

struct ChannelModel {
    std::string name;
    ChannelType type = ChannelType::Float;
    int xSampling = 1, ySampling = 1;
};

struct Box {
    std::int64_t minX = 0, minY = 0, maxX = -1, maxY = -1;
    std::int64_t width() const { return maxX - minX + 1; }
    std::int64_t height() const { return maxY - minY + 1; }
    bool operator==(const Box&) const = default;
};

struct PartModel {
    std::string name;
    std::string type;  // "scanlineimage", "tiledimage", "deepscanline", ...
    std::vector<ChannelModel> channels;
    Box dataWindow, displayWindow;
    std::int64_t tileWidth = 0, tileHeight = 0;  // tiled parts only
};

struct HeaderModel {
    std::vector<PartModel> parts;
    int conusPart = -1, mapPart = -1;  // index of the first part with that name
    int conusPartCount = 0, mapPartCount = 0;

    // Attributes of the `conus` part.
    Attr<int> version;
    Attr<std::array<int, 2>> sourceSize;
    Attr<std::string> dataKind;
    Attr<std::string> mapKind;
    Attr<std::vector<float>> foci;
    Attr<std::string> composition;
    std::map<std::string, Attr<double>> params;  // conus:param:<name>, keyed by <name>
    Attr<std::array<float, 16>> worldToCamera, worldToNDC;
    Attr<std::string> projection;
    Attr<std::string> depthKind;
    Attr<std::array<float, 2>> depthRange;
    Attr<std::string> depthUnits;
    // Colour (V16).
    Attr<std::string> sourceTransfer, sourceSampleType, iccProfile;
    Attr<std::array<float, 8>> chromaticities;
};

// Which rule a failure maps to is part of the report; this says how readConusFile should throw.
struct HeaderCheck {
    bool notConus = false;       // readable EXR without a `conus` part
    bool limitExceeded = false;  // a size beyond ReadLimits
};

// The camera the attributes describe, or what is wrong with them (V13's geometric half: known
// projection, finite invertible matrices that agree with it). toCamera() throws with that text.
struct CameraCheck {
    std::optional<conus::Camera> camera;
    std::string problem;  // empty when `camera` holds one
};
CameraCheck describeCamera(const CameraAttributes& attributes);

// Runs V2..V7 (shape only for V7) and V12..V15 on the model, appending to `report`.
HeaderCheck checkHeaderRules(const HeaderModel& model, const ReadLimits& limits, ValidationReport& report);

// The header an in-memory file would be written with.
HeaderModel modelOf(const ConusFile& file);

// Base64 (RFC 4648) for the ICC profile, which OpenEXR 3.1 has no byte-array attribute for.
std::string base64Encode(const std::string& bytes);
// Empty optional for text that is not base64.
std::optional<std::string> base64Decode(const std::string& text);

// Attribute names (spec/conus-format.md).
inline constexpr const char* kAttrVersion = "conus:version";
inline constexpr const char* kAttrSourceSize = "conus:sourceSize";
inline constexpr const char* kAttrDataKind = "conus:dataKind";
inline constexpr const char* kAttrMapKind = "conus:mapKind";
inline constexpr const char* kAttrFoci = "conus:foci";
inline constexpr const char* kAttrComposition = "conus:composition";
inline constexpr const char* kAttrParamPrefix = "conus:param:";
inline constexpr const char* kAttrProjection = "conus:projection";
inline constexpr const char* kAttrDepthKind = "conus:depthKind";
inline constexpr const char* kAttrDepthRange = "conus:depthRange";
inline constexpr const char* kAttrDepthUnits = "conus:depthUnits";
inline constexpr const char* kAttrWorldToCamera = "worldToCamera";
inline constexpr const char* kAttrWorldToNDC = "worldToNDC";
inline constexpr const char* kAttrSoftware = "software";
inline constexpr const char* kAttrSourceTransfer = "conus:sourceTransfer";
inline constexpr const char* kAttrSourceSampleType = "conus:sourceSampleType";
inline constexpr const char* kAttrIccProfile = "conus:iccProfile";  // base64
inline constexpr const char* kAttrChromaticities = "chromaticities";
inline constexpr const char* kMapChannelU = "ud";
inline constexpr const char* kMapChannelV = "vd";

}  // namespace conus::format::detail
