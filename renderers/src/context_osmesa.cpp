// OSMesa backend: Mesa's off-screen library, an OpenGL 4.5 core context rendering into a client
// buffer. We render only to framebuffer objects, but OSMesaMakeCurrent insists on a buffer, so each
// context carries a 1x1 one.
//
// libOSMesa is opened on first use (dlopen), not linked: it pulls in LLVM, which cost every conus
// process ~0.15 s of CPU at start-up whether or not it drew anything.
#include <dlfcn.h>

#include <array>

#include "context_pvt.h"
#include "conus/core/plugin.h"

// GL/osmesa.h expects GL/gl.h, which glad's header replaces (and blocks): it then lacks these two.
#ifndef GLAPI
#define GLAPI extern
#endif
#ifndef GLAPIENTRY
#define GLAPIENTRY
#endif
#include <GL/osmesa.h>

namespace conus::renderers {
namespace {

// The OSMesa entry points this backend calls, resolved once from the library.
struct OsMesaApi {
    decltype(&OSMesaCreateContextAttribs) createContextAttribs = nullptr;
    decltype(&OSMesaMakeCurrent) makeCurrent = nullptr;
    decltype(&OSMesaGetCurrentContext) getCurrentContext = nullptr;
    decltype(&OSMesaDestroyContext) destroyContext = nullptr;
    decltype(&OSMesaGetProcAddress) getProcAddress = nullptr;
    std::string failure;  // why the library is unusable; empty when every entry point was found
};

template <typename F>
void resolve(void* library, const char* name, F& function, std::string& failure) {
    function = reinterpret_cast<F>(dlsym(library, name));
    if (!function && failure.empty()) failure = std::string("libOSMesa.so.8 lacks ") + name;
}

const OsMesaApi& osMesa() {
    static const OsMesaApi api = [] {
        OsMesaApi a;
        void* library = loadSystemLibrary("libOSMesa.so.8", a.failure);
        if (!library) return a;
        resolve(library, "OSMesaCreateContextAttribs", a.createContextAttribs, a.failure);
        resolve(library, "OSMesaMakeCurrent", a.makeCurrent, a.failure);
        resolve(library, "OSMesaGetCurrentContext", a.getCurrentContext, a.failure);
        resolve(library, "OSMesaDestroyContext", a.destroyContext, a.failure);
        resolve(library, "OSMesaGetProcAddress", a.getProcAddress, a.failure);
        return a;
    }();
    return api;
}

// glad calls this with the context current; OSMesaGetProcAddress is the library's own.
GLADapiproc osMesaProc(const char* name) { return reinterpret_cast<GLADapiproc>(osMesa().getProcAddress(name)); }

class OsMesaPlatform final : public Platform {
public:
    explicit OsMesaPlatform(OSMesaContext context) : m_context(context) {}
    ~OsMesaPlatform() override {
        if (osMesa().getCurrentContext() == m_context) release();
        osMesa().destroyContext(m_context);
    }
    bool bind() { return osMesa().makeCurrent(m_context, m_buffer.data(), GL_UNSIGNED_BYTE, 1, 1) == GL_TRUE; }
    void makeCurrent() override { bind(); }
    void release() override { osMesa().makeCurrent(nullptr, nullptr, 0, 0, 0); }
    GLADloadfunc loader() const override { return osMesaProc; }
    std::string description() const override { return "OSMesa " + std::to_string(OSMESA_MAJOR_VERSION) + "." +
                                                      std::to_string(OSMESA_MINOR_VERSION) + ", 1x1 client buffer"; }

private:
    OSMesaContext m_context;
    std::array<unsigned char, 4> m_buffer{};
};

}  // namespace

std::unique_ptr<Platform> createOsMesaPlatform(std::string& reason) {
    reason.clear();
    const OsMesaApi& api = osMesa();
    if (!api.failure.empty()) {
        reason = api.failure;
        return nullptr;
    }
    const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 0, OSMESA_STENCIL_BITS, 0,
                           OSMESA_PROFILE, OSMESA_CORE_PROFILE, OSMESA_CONTEXT_MAJOR_VERSION, 4,
                           OSMESA_CONTEXT_MINOR_VERSION, 5, 0};
    const OSMesaContext context = api.createContextAttribs(attribs, nullptr);
    if (!context) {
        reason = "OSMesaCreateContextAttribs refused an OpenGL 4.5 core context";
        return nullptr;
    }
    auto platform = std::make_unique<OsMesaPlatform>(context);
    if (!platform->bind()) {
        reason = "OSMesaMakeCurrent failed";
        return nullptr;
    }
    return platform;
}

}  // namespace conus::renderers
