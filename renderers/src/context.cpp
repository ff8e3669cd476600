// The ordered backend list and what every Context shares: loading GL through glad (one function
// table per context) and the cache of compiled programs.
#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <sstream>
#include <vector>

#include "context_pvt.h"
#include "shader_constants_pvt.h"
#include "conus/core/error.h"

namespace conus::renderers {
namespace {

// Platforms differ in dispatch; the one bound last on this thread is released before another.
thread_local Platform* tCurrent = nullptr;

void bind(Platform* platform) {
    if (tCurrent && tCurrent != platform) tCurrent->release();
    platform->makeCurrent();
    tCurrent = platform;
}

std::string glString(const GladGLContext& gl, GLenum name) {
    const GLubyte* s = gl.GetString(name);
    return s ? reinterpret_cast<const char*>(s) : "";
}

// Loads GL 4.5 core into a context whose platform is current and reads what every Context
// knows of itself. Empty on success, else why not.
std::string loadGl(Context::Impl& impl) {
    const int version = gladLoadGLContext(&impl.gl, impl.platform->loader());
    if (version == 0 || GLAD_VERSION_MAJOR(version) * 10 + GLAD_VERSION_MINOR(version) < 45)
        return impl.platform->description() + ": could not load OpenGL 4.5 core entry points (glad reports " +
               std::to_string(GLAD_VERSION_MAJOR(version)) + "." + std::to_string(GLAD_VERSION_MINOR(version)) + ")";
    impl.renderer = glString(impl.gl, GL_RENDERER);
    impl.version = glString(impl.gl, GL_VERSION);
    impl.gl.GetIntegerv(GL_MAX_TEXTURE_SIZE, &impl.maxTextureSize);
    impl.gl.GenVertexArrays(1, &impl.emptyVertexArray);
    return {};
}

// One backend: a current context with GL 4.5 loaded, or nullptr and the reason.
std::unique_ptr<Context::Impl> tryBackend(Backend backend, std::string& reason) {
    if (disabledByEnvironment(enumName(backend))) {
        reason = "disabled by CONUS_GL_DISABLE";
        return nullptr;
    }
    auto impl = std::make_unique<Context::Impl>();
    impl->backend = backend;
    if (tCurrent) {
        tCurrent->release();  // creating a context may bind it before we know it works
        tCurrent = nullptr;
    }
    impl->platform = backend == Backend::Egl ? createEglPlatform(reason) : createOsMesaPlatform(reason);
    if (!impl->platform) return nullptr;
    tCurrent = impl->platform.get();
    if (const std::string failure = loadGl(*impl); !failure.empty()) {
        reason += std::string(reason.empty() ? "" : "; ") + failure;
        return nullptr;
    }
    impl->reason = impl->platform->description() + (reason.empty() ? "" : " (after: " + reason + ")");
    return impl;
}

// The caller's context: binding and unbinding it are the caller's business (GLFW's, say).
class AdoptedPlatform final : public Platform {
public:
    explicit AdoptedPlatform(GetProcFn getProc) : m_getProc(getProc) {}
    void makeCurrent() override {}
    void release() override {}
    GLADloadfunc loader() const override { return reinterpret_cast<GLADloadfunc>(m_getProc); }
    std::string description() const override { return "adopted GL context (owned by the caller)"; }

private:
    GetProcFn m_getProc;
};

constexpr int kMinTextureLimit = 64;

}  // namespace

bool disabledByEnvironment(const std::string& name) {
    const char* env = std::getenv("CONUS_GL_DISABLE");
    if (!env) return false;
    std::string list(env);
    std::transform(list.begin(), list.end(), list.begin(), [](unsigned char c) { return std::tolower(c); });
    std::stringstream ss(list);
    for (std::string item; std::getline(ss, item, ',');)
        if (item == name) return true;
    return false;
}

Context::Impl::~Impl() {
    if (!platform) return;
    bind(platform.get());
    for (const auto& [key, program] : programs) gl.DeleteProgram(program);
    if (emptyVertexArray) gl.DeleteVertexArrays(1, &emptyVertexArray);
    platform->release();
    if (tCurrent == platform.get()) tCurrent = nullptr;
}

std::vector<BackendStatus> probeBackends() {
    std::vector<BackendStatus> out;
    for (Backend b : {Backend::Egl, Backend::OsMesa}) {
        BackendStatus status;
        status.backend = b;
        std::string reason;
        if (auto impl = tryBackend(b, reason)) {
            status.works = true;
            status.renderer = impl->renderer;
            status.version = impl->version;
            status.reason = impl->reason;
        } else {
            status.reason = reason;
        }
        out.push_back(status);
    }
    out.push_back({Backend::Cpu, true, "CPU reference (conus::codec)", "", "always available"});
    return out;
}

std::unique_ptr<Context> Context::create(Backend backend) {
    if (backend == Backend::Cpu)
        throw Error(ErrorCode::InvalidArgument,
                    "Context::create: the cpu backend has no GL context (use codec::encodeImage / decodeImage)");
    // EGL first: it reaches hardware devices and is what GPU machines offer headless; OSMesa is
    // Mesa-only software rendering, kept as the fallback.
    const std::vector<Backend> order =
        backend == Backend::Auto ? std::vector<Backend>{Backend::Egl, Backend::OsMesa} : std::vector<Backend>{backend};
    std::string reasons;
    for (Backend b : order) {
        std::string reason;
        if (auto impl = tryBackend(b, reason)) return std::make_unique<Context>(std::move(impl));
        reasons += std::string(reasons.empty() ? "" : "; ") + enumName(b) + ": " + reason;
    }
    throw Error(ErrorCode::Unsupported, "no OpenGL 4.5 context (" + reasons + ")");
}

std::unique_ptr<Context> adoptCurrentContext(GetProcFn getProc) {
    if (!getProc) throw Error(ErrorCode::InvalidArgument, "adoptCurrentContext: no GL loader given");
    auto impl = std::make_unique<Context::Impl>();
    impl->backend = Backend::Auto;
    impl->platform = std::make_unique<AdoptedPlatform>(getProc);
    if (const std::string failure = loadGl(*impl); !failure.empty()) {
        impl->platform.reset();  // nothing was created in the caller's context
        throw Error(ErrorCode::Unsupported, "adoptCurrentContext: " + failure);
    }
    impl->reason = impl->platform->description();
    return std::make_unique<Context>(std::move(impl));
}

int Context::textureLimit() const {
    const int limit = m_impl->maxTextureSize;
    const char* env = std::getenv(kTextureLimitVariable);
    if (!env || !*env) return limit;
    char* end = nullptr;
    const long value = std::strtol(env, &end, 10);
    if (end == env || *end != '\0' || value <= 0)
        throw Error(ErrorCode::InvalidArgument, std::string(kTextureLimitVariable) + "=\"" + env +
                                                    "\" is not a positive whole number of texels");
    return static_cast<int>(std::clamp<long>(value, std::min(kMinTextureLimit, limit), limit));
}

Context::Context(std::unique_ptr<Impl> impl) : m_impl(std::move(impl)) {}
Context::~Context() = default;

Backend Context::backend() const { return m_impl->backend; }
std::string Context::renderer() const { return m_impl->renderer; }
std::string Context::version() const { return m_impl->version; }
std::string Context::description() const { return m_impl->reason; }
int Context::maxTextureSize() const { return m_impl->maxTextureSize; }
void Context::makeCurrent() { bind(m_impl->platform.get()); }

const GladGLContext& makeCurrentGl(Context& context) {
    context.makeCurrent();
    return context.impl().gl;
}

namespace {

// Returns when the shader `name` compiled or the program `name` linked (`status`: GL_COMPILE_STATUS or
// GL_LINK_STATUS; the three functions the shader's or the program's); otherwise deletes it and
// throws Unsupported with `failure` and the compiler's or linker's log.
void throwUnlessBuilt(GLuint name, GLenum status, PFNGLGETSHADERIVPROC getParameter, PFNGLGETSHADERINFOLOGPROC getLog,
                      PFNGLDELETESHADERPROC destroy, const std::string& failure) {
    GLint ok = 0;
    getParameter(name, status, &ok);
    if (ok) return;
    GLint length = 0;
    getParameter(name, GL_INFO_LOG_LENGTH, &length);
    std::string log(static_cast<std::size_t>(std::max(length, 1)), '\0');
    getLog(name, length, nullptr, log.data());
    destroy(name);
    throw Error(ErrorCode::Unsupported, failure + ": " + log);
}

GLuint compileShader(const GladGLContext& gl, GLenum type, const char* source, const std::string& key) {
    const GLuint shader = gl.CreateShader(type);
    gl.ShaderSource(shader, 1, &source, nullptr);
    gl.CompileShader(shader);
    throwUnlessBuilt(shader, GL_COMPILE_STATUS, gl.GetShaderiv, gl.GetShaderInfoLog, gl.DeleteShader,
                     "GLSL compile failed (" + key + ")");
    return shader;
}

}  // namespace

GLuint cachedProgram(Context& context, const std::string& key, std::initializer_list<ShaderStage> stages) {
    Context::Impl& impl = context.impl();
    if (auto it = impl.programs.find(key); it != impl.programs.end()) return it->second;
    const GladGLContext& gl = impl.gl;
    std::vector<GLuint> shaders;
    try {
        for (const ShaderStage& stage : stages)
            shaders.push_back(compileShader(gl, stage.type, withSharedConstants(stage.source).c_str(), key));
    } catch (...) {
        for (GLuint shader : shaders) gl.DeleteShader(shader);
        throw;
    }
    const GLuint program = gl.CreateProgram();
    for (GLuint shader : shaders) gl.AttachShader(program, shader);
    gl.LinkProgram(program);
    for (GLuint shader : shaders) gl.DeleteShader(shader);
    throwUnlessBuilt(program, GL_LINK_STATUS, gl.GetProgramiv, gl.GetProgramInfoLog, gl.DeleteProgram,
                     "GLSL link failed (" + key + ")");
    impl.programs.emplace(key, program);
    return program;
}

GLuint cachedProgram(Context& context, const std::string& key, const char* vertex, const char* fragment) {
    return cachedProgram(context, key, {{GL_VERTEX_SHADER, vertex}, {GL_FRAGMENT_SHADER, fragment}});
}

}  // namespace conus::renderers
