// Map files (spec/conus-format.md, "Map files"): a sampling map on its own, as an ordinary CoNUS
// file whose image is the map's density at its nodes (one FLOAT channel Y, one pixel per node), so
// any EXR viewer shows where the samples go. `conus map` and the viewer's map editor write them;
// every reader takes the map from any CoNUS file the same way.
#pragma once

#include <optional>

#include "conus/codec/sampling_map.h"
#include "conus/format/container.h"

namespace conus::codec {

format::ConusFile makeMapFile(const SamplingMap& map, std::optional<format::AnalyticMap> analytic = std::nullopt);

}  // namespace conus::codec
