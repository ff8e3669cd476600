// The one way each kind of CoNUS file is assembled from its parts, so that every writer (the
// CLI, the viewer's editor, the bindings) fills the same attributes the same way.
//
// - Image files: a CoNUS image encoded through a map, the size and encoding of its source, and the
//   analytic parameters when the map was built from some; a `Z` channel makes it a depth image
//   of camera depth over [0, 1] unless the caller says otherwise afterwards.
// - Depth images (a mesh render: R, G, B, A, Z): data kind `depthimage`, Z camera depth over the
//   camera's [near, far] in `units`, the camera recorded, float pixels (depth needs them), the
//   conventional frame of the same pixel count as the source size.
// - Map files (spec/conus-format.md, "Map files"): a sampling map on its own, as an ordinary CoNUS
//   file whose image is the map's density at its nodes (one FLOAT channel Y, one pixel per node),
//   so any EXR viewer shows where the samples go. Every reader takes the map from any CoNUS file
//   the same way.
#pragma once

#include <optional>

#include "conus/codec/map/sampling_map.h"
#include "conus/core/color.h"
#include "conus/format/container.h"

namespace conus::codec {

format::ConusFile makeImageFile(Image image, const SamplingMap& map, int sourceWidth, int sourceHeight,
                                SourceEncoding encoding, std::optional<format::AnalyticMap> analytic = std::nullopt);

format::ConusFile makeDepthImageFile(Image image, const SamplingMap& map, const Camera& camera, std::string units,
                                     std::optional<format::AnalyticMap> analytic = std::nullopt);

format::ConusFile makeMapFile(const SamplingMap& map, std::optional<format::AnalyticMap> analytic = std::nullopt);

// The width / height of the pictures a file's map was made for: a map file's `aspect` scalar, an
// image file's source's; none when the file does not say (a map file without it).
std::optional<double> madeForAspect(const format::ConusFile& file);

}  // namespace conus::codec
