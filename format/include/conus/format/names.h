// The names the container writes for its enumerations, each written once: the writer, the reader,
// the validator's "one of" checks and the command line's choices all come from these tables.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace conus::format {

enum class PixelType { Half, Float };         // storage type of the image channels (Z is always float)
enum class Compression { None, Zip, Piz, Dwaa };
enum class DataKind { Image, HeightField, DepthImage };
enum class DepthKind { None, CameraDepth, Height };  // what a `Z` channel holds

template <class E>
struct EnumNames;  // `table`: each value with its name, in the order choices are listed

template <>
struct EnumNames<PixelType> {
    static constexpr std::pair<PixelType, const char*> table[] = {{PixelType::Half, "half"}, {PixelType::Float, "float"}};
};
template <>
struct EnumNames<Compression> {
    static constexpr std::pair<Compression, const char*> table[] = {
        {Compression::Zip, "zip"}, {Compression::Piz, "piz"}, {Compression::Dwaa, "dwaa"}, {Compression::None, "none"}};
};
template <>
struct EnumNames<DataKind> {
    static constexpr std::pair<DataKind, const char*> table[] = {
        {DataKind::Image, "image"}, {DataKind::HeightField, "heightfield"}, {DataKind::DepthImage, "depthimage"}};
};
template <>
struct EnumNames<DepthKind> {
    static constexpr std::pair<DepthKind, const char*> table[] = {
        {DepthKind::None, "none"}, {DepthKind::CameraDepth, "cameraDepth"}, {DepthKind::Height, "height"}};
};

template <class E>
const char* nameOf(E value) {
    for (const auto& [v, name] : EnumNames<E>::table)
        if (v == value) return name;
    return "unknown";
}

template <class E>
std::optional<E> parseName(std::string_view text) {
    for (const auto& [v, name] : EnumNames<E>::table)
        if (text == name) return v;
    return std::nullopt;
}

// Every name, in table order ("zip", "piz", ...): for "one of" checks and command-line choices.
template <class E>
std::vector<std::string> namesOf() {
    std::vector<std::string> names;
    for (const auto& entry : EnumNames<E>::table) names.emplace_back(entry.second);
    return names;
}

// "zip, piz, dwaa, none": for messages.
template <class E>
std::string nameList() {
    std::string list;
    for (const auto& entry : EnumNames<E>::table) list.append(list.empty() ? "" : ", ").append(entry.second);
    return list;
}

}  // namespace conus::format
