// The backend dispatch: the ordered list and the software-rasterizer rule, written once.
#include "conus/renderers/backend.h"

#include <filesystem>
#include <system_error>

#include "conus/core/error.h"

namespace conus::renderers {

namespace {

// Whether this machine has a device node a hardware GL driver could use: a DRM render node
// (Mesa's hardware drivers, EGL surfaceless), NVIDIA's device, or WSL's GPU. Without one, any GL
// context is a software rasterizer, which work with a CPU path leaves anyway: deciding that here
// spares loading Mesa and LLVM (~0.2 s of CPU and ~80 MiB for `conus encode`,
// bench/notes/2026-11-24-end-to-end.md) only to read GL_RENDERER.
bool mayHaveHardwareGpu() {
    std::error_code ec;
    for (const char* node : {"/dev/nvidiactl", "/dev/nvidia0", "/dev/dxg"})
        if (std::filesystem::exists(node, ec)) return true;
    for (std::filesystem::directory_iterator it("/dev/dri", ec), end; !ec && it != end; it.increment(ec))
        if (it->path().filename().string().rfind("renderD", 0) == 0) return true;
    return false;
}

}  // namespace

bool isSoftwareRasterizer(const std::string& renderer) {
    for (const char* name : {"llvmpipe", "softpipe", "swrast"})
        if (renderer.find(name) != std::string::npos) return true;
    return false;
}

bool prefersCpu(const Context& context) { return isSoftwareRasterizer(context.renderer()); }

Device Device::choose(Backend requested, CpuPath cpuPath, const std::string& work, const SpeedProbe& probe) {
    if (requested == Backend::Cpu) {
        if (cpuPath == CpuPath::None)
            throw Error(ErrorCode::InvalidArgument, work + " needs GL (it has no CPU path): use --backend auto, egl or osmesa");
        return cpu();
    }
    if (requested == Backend::Auto && cpuPath == CpuPath::Faster) return cpu();
    if (requested == Backend::Auto && cpuPath == CpuPath::Measured) {
        if (!probe.glFaster || (!probe.measureAnywhere && !mayHaveHardwareGpu())) return cpu();
        try {
            std::shared_ptr<Context> context = Context::create(Backend::Auto);
            if (probe.glFaster(*context)) return on(std::move(context));
        } catch (const Error&) {
            // No GL at all, or the measurement failed on it: the CPU reference serves.
        }
        return cpu();
    }
    if (requested != Backend::Auto || cpuPath == CpuPath::None)
        return on(Context::create(requested));  // asked for by name, or GL is the only way: its failure is an error
    if (!mayHaveHardwareGpu()) return cpu();
    try {
        std::shared_ptr<Context> context = Context::create(Backend::Auto);
        if (!prefersCpu(*context)) return on(std::move(context));
    } catch (const Error&) {
        // No GL at all: the CPU reference serves.
    }
    return cpu();
}

Device Device::cpu() { return Device(); }

Device Device::on(std::shared_ptr<Context> context) {
    Device device;
    device.m_context = std::move(context);
    return device;
}

Context& Device::context() const {
    if (!m_context) throw Error(ErrorCode::InvalidArgument, "this work runs on the CPU: there is no GL context");
    return *m_context;
}

std::string Device::describe() const {
    if (!m_context) return enumName(Backend::Cpu);
    return std::string(enumName(m_context->backend())) + ": " + m_context->renderer();
}

}  // namespace conus::renderers
