#include "backend.h"

#include <CLI/CLI.hpp>

namespace conus::cli {

void addBackendOption(CLI::App& command, std::string& backend, renderers::CpuPath cpuPath) {
    const std::string automatic = enumName(renderers::Backend::Auto);
    if (cpuPath == renderers::CpuPath::None) {
        command.add_option("--backend", backend, "the GL that runs the work (GL is needed); " + automatic + ": the first that works")
            ->default_val(automatic)
            ->check(CLI::IsMember(enumNames({renderers::Backend::Auto, renderers::Backend::Egl, renderers::Backend::OsMesa}), CLI::ignore_case));
        return;
    }
    const std::string rule =
        cpuPath == renderers::CpuPath::Faster     ? ": the CPU (measured faster than a GPU at this work; egl and osmesa ask for GL)"
        : cpuPath == renderers::CpuPath::Measured ? ": GL where a first encode on this machine's GPU measures faster than the CPU, else the CPU"
                                                  : ": a GPU when there is one, else the CPU";
    command.add_option("--backend", backend, "what runs the work; " + automatic + rule)
        ->default_val(automatic)
        ->check(CLI::IsMember(enumNames<renderers::Backend>(), CLI::ignore_case));
}

renderers::Device deviceFor(const std::string& backend, renderers::CpuPath cpuPath, const std::string& work,
                            const renderers::SpeedProbe& probe) {
    return renderers::Device::choose(parseEnum<renderers::Backend>(backend), cpuPath, work, probe);
}

}  // namespace conus::cli
