// What pixel values mean, shared by image files (imageio/), the container (format/) and the tools.
//
// CoNUS works in linear light: every CoNUS image and every EXR it writes holds scene-linear values
// (OpenEXR's convention) with associated (premultiplied) alpha. Display-referred files (8- and
// 16-bit PNG, JPEG, TIFF; sRGB or untagged) are converted to linear on read and back to sRGB on
// write. Data images (importance maps, DEMs, height fields, normal maps) are `raw`: never converted.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "conus/core/enum_names.h"

namespace conus {

// The encoding of a file's values.
enum class Transfer {
    Linear,  // scene-linear light (EXR, float TIFF, HDR)
    Srgb,    // the sRGB transfer curve (8/16-bit display formats, unless tagged otherwise)
    Raw,     // data, not light: values kept exactly as they are
};

// The sample type a file stored, which a round trip restores.
enum class SampleType { Uint8, Uint16, Uint32, Half, Float };

constexpr auto enumNameTable(Transfer) {
    return makeEnumNameTable<Transfer>(
        "colour space", {{Transfer::Linear, "linear"}, {Transfer::Srgb, "srgb"}, {Transfer::Raw, "raw"}});
}
constexpr auto enumNameTable(SampleType) {
    return makeEnumNameTable<SampleType>("sample type", {{SampleType::Uint8, "uint8"}, {SampleType::Uint16, "uint16"}, {SampleType::Uint32, "uint32"},
                                                         {SampleType::Half, "half"}, {SampleType::Float, "float"}});
}

// A metadata item carried from a source file into a CoNUS file and back out on decode (EXIF,
// camera make and model, ...), under the name OpenImageIO gives it ("Make", "Exif:FNumber").
struct MetadataItem {
    std::string name;
    std::variant<std::string, int, float, double> value;
    bool operator==(const MetadataItem&) const = default;
};

// What a CoNUS file remembers of its source picture so that decode can give it back as it was.
struct SourceEncoding {
    Transfer transfer = Transfer::Linear;  // of the source file's values
    std::optional<SampleType> sampleType;  // absent when unknown
    // CIE xy of the red, green and blue primaries and the white point (OpenEXR's chromaticities);
    // absent for raw data, and when an ICC profile describes the colours instead.
    std::optional<std::array<float, 8>> chromaticities;
    std::string iccProfile;  // the source's ICC profile, raw bytes; empty when it had none
    std::vector<MetadataItem> metadata;
    bool operator==(const SourceEncoding&) const = default;
};

// sRGB's primaries and white point (ITU-R BT.709, D65), the chromaticities of sRGB sources.
inline constexpr std::array<float, 8> kRec709Chromaticities{0.64f, 0.33f, 0.30f, 0.60f, 0.15f, 0.06f, 0.3127f, 0.3290f};

// Bits per sample of a type: 8, 16, 32, 16, 32.
int bitsOf(SampleType sampleType);

// A picture's sample type as `--bits` names it: an integer type by its bits ("8", "16"), a floating
// type by its name in SampleType's table ("half", "float"); the types a picture file is written
// in, in that order (pictureBitsNames: "8, 16, half, float" for CLI11's IsMember and help).
inline constexpr SampleType kPictureSampleTypes[] = {SampleType::Uint8, SampleType::Uint16, SampleType::Half, SampleType::Float};
std::string pictureBitsName(SampleType sampleType);
std::optional<SampleType> parsePictureBits(std::string_view text);
std::vector<std::string> pictureBitsNames();

// Whether a metadata item of this name travels from a source file into a CoNUS file and back out:
// the EXIF, GPS and IPTC blocks (names "Exif:...", "GPS:...", "IPTC:...") and Make, Model,
// DateTime, Artist, Copyright, ImageDescription and Orientation.
bool isCarriedMetadata(std::string_view name);

// Empty when `bytes` are an ICC profile as far as its header tells (ICC.1, 7.2: at least the
// 128-byte header and a tag count, the header's size field, big-endian, equal to the byte count,
// "acsp" at bytes 36..39); else why not. Readers drop a profile that is not one (a writer would
// embed garbage), and the format refuses one (spec V16).
std::string iccProfileProblem(const std::string& bytes);

}  // namespace conus
