// conus.Map and conus.importance (maps.cpp): sampling maps made from foci, importance, brush
// strokes or nodes, what they do to points, and the importance rules a picture gives; added to
// the module by module.cpp, whose File and encode share Map.
#pragma once

#include <pybind11/pybind11.h>

#include <optional>

#include "conus/codec/builders/importance.h"
#include "conus/codec/map/sampling_map.h"
#include "conus/core/image.h"
#include "conus/format/container.h"

namespace conus::python {

struct Map {
    codec::SamplingMap map;
    std::optional<format::AnalyticMap> analytic;  // when built from parameters
    std::optional<double> aspect;                 // width / height of the pictures it was made for, when known
};

// The importance `rule` gives `picture` (linear light), as `--importance` computes it: on the
// picture as a display shows it. Call without the GIL.
Image pictureImportance(codec::ImportanceRule rule, const Image& picture);

void addMaps(pybind11::module_& m);

}  // namespace conus::python
