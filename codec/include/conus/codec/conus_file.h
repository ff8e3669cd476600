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
#include <string>
#include <utility>

#include "conus/codec/map/sampling_map.h"
#include "conus/core/color.h"
#include "conus/core/map_rules.h"
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
// Whether a map made for pictures of aspect `madeFor` (width / height) shapes one of `aspect` out of
// true (more than 1% apart): its foci become ellipses, which encode warns of.
bool aspectsDiffer(double madeFor, double aspect);

// The CoNUS size of an encode that is not told one: a quarter of each side of the source (1/16 of
// the pixels), to the nearest pixel, at least 1.
std::pair<int, int> defaultConusSize(int sourceWidth, int sourceHeight);

// A map much finer than the image it shapes adds nothing the image can show and costs a build in
// proportion to its nodes (a minute at 4097 a side): a grid of `side` nodes (the longer of its
// two) is refused with InvalidArgument, `what` naming it ("--grid"), past the larger of
// `defaultSide` and map_rules::maxSideForImage (4 nodes a pixel along the image's longer side plus
// one, 129 always), the bound readers hold files to (V7).
void checkGridForImage(int side, int width, int height, const std::string& what, int defaultSide = map_rules::kDefaultSide);

}  // namespace conus::codec
