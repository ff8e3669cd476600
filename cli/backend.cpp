#include "backend.h"

#include <CLI/CLI.hpp>

namespace conus::cli {

void addBackendOption(CLI::App& command, std::string& backend, gl::CpuPath cpuPath) {
    const std::string automatic = enumName(gl::Backend::Auto);
    if (cpuPath == gl::CpuPath::None) {
        command.add_option("--backend", backend, "the GL that runs the work (GL is needed); " + automatic + ": the first that works")
            ->default_val(automatic)
            ->check(CLI::IsMember(enumNames({gl::Backend::Auto, gl::Backend::Egl, gl::Backend::OsMesa}), CLI::ignore_case));
        return;
    }
    command.add_option("--backend", backend, "what runs the work; " + automatic + ": a GPU when there is one, else the CPU")
        ->default_val(automatic)
        ->check(CLI::IsMember(enumNames<gl::Backend>(), CLI::ignore_case));
}

gl::Device deviceFor(const std::string& backend, gl::CpuPath cpuPath, const std::string& work) {
    return gl::Device::choose(parseEnum<gl::Backend>(backend), cpuPath, work);
}

}  // namespace conus::cli
