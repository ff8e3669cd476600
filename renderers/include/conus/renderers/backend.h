// Where work runs, decided in one place.
//
// The ordered list: EGL (hardware devices first, then Mesa's software device, then surfaceless),
// then OSMesa, then the CPU reference in conus::codec. `auto` takes the first that works, with two
// rules: on a software rasterizer (llvmpipe, softpipe, swrast), work that has a CPU path runs there
// instead, since the CPU reference measured several times faster (bench/README.md); and work whose
// CPU path measured faster than a hardware GPU too (image encode and decode: the upload of a
// host-resident image costs more than the CPU's whole pass, bench/notes/2026-11-27-gpu-h200.md)
// runs on the CPU unless GL is asked for by name; work whose speed differs by machine (image
// encode) runs where a one-time measurement on the machine's GL says it is faster. Work without a
// CPU path (terrain rendering) needs GL on any rasterizer, and asking for the CPU is refused.
//
// A GPU path and its CPU reference are registered once, where the work is declared, through
// Device::run (gpu_image.h's encodeImage / decodeImage are the pattern to follow).
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <utility>

#include "conus/renderers/context.h"

namespace conus::renderers {

// Available: `auto` takes a hardware GPU when there is one. Faster: `auto` takes the CPU (GL only
// by name). Measured: `auto` takes GL where the work's SpeedProbe says GL is faster (on a machine
// with no GPU device node, the CPU without measuring). None: GL only.
enum class CpuPath { Available, Faster, Measured, None };

// The answer to "is GL faster than the CPU at this work here?", asked of a context `auto` made
// (the probe caches its measurement itself: gpu_image.h's encodeSpeedProbe). measureAnywhere asks
// even where the machine has no GPU device node (which otherwise settles it for the CPU without a
// context): tests choosing on llvmpipe with a given answer.
struct SpeedProbe {
    std::function<bool(Context&)> glFaster;
    bool measureAnywhere = false;
};

class Device {
public:
    // Chooses by the rule above. `work` names the work in messages ("terrain rendering"). Throws
    // conus::Error: InvalidArgument for Backend::Cpu when there is no CPU path; Unsupported when
    // the GL backend asked for by name does not work, or no GL works for work that needs it.
    // CpuPath::Measured needs `probe` (without one `auto` takes the CPU).
    static Device choose(Backend requested, CpuPath cpuPath, const std::string& work, const SpeedProbe& probe = {});
    // The CPU reference (no GL), and a device on a context someone else made.
    static Device cpu();
    static Device on(std::shared_ptr<Context> context);

    bool onGpu() const { return m_context != nullptr; }
    Context& context() const;  // throws conus::Error(InvalidArgument) on the CPU
    Backend backend() const { return m_context ? m_context->backend() : Backend::Cpu; }
    // "cpu", or "egl: <GL_RENDERER>" / "osmesa: <GL_RENDERER>".
    std::string describe() const;

    // The one place a piece of work names its two paths: gpu(Context&) on a GL device, else cpu().
    template <class CpuFn, class GpuFn>
    auto run(CpuFn&& cpu, GpuFn&& gpu) const {
        return m_context ? std::forward<GpuFn>(gpu)(*m_context) : std::forward<CpuFn>(cpu)();
    }

private:
    std::shared_ptr<Context> m_context;  // null: the CPU
};

// Whether GL_RENDERER names a software rasterizer (llvmpipe, softpipe, swrast).
bool isSoftwareRasterizer(const std::string& renderer);
// Whether work that has a CPU path should take it rather than run on this context: the rule above.
bool prefersCpu(const Context& context);

}  // namespace conus::renderers
