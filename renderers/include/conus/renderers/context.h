// The GL context of the GPU paths: an OpenGL 4.5 core context without a window, from the first
// backend in this ordered list that works on the machine (chosen at run time):
//   1. EGL, device platform: hardware devices first, then Mesa's software device (llvmpipe);
//      then EGL's surfaceless platform (Mesa). Works headless, on NVIDIA and on Mesa alike.
//   2. OSMesa: Mesa's off-screen library; the fallback where EGL is missing or broken.
//   3. none: Context::create throws; callers fall back to the CPU reference (Backend::Cpu).
// Every refused candidate keeps its reason, so an error says why each backend did not work.
//
// Shared rules: contexts render only to their own framebuffer objects (no window, no default
// framebuffer); a Context is used from one thread at a time and every GPU function makes it
// current on the calling thread itself. The environment variable CONUS_GL_DISABLE (a comma list of
// "egl", "egl-device", "egl-surfaceless", "osmesa") refuses backends or EGL platforms, for tests
// and for working around a broken driver.
// Errors are conus::Error: InvalidArgument for a bad name, Unsupported when no backend works.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "conus/core/enum_names.h"

namespace conus::renderers {

// The environment variable that lowers Context::textureLimit.
inline constexpr const char* kTextureLimitVariable = "CONUS_GL_MAX_TEXTURE";

enum class Backend {
    Auto,    // the first that works of Egl, OsMesa (never Cpu: a GL context is asked for)
    Egl,     // EGL device platform, then surfaceless
    OsMesa,  // Mesa's off-screen rendering library
    Cpu,     // no GL: the CPU reference in conus::codec; has no Context
};

// Backends are named in any case (parseEnum<renderers::Backend>("OSMesa")); a bad name throws
// conus::Error(InvalidArgument) listing these.
constexpr auto enumNameTable(Backend) {
    return makeEnumNameTable<Backend>(
        "backend", {{Backend::Auto, "auto"}, {Backend::Egl, "egl"}, {Backend::OsMesa, "osmesa"}, {Backend::Cpu, "cpu"}}, true);
}

struct BackendStatus {
    Backend backend = Backend::Cpu;
    bool works = false;
    std::string renderer;  // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
    std::string version;   // GL_VERSION
    // When it does not work: why (every candidate tried, with its error). When it works: which
    // variant was chosen, after the refusals of the candidates before it.
    std::string reason;
};

// Tries each backend in turn (Egl, OsMesa, then Cpu, which always works) by creating and
// destroying a context; never throws for a backend that fails.
std::vector<BackendStatus> probeBackends();

class Context {
public:
    // Backend::Auto takes the first that works. Throws conus::Error(Unsupported) with every
    // reason when none works (or the one asked for does not), InvalidArgument for Backend::Cpu.
    static std::unique_ptr<Context> create(Backend backend = Backend::Auto);
    ~Context();
    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;

    Backend backend() const;
    std::string renderer() const;     // GL_RENDERER
    std::string version() const;      // GL_VERSION
    std::string description() const;  // which platform/device, e.g. "EGL device 0 (software)"
    int maxTextureSize() const;       // GL_MAX_TEXTURE_SIZE
    // The largest texture side the GPU paths use: GL_MAX_TEXTURE_SIZE, or less where the
    // environment variable CONUS_GL_MAX_TEXTURE asks for less (texels, read on every call, clamped
    // to [64, GL_MAX_TEXTURE_SIZE]; tests use it to exercise tiling). A value that is not a
    // positive whole number throws conus::Error(InvalidArgument).
    int textureLimit() const;
    // Binds the context to the calling thread (GPU functions do this themselves).
    void makeCurrent();

    struct Impl;
    explicit Context(std::unique_ptr<Impl> impl);
    Impl& impl() { return *m_impl; }

private:
    std::unique_ptr<Impl> m_impl;
};

// A GL loader: glfwGetProcAddress and friends have this shape.
using ProcAddress = void (*)();
using GetProcFn = ProcAddress (*)(const char* name);

// A Context on the GL context current on the calling thread (a GLFW window's, say), loaded through
// `getProc`. It neither owns nor destroys that GL context and never makes it current: the caller
// keeps it current while using the Context and destroys the Context first. Throws
// conus::Error(Unsupported) when GL 4.5 core cannot be loaded.
std::unique_ptr<Context> adoptCurrentContext(GetProcFn getProc);

}  // namespace conus::renderers
