// The container's enumerations and the names it writes for them (spec/conus-format.md), each
// written once in its table (core/enum_names.h): the writer, the reader, the
// validator's "one of" checks and the command line's choices all come from these tables.
#pragma once

#include <utility>

#include "conus/core/enum_names.h"
#include "conus/core/map_rules.h"

namespace conus::format {

enum class PixelType { Half, Float };         // storage type of the image channels (Z is always float)
enum class Compression { None, Zip, Piz, Dwaa };
enum class DataKind { Image, HeightField, DepthImage };
enum class DepthKind { None, CameraDepth, Height };  // what a `Z` channel holds
// How a map was built (conus:mapKind): foci, or the perspective ground plane.
enum class MapKind { Foci, Ground };
// How a foci map's foci combine (conus:composition) and the shape of a focus's transition
// (conus:param:falloffShape, stored as the value's number); codec/builders/foci.h builds each.
enum class FociComposition { Density, Add };
enum class FociFalloffShape { Density, LogDensity, LogRadius };

constexpr auto enumNameTable(PixelType) {
    return makeEnumNameTable<PixelType>("pixel type", {{PixelType::Half, "half"}, {PixelType::Float, "float"}});
}
constexpr auto enumNameTable(Compression) {
    return makeEnumNameTable<Compression>("compression", {{Compression::Zip, "zip"}, {Compression::Piz, "piz"},
                                                          {Compression::Dwaa, "dwaa"}, {Compression::None, "none"}});
}
constexpr auto enumNameTable(DataKind) {
    return makeEnumNameTable<DataKind>(
        "data kind", {{DataKind::Image, "image"}, {DataKind::HeightField, "heightfield"}, {DataKind::DepthImage, "depthimage"}});
}
constexpr auto enumNameTable(DepthKind) {
    return makeEnumNameTable<DepthKind>(
        "depth kind", {{DepthKind::None, "none"}, {DepthKind::CameraDepth, "cameraDepth"}, {DepthKind::Height, "height"}});
}
constexpr auto enumNameTable(MapKind) { return makeEnumNameTable<MapKind>("map kind", {{MapKind::Foci, "foci"}, {MapKind::Ground, "ground"}}); }
constexpr auto enumNameTable(FociComposition) {
    return makeEnumNameTable<FociComposition>(
        "composition", {{FociComposition::Density, "density"}, {FociComposition::Add, "add"}});
}
constexpr auto enumNameTable(FociFalloffShape) {
    return makeEnumNameTable<FociFalloffShape>("falloff shape", {{FociFalloffShape::Density, "density"}, {FociFalloffShape::LogDensity, "log"},
                                                                 {FociFalloffShape::LogRadius, "logr"}});
}
static_assert(kEnumNameTable<FociFalloffShape>.names.size() == map_rules::kFalloffShapes);

}  // namespace conus::format
