// Names of the colour enumerations, written once (spec/conus-format.md uses the same words).
#include <array>
#include <cstdint>
#include <string>
#include <utility>

#include "conus/core/color.h"
#include "conus/core/display.h"

namespace conus {
namespace {

constexpr std::array<std::pair<Transfer, const char*>, 3> kTransfers{
    {{Transfer::Linear, "linear"}, {Transfer::Srgb, "srgb"}, {Transfer::Raw, "raw"}}};
constexpr std::array<std::pair<SampleType, const char*>, 5> kSampleTypes{{{SampleType::Uint8, "uint8"},
                                                                          {SampleType::Uint16, "uint16"},
                                                                          {SampleType::Uint32, "uint32"},
                                                                          {SampleType::Half, "half"},
                                                                          {SampleType::Float, "float"}}};
constexpr std::array<std::pair<ToneMap, const char*>, 3> kToneMaps{
    {{ToneMap::None, "none"}, {ToneMap::Reinhard, "reinhard"}, {ToneMap::Aces, "aces"}}};

template <class E, std::size_t N>
const char* nameOf(const std::array<std::pair<E, const char*>, N>& table, E value) {
    for (const auto& [v, name] : table)
        if (v == value) return name;
    return "unknown";
}

template <class E, std::size_t N>
std::optional<E> valueOf(const std::array<std::pair<E, const char*>, N>& table, std::string_view text) {
    for (const auto& [v, name] : table)
        if (text == name) return v;
    return std::nullopt;
}

}  // namespace

const char* toString(Transfer t) { return nameOf(kTransfers, t); }
const char* toString(SampleType t) { return nameOf(kSampleTypes, t); }
const char* toString(ToneMap t) { return nameOf(kToneMaps, t); }
std::optional<Transfer> parseTransfer(std::string_view text) { return valueOf(kTransfers, text); }
std::optional<SampleType> parseSampleType(std::string_view text) { return valueOf(kSampleTypes, text); }
std::optional<ToneMap> parseToneMap(std::string_view text) { return valueOf(kToneMaps, text); }

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
