// Colour facts that are not names: which metadata travels, bits per sample, what an ICC profile header holds.
#include <array>
#include <cstdint>
#include <string>
#include <utility>

#include "conus/core/color.h"
#include "conus/core/display.h"

namespace conus {

bool isCarriedMetadata(std::string_view name) {
    for (std::string_view prefix : {"Exif:", "GPS:", "IPTC:"})
        if (name.starts_with(prefix)) return true;
    for (std::string_view known : {"Make", "Model", "DateTime", "Artist", "Copyright", "ImageDescription", "Orientation"})
        if (name == known) return true;
    return false;
}

int bitsOf(SampleType t) {
    switch (t) {
        case SampleType::Uint8: return 8;
        case SampleType::Uint16:
        case SampleType::Half: return 16;
        case SampleType::Uint32:
        case SampleType::Float: return 32;
    }
    return 32;
}

std::string pictureBitsName(SampleType t) {
    return t == SampleType::Half || t == SampleType::Float ? enumName(t) : std::to_string(bitsOf(t));
}

std::optional<SampleType> parsePictureBits(std::string_view text) {
    for (SampleType t : kPictureSampleTypes)
        if (text == pictureBitsName(t)) return t;
    return std::nullopt;
}

std::vector<std::string> pictureBitsNames() {
    std::vector<std::string> names;
    for (SampleType t : kPictureSampleTypes) names.push_back(pictureBitsName(t));
    return names;
}

std::string iccProfileProblem(const std::string& bytes) {
    if (bytes.size() < 132) return std::to_string(bytes.size()) + " bytes, shorter than an ICC header and tag count";
    const auto byte = [&](std::size_t i) { return std::uint32_t(static_cast<unsigned char>(bytes[i])); };
    const std::uint32_t declared = byte(0) << 24 | byte(1) << 16 | byte(2) << 8 | byte(3);
    if (bytes.compare(36, 4, "acsp") != 0) return "no `acsp` signature at byte 36";
    if (declared != bytes.size())
        return "its header declares " + std::to_string(declared) + " bytes, it holds " + std::to_string(bytes.size());
    return {};
}

}  // namespace conus
