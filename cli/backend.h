// `--backend` (renderers::Backend's names) on every command that renders. The choice itself is made in one
// place, conus::renderers::Device::choose (renderers/backend.h); this file only parses the option.
#pragma once

#include <string>

#include "conus/renderers/backend.h"

namespace CLI {
class App;
}

namespace conus::cli {

// Work without a CPU path offers auto, egl and osmesa only.
void addBackendOption(CLI::App& command, std::string& backend, renderers::CpuPath cpuPath = renderers::CpuPath::Available);

// The device for `work` from the option's value (`probe`: CpuPath::Measured's, renderers/backend.h).
renderers::Device deviceFor(const std::string& backend, renderers::CpuPath cpuPath, const std::string& work,
                            const renderers::SpeedProbe& probe = {});

}  // namespace conus::cli
