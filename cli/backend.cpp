#include "backend.h"

#include <CLI/CLI.hpp>

namespace conus::cli {

void addBackendOption(CLI::App& command, std::string& backend, gl::CpuPath cpuPath) {
    if (cpuPath == gl::CpuPath::None) {
        command.add_option("--backend", backend, "auto (default: the first GL that works) | egl | osmesa (GL is needed)")
            ->default_val("auto")
            ->check(CLI::IsMember({"auto", "egl", "osmesa"}, CLI::ignore_case));
        return;
    }
    command.add_option("--backend", backend,
                       "auto (default: a GPU when there is one, else the CPU) | egl | osmesa | cpu")
        ->default_val("auto")
        ->check(CLI::IsMember({"auto", "egl", "osmesa", "cpu"}, CLI::ignore_case));
}

gl::Device deviceFor(const std::string& backend, gl::CpuPath cpuPath, const std::string& work) {
    return gl::Device::choose(gl::parseBackend(backend), cpuPath, work);
}

}  // namespace conus::cli
