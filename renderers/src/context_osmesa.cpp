// OSMesa backend: Mesa's off-screen library, an OpenGL 4.5 core context rendering into a client
// buffer. We render only to framebuffer objects, but OSMesaMakeCurrent insists on a buffer, so each
// context carries a 1x1 one.
#include <array>

#include "context_pvt.h"

// GL/osmesa.h expects GL/gl.h, which glad's header replaces (and blocks): it then lacks these two.
#ifndef GLAPI
#define GLAPI extern
#endif
#ifndef GLAPIENTRY
#define GLAPIENTRY
#endif
#include <GL/osmesa.h>

namespace conus::gl {
namespace {

class OsMesaPlatform final : public Platform {
public:
    explicit OsMesaPlatform(OSMesaContext context) : m_context(context) {}
    ~OsMesaPlatform() override {
        if (OSMesaGetCurrentContext() == m_context) release();
        OSMesaDestroyContext(m_context);
    }
    bool bind() { return OSMesaMakeCurrent(m_context, m_buffer.data(), GL_UNSIGNED_BYTE, 1, 1) == GL_TRUE; }
    void makeCurrent() override { bind(); }
    void release() override { OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0); }
    GLADloadfunc loader() const override { return reinterpret_cast<GLADloadfunc>(OSMesaGetProcAddress); }
    std::string description() const override { return "OSMesa " + std::to_string(OSMESA_MAJOR_VERSION) + "." +
                                                      std::to_string(OSMESA_MINOR_VERSION) + ", 1x1 client buffer"; }

private:
    OSMesaContext m_context;
    std::array<unsigned char, 4> m_buffer{};
};

}  // namespace

std::unique_ptr<Platform> createOsMesaPlatform(std::string& reason) {
    reason.clear();
    const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 0, OSMESA_STENCIL_BITS, 0,
                           OSMESA_PROFILE, OSMESA_CORE_PROFILE, OSMESA_CONTEXT_MAJOR_VERSION, 4,
                           OSMESA_CONTEXT_MINOR_VERSION, 5, 0};
    const OSMesaContext context = OSMesaCreateContextAttribs(attribs, nullptr);
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

}  // namespace conus::gl
