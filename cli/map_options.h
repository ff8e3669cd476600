// The options that shape a built map, shared by `map foci`, `map auto` and `encode`.
#pragma once

#include <string>

#include "conus/codec/build/auto_map.h"

namespace CLI {
class App;
}

namespace conus::cli {

// The options that shape a built map, for `map foci`, `map auto` and `encode`: --max-anisotropy
// (0: none), and --min-density / --max-density for automatic maps.
void addMaxAnisotropyOption(CLI::App& command, double& maxAnisotropy);
void addDensityBoundOptions(CLI::App& command, double& minDensity, double& maxDensity, const std::string& prefix = "");
// --falloff WIDTH[,SHAPE] for `map foci` and `encode --focus` (codec::parseFalloff; "2": the default).
void addFalloffOption(CLI::App& command, std::string& falloff);

// The builder's options from what `map auto` and `encode --importance` are given (method "flow"
// or "separable").
codec::AutoMapOptions autoMapOptions(int grid, double minDensity, double maxDensity, double maxAnisotropy, const std::string& method);

}  // namespace conus::cli
