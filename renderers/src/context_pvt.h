// Private: what a context backend provides (one .cpp per backend, compiled only when its library
// was found; context_*_missing.cpp stands in otherwise) and the state a Context holds.
#pragma once

#include <initializer_list>
#include <map>
#include <memory>
#include <string>

#include <glad/gl.h>

#include "conus/renderers/context.h"

namespace conus::renderers {

// One backend's native context, already current on the calling thread when returned.
class Platform {
public:
    virtual ~Platform() = default;
    virtual void makeCurrent() = 0;
    // Unbinds it from the calling thread (before another backend's context is made current:
    // EGL and OSMesa share Mesa's dispatch, and a stale binding would route calls to the wrong one).
    virtual void release() = 0;
    virtual GLADloadfunc loader() const = 0;
    virtual std::string description() const = 0;
};

// Whether CONUS_GL_DISABLE lists `name` ("egl", "egl-device", "egl-surfaceless", "osmesa").
bool disabledByEnvironment(const std::string& name);

// Each returns a current context, or nullptr with `reason` saying why every candidate failed.
// `reason` is also filled with the refusals before a candidate that worked.
std::unique_ptr<Platform> createEglPlatform(std::string& reason);
std::unique_ptr<Platform> createOsMesaPlatform(std::string& reason);

struct Context::Impl {
    Backend backend = Backend::Auto;
    std::unique_ptr<Platform> platform;
    GladGLContext gl{};
    std::string renderer, version, reason;
    int maxTextureSize = 0;
    std::map<std::string, GLuint> programs;  // compiled once per context (LLVM compiles are slow)
    GLuint emptyVertexArray = 0;             // core profile draws need one bound
    ~Impl();
};

// The GL function table of a context made current on this thread.
const GladGLContext& makeCurrentGl(Context& context);
// A linked program from the cache, compiled on first use; throws conus::Error(Unsupported) with
// the GLSL log when it does not compile.
GLuint cachedProgram(Context& context, const std::string& key, const char* vertex, const char* fragment);
// The same for any stages (tessellation's between the vertex and the fragment shader).
struct ShaderStage {
    GLenum type;  // GL_VERTEX_SHADER, GL_TESS_CONTROL_SHADER, ...
    const char* source;
};
GLuint cachedProgram(Context& context, const std::string& key, std::initializer_list<ShaderStage> stages);

}  // namespace conus::renderers
