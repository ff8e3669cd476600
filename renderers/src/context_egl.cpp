// EGL backend: an OpenGL 4.5 core context with no surface. Candidates in order:
//   1. device platform, hardware devices (NVIDIA's headless path; any DRM device Mesa exposes),
//   2. device platform, software devices (extension EGL_MESA_device_software: llvmpipe),
//   3. Mesa's surfaceless platform.
// eglGetDisplay(EGL_DEFAULT_DISPLAY) is not tried: it needs X or Wayland.
#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "context_pvt.h"

namespace conus::renderers {
namespace {

bool hasExtension(const char* list, const char* name) {
    if (!list) return false;
    const std::size_t n = std::strlen(name);
    for (const char* p = list; (p = std::strstr(p, name)) != nullptr; p += n)
        if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
    return false;
}

std::string eglErrorText() {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "EGL error 0x%04X", static_cast<unsigned>(eglGetError()));
    return buffer;
}

class EglPlatform final : public Platform {
public:
    EglPlatform(EGLDisplay display, EGLContext context, EGLSurface surface, std::string description)
        : m_display(display), m_context(context), m_surface(surface), m_description(std::move(description)) {}
    ~EglPlatform() override {
        if (eglGetCurrentContext() == m_context) eglMakeCurrent(m_display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(m_display, m_context);
        if (m_surface != EGL_NO_SURFACE) eglDestroySurface(m_display, m_surface);
        // No eglTerminate: a display is shared by every context on it in the process.
    }
    void makeCurrent() override {
        eglBindAPI(EGL_OPENGL_API);
        eglMakeCurrent(m_display, m_surface, m_surface, m_context);
    }
    void release() override { eglMakeCurrent(m_display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT); }
    GLADloadfunc loader() const override { return reinterpret_cast<GLADloadfunc>(eglGetProcAddress); }
    std::string description() const override { return m_description; }

private:
    EGLDisplay m_display;
    EGLContext m_context;
    EGLSurface m_surface;
    std::string m_description;
};

// A 4.5 core context on an initialized-or-not display, or nullptr and why.
std::unique_ptr<Platform> tryDisplay(EGLDisplay display, const std::string& label, std::string& why) {
    if (display == EGL_NO_DISPLAY) {
        why = label + ": no display (" + eglErrorText() + ")";
        return nullptr;
    }
    EGLint major = 0, minor = 0;
    if (!eglInitialize(display, &major, &minor)) {
        why = label + ": eglInitialize failed (" + eglErrorText() + ")";
        return nullptr;
    }
    if (!eglBindAPI(EGL_OPENGL_API)) {
        why = label + ": desktop OpenGL not offered (" + eglErrorText() + ")";
        return nullptr;
    }
    const char* extensions = eglQueryString(display, EGL_EXTENSIONS);
    const bool surfaceless = hasExtension(extensions, "EGL_KHR_surfaceless_context");
    // A config is only needed for the pbuffer of drivers without surfaceless contexts.
    EGLConfig config = EGL_NO_CONFIG_KHR;
    if (!surfaceless || !hasExtension(extensions, "EGL_KHR_no_config_context")) {
        const EGLint attribs[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
        EGLint count = 0;
        if (!eglChooseConfig(display, attribs, &config, 1, &count) || count < 1) {
            why = label + ": no OpenGL pbuffer config (" + eglErrorText() + ")";
            return nullptr;
        }
    }
    const EGLint contextAttribs[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                                     EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    const EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, contextAttribs);
    if (context == EGL_NO_CONTEXT) {
        why = label + ": no OpenGL 4.5 core context (" + eglErrorText() + ")";
        return nullptr;
    }
    EGLSurface surface = EGL_NO_SURFACE;
    if (!surfaceless) {
        const EGLint pbufferAttribs[] = {EGL_WIDTH, 1, EGL_HEIGHT, 1, EGL_NONE};
        surface = eglCreatePbufferSurface(display, config, pbufferAttribs);
        if (surface == EGL_NO_SURFACE) {
            why = label + ": no pbuffer surface (" + eglErrorText() + ")";
            eglDestroyContext(display, context);
            return nullptr;
        }
    }
    if (!eglMakeCurrent(display, surface, surface, context)) {
        why = label + ": eglMakeCurrent failed (" + eglErrorText() + ")";
        if (surface != EGL_NO_SURFACE) eglDestroySurface(display, surface);
        eglDestroyContext(display, context);
        return nullptr;
    }
    return std::make_unique<EglPlatform>(display, context, surface,
                                         "EGL " + std::to_string(major) + "." + std::to_string(minor) + ", " + label);
}

void append(std::string& reasons, const std::string& why) { reasons += (reasons.empty() ? "" : "; ") + why; }

}  // namespace

std::unique_ptr<Platform> createEglPlatform(std::string& reason) {
    reason.clear();
    const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!client) {
        reason = "EGL client extensions unavailable (" + eglErrorText() + "); no EGL vendor library?";
        return nullptr;
    }
    auto getPlatformDisplay =
        reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (!getPlatformDisplay || !hasExtension(client, "EGL_EXT_platform_base")) {
        reason = "EGL_EXT_platform_base missing";
        return nullptr;
    }

    if (disabledByEnvironment("egl-device")) {
        append(reason, "egl-device: disabled by CONUS_GL_DISABLE");
    } else if (hasExtension(client, "EGL_EXT_platform_device") && hasExtension(client, "EGL_EXT_device_enumeration")) {
        auto queryDevices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
        auto queryDeviceString =
            reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(eglGetProcAddress("eglQueryDeviceStringEXT"));
        EGLint count = 0;
        std::vector<EGLDeviceEXT> devices;
        if (queryDevices && queryDeviceString && queryDevices(0, nullptr, &count) && count > 0) {
            devices.resize(static_cast<std::size_t>(count));
            queryDevices(count, devices.data(), &count);
            devices.resize(static_cast<std::size_t>(std::max(count, 0)));
        }
        if (devices.empty()) append(reason, "EGL device platform: no devices");
        // Hardware first: on a machine with a GPU the software device would be a silent 100x loss.
        for (const bool software : {false, true}) {
            for (std::size_t i = 0; i < devices.size(); ++i) {
                const char* ext = queryDeviceString(devices[i], EGL_EXTENSIONS);
                if (hasExtension(ext, "EGL_MESA_device_software") != software) continue;
                const std::string label =
                    "device platform, device " + std::to_string(i) + (software ? " (software)" : " (hardware)");
                std::string why;
                if (auto p = tryDisplay(getPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr), label, why))
                    return p;
                append(reason, why);
            }
        }
    } else {
        append(reason, "EGL device platform not offered");
    }

    if (disabledByEnvironment("egl-surfaceless")) {
        append(reason, "egl-surfaceless: disabled by CONUS_GL_DISABLE");
    } else if (hasExtension(client, "EGL_MESA_platform_surfaceless")) {
        std::string why;
        if (auto p = tryDisplay(getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr),
                                "surfaceless platform", why))
            return p;
        append(reason, why);
    } else {
        append(reason, "EGL surfaceless platform not offered");
    }
    return nullptr;
}

}  // namespace conus::renderers
