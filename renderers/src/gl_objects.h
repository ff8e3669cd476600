// Private: owning handles for the GL objects one GPU call creates, so that an exception halfway
// (a failed allocation, a GL error) leaves nothing behind in the context.
#pragma once

#include <cstdio>
#include <string>

#include <glad/gl.h>

#include "conus/core/error.h"

namespace conus::gl {

// The Gen/Delete pair of glGen*/glDelete* share one signature; the handle keeps its Delete.
class GlHandle {
public:
    using Gen = PFNGLGENTEXTURESPROC;
    using Del = PFNGLDELETETEXTURESPROC;
    GlHandle(Gen gen, Del del) : m_del(del) { gen(1, &m_id); }
    ~GlHandle() {
        if (m_id) m_del(1, &m_id);
    }
    GlHandle(const GlHandle&) = delete;
    GlHandle& operator=(const GlHandle&) = delete;
    GLuint id() const { return m_id; }

private:
    Del m_del;
    GLuint m_id = 0;
};

inline GlHandle makeTexture(const GladGLContext& gl) { return {gl.GenTextures, gl.DeleteTextures}; }
inline GlHandle makeBuffer(const GladGLContext& gl) { return {gl.GenBuffers, gl.DeleteBuffers}; }
inline GlHandle makeFramebuffer(const GladGLContext& gl) { return {gl.GenFramebuffers, gl.DeleteFramebuffers}; }
inline GlHandle makeVertexArray(const GladGLContext& gl) { return {gl.GenVertexArrays, gl.DeleteVertexArrays}; }

// Throws on a pending GL error: out of memory -> LimitExceeded, anything else -> Unsupported
// (a driver that refused a valid request).
inline void checkGl(const GladGLContext& gl, const char* what) {
    const GLenum error = gl.GetError();
    if (error == GL_NO_ERROR) return;
    while (gl.GetError() != GL_NO_ERROR) {
    }
    if (error == GL_OUT_OF_MEMORY)
        throw Error(ErrorCode::LimitExceeded, std::string(what) + ": the GL driver ran out of memory");
    throw Error(ErrorCode::Unsupported, std::string(what) + ": GL error 0x" + [&] {
        char buffer[16];
        std::snprintf(buffer, sizeof buffer, "%04X", error);
        return std::string(buffer);
    }());
}

}  // namespace conus::gl
