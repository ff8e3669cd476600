// Private to format/: a neutral description of a CoNUS file's parts and attributes, filled either
// from OpenEXR headers (exr_io.cpp) or from an in-memory ConusFile (header_model.cpp), so the
// header rules V2..V7 and V12..V16 are written once and checked the same way for both, and the
// writer writes exactly what the validator checked. The known parts and attributes are tables
// (kParts, kAttributes) that the reader, the writer and the validator share.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <iterator>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "conus/format/container.h"
#include "conus/format/reflection_asset.h"

namespace conus::format::detail {

// An attribute as found: absent, present with the wrong EXR type, or present with a value.
template <class T>
struct Attr {
    using Value = T;
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

// The parts CoNUS knows (spec "High-level layout"), in the order the writer stores them. A new
// part is a value here and a row in kParts; its attributes name it in kAttributes.
enum class PartKind { Conus, SamplingMap };

struct PartSpec {
    PartKind kind;
    const char* name;  // the part's `name` attribute
    Rule rule;         // the rule that requires exactly one such part
};

inline constexpr PartSpec kParts[] = {
    {PartKind::Conus, kConusPartName, Rule::V2},
    {PartKind::SamplingMap, kMapPartName, Rule::V7},
};
inline constexpr std::size_t kPartCount = std::size(kParts);

struct PartModel {
    std::string name;
    std::string type;  // "scanlineimage", "tiledimage", "deepscanline", ...
    std::vector<ChannelModel> channels;
    Box dataWindow, displayWindow;
    std::int64_t tileWidth = 0, tileHeight = 0;  // tiled parts only
    Compression compression = Compression::Zip;
};

// Where a known part was found: the index of the first part with its name, and how many have it.
struct PartSlot {
    int index = -1;
    int count = 0;
};

struct HeaderModel {
    std::vector<PartModel> parts;
    std::array<PartSlot, kPartCount> found;  // by PartKind

    const PartSlot& slot(PartKind kind) const { return found[static_cast<std::size_t>(kind)]; }
    PartSlot& slot(PartKind kind) { return found[static_cast<std::size_t>(kind)]; }
    // The first part of that kind; only when slot(kind).index >= 0.
    const PartModel& part(PartKind kind) const { return parts[static_cast<std::size_t>(slot(kind).index)]; }

    // Attributes of the `conus` part (kAttributes says each one's name and type).
    Attr<int> version;
    Attr<std::array<int, 2>> sourceSize;
    Attr<std::string> dataKind;
    Attr<std::string> mapKind;
    Attr<std::vector<float>> foci;
    Attr<std::vector<float>> groundRows;
    Attr<std::string> composition;
    std::map<std::string, Attr<double>> params;  // conus:param:<name>, keyed by <name>
    Attr<std::array<float, 16>> worldToCamera, worldToNDC;
    Attr<std::string> projection;
    Attr<std::string> depthKind;
    Attr<std::array<float, 2>> depthRange;
    Attr<std::string> depthUnits;
    Attr<std::string> software;
    // Colour (V16).
    Attr<std::string> sourceTransfer, sourceSampleType, iccProfile;
    Attr<std::array<float, 8>> chromaticities;
    // A reflection asset's cube frame (V19), on its first face's image part.
    Attr<std::array<float, 3>> cubeCentre;
    Attr<std::array<float, 9>> cubeAxes;  // row-major: rows the cube's +x, +y, +z in world space

    // The name of the part of `kind` this model describes: kParts' name plus `suffix` (".px" for a
    // reflection asset's +x face, empty for a single image).
    std::string suffix;
    std::string partName(PartKind kind) const;
};

// ---- The attributes CoNUS reads and writes, as data ----------------------------------------------
// Each known attribute once: its name in the file, the part that carries it, the rule that checks
// it, and the HeaderModel member that holds it (whose C++ type fixes the EXR type: int, v2i,
// string, floatvector, m44f, v2f, chromaticities; double for a family of named parameters). The
// reader fills every member from this table and the writer writes every member through it, so a
// new attribute is a member, a row, a check in validate_file.cpp and its ConusFile field.

template <class T>
using AttrMember = Attr<T> HeaderModel::*;
using ParamsMember = std::map<std::string, Attr<double>> HeaderModel::*;
using AttrField = std::variant<AttrMember<int>, AttrMember<std::string>, AttrMember<std::array<int, 2>>,
                               AttrMember<std::array<float, 2>>, AttrMember<std::vector<float>>,
                               AttrMember<std::array<float, 16>>, AttrMember<std::array<float, 8>>, ParamsMember,
                               AttrMember<std::array<float, 3>>, AttrMember<std::array<float, 9>>>;

// The EXR type of each of AttrField's alternatives, in its order, as messages and the spec name it.
inline constexpr const char* kAttrTypeNames[] = {"int", "string", "v2i", "v2f", "floatvector", "m44f", "chromaticities",
                                                 "double or float", "v3f", "m33f"};
static_assert(std::size(kAttrTypeNames) == std::variant_size_v<AttrField>);

struct AttributeSpec {
    const char* name;  // for a ParamsMember, the prefix of every name in the family
    PartKind part;
    Rule rule;  // the rule that checks its presence, type and value
    AttrField field;

    constexpr const char* typeName() const { return kAttrTypeNames[field.index()]; }
};

// Attribute names (spec/conus-format.md, "Attributes").
// A channel that holds depth, always FLOAT (V3, V18): `Z`, and a reflection asset's deeper layers'
// `layer<k>.Z` (spec "Layers").
inline bool isDepthChannel(const std::string& name) {
    return name == "Z" || (name.rfind("layer", 0) == 0 && name.size() > 2 && name.compare(name.size() - 2, 2, ".Z") == 0);
}

inline constexpr const char* kAttrVersion = "conus:version";
inline constexpr const char* kAttrSourceSize = "conus:sourceSize";
inline constexpr const char* kAttrDataKind = "conus:dataKind";
inline constexpr const char* kAttrMapKind = "conus:mapKind";
inline constexpr const char* kAttrFoci = "conus:foci";
inline constexpr const char* kAttrComposition = "conus:composition";
inline constexpr const char* kAttrGroundRows = "conus:groundRows";
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
inline constexpr const char* kAttrCubeCentre = "conus:cubeCentre";
inline constexpr const char* kAttrCubeAxes = "conus:cubeAxes";
inline constexpr const char* kMapChannelU = "ud";
inline constexpr const char* kMapChannelV = "vd";

inline constexpr AttributeSpec kAttributes[] = {
    // Every file: its version, its source, what it holds (V2, V5, V6).
    {kAttrVersion, PartKind::Conus, Rule::V2, &HeaderModel::version},
    {kAttrSourceSize, PartKind::Conus, Rule::V5, &HeaderModel::sourceSize},
    {kAttrDataKind, PartKind::Conus, Rule::V6, &HeaderModel::dataKind},
    // The analytic map, when the map was built from one (V12).
    {kAttrMapKind, PartKind::Conus, Rule::V12, &HeaderModel::mapKind},
    {kAttrFoci, PartKind::Conus, Rule::V12, &HeaderModel::foci},
    {kAttrComposition, PartKind::Conus, Rule::V12, &HeaderModel::composition},
    {kAttrGroundRows, PartKind::Conus, Rule::V12, &HeaderModel::groundRows},
    {kAttrParamPrefix, PartKind::Conus, Rule::V12, &HeaderModel::params},
    // The camera (V13).
    {kAttrWorldToCamera, PartKind::Conus, Rule::V13, &HeaderModel::worldToCamera},
    {kAttrWorldToNDC, PartKind::Conus, Rule::V13, &HeaderModel::worldToNDC},
    {kAttrProjection, PartKind::Conus, Rule::V13, &HeaderModel::projection},
    // Depth (V14).
    {kAttrDepthKind, PartKind::Conus, Rule::V14, &HeaderModel::depthKind},
    {kAttrDepthRange, PartKind::Conus, Rule::V14, &HeaderModel::depthRange},
    {kAttrDepthUnits, PartKind::Conus, Rule::V14, &HeaderModel::depthUnits},
    // Free text that no rule checks.
    {kAttrSoftware, PartKind::Conus, Rule::Unreadable, &HeaderModel::software},
    // Colour (V16).
    {kAttrSourceTransfer, PartKind::Conus, Rule::V16, &HeaderModel::sourceTransfer},
    {kAttrSourceSampleType, PartKind::Conus, Rule::V16, &HeaderModel::sourceSampleType},
    {kAttrIccProfile, PartKind::Conus, Rule::V16, &HeaderModel::iccProfile},
    {kAttrChromaticities, PartKind::Conus, Rule::V16, &HeaderModel::chromaticities},
    // A reflection asset's cube frame (V19).
    {kAttrCubeCentre, PartKind::Conus, Rule::V19, &HeaderModel::cubeCentre},
    {kAttrCubeAxes, PartKind::Conus, Rule::V19, &HeaderModel::cubeAxes},
};

// The row of the attribute `member` holds.
template <class Member>
constexpr const AttributeSpec& specOf(Member member) {
    for (const AttributeSpec& spec : kAttributes)
        if (const auto* m = std::get_if<Member>(&spec.field); m && *m == member) return spec;
    throw std::logic_error("attribute missing from kAttributes");
}

// Which rule a failure maps to is part of the report; this says how readConusFile should throw.
struct HeaderCheck {
    bool notConus = false;       // readable EXR without a `conus` part
    bool limitExceeded = false;  // a size beyond Limits
};

// The camera the attributes describe, or what is wrong with them (V13's geometric half: known
// projection, finite invertible matrices that agree with it). toCamera() throws with that text.
struct CameraCheck {
    std::optional<conus::Camera> camera;
    std::string problem;  // empty when `camera` holds one
};
CameraCheck describeCamera(const CameraAttributes& attributes);

// Runs V2..V7 (shape only for V7) and V12..V15 on the model, appending to `report`.
HeaderCheck checkHeaderRules(const HeaderModel& model, const Limits& limits, ValidationReport& report);

// An in-memory file's pixel array against its size (V4) and its map's rules (V8..V11; V7 unless
// the headers said it), each message after `prefix` (validate_file.cpp).
void checkPixelsAndMap(const ConusFile& file, const std::string& prefix, ValidationReport& report);

// The header an in-memory file is written with (header_model.cpp); `suffix` names its parts.
HeaderModel modelOf(const ConusFile& file, const std::string& suffix = "");

// A reflection asset's headers: one model per face, each naming its parts with faceSuffix(face).
using AssetModel = std::array<HeaderModel, kCubeFaceCount>;
inline std::string faceSuffix(int face) { return std::string(".") + kCubeFaceNames[face]; }
// Each present face's header rules (V2..V17, its issues prefixed "face px: "), then V18 and V19
// (validate_asset.cpp).
HeaderCheck checkAssetRules(const AssetModel& faces, const Limits& limits, ValidationReport& report);
// The headers an in-memory asset is written with: each face's modelOf, the frame on the first.
AssetModel modelOf(const ReflectionAssetFile& asset);

// Base64 (RFC 4648) for the ICC profile, which OpenEXR 3.1 has no byte-array attribute for.
std::string base64Encode(const std::string& bytes);
// Empty optional for text that is not base64.
std::optional<std::string> base64Decode(const std::string& text);

}  // namespace conus::format::detail
