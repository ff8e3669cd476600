// Private: owning handles for the GL objects one GPU call creates, so that an exception halfway
// (a failed allocation, a GL error) leaves nothing behind in the context.
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include <glad/gl.h>

#include "conus/core/error.h"

namespace conus::renderers {

// The Gen/Delete pair of glGen*/glDelete* share one signature; the handle keeps its Delete. An
// empty handle (default) holds nothing; moving hands the object over, assigning deletes the old one.
// The context must be current wherever a handle is destroyed or assigned.
class GlHandle {
public:
    using Gen = PFNGLGENTEXTURESPROC;
    using Del = PFNGLDELETETEXTURESPROC;
    GlHandle() = default;
    GlHandle(Gen gen, Del del) : m_del(del) { gen(1, &m_id); }
    ~GlHandle() { reset(); }
    GlHandle(const GlHandle&) = delete;
    GlHandle& operator=(const GlHandle&) = delete;
    GlHandle(GlHandle&& other) noexcept : m_del(other.m_del), m_id(other.m_id) { other.m_id = 0; }
    GlHandle& operator=(GlHandle&& other) noexcept {
        if (this != &other) {
            reset();
            m_del = other.m_del;
            m_id = other.m_id;
            other.m_id = 0;
        }
        return *this;
    }
    void reset() {
        if (m_id && m_del) m_del(1, &m_id);
        m_id = 0;
    }
    GLuint id() const { return m_id; }
    explicit operator bool() const { return m_id != 0; }

private:
    Del m_del = nullptr;
    GLuint m_id = 0;
};

inline GlHandle makeTexture(const GladGLContext& gl) { return {gl.GenTextures, gl.DeleteTextures}; }
inline GlHandle makeBuffer(const GladGLContext& gl) { return {gl.GenBuffers, gl.DeleteBuffers}; }
inline GlHandle makeFramebuffer(const GladGLContext& gl) { return {gl.GenFramebuffers, gl.DeleteFramebuffers}; }
inline GlHandle makeVertexArray(const GladGLContext& gl) { return {gl.GenVertexArrays, gl.DeleteVertexArrays}; }
inline GlHandle makeQuery(const GladGLContext& gl) { return {gl.GenQueries, gl.DeleteQueries}; }

// The sampling map's nodes as an RG32F texture on `unit`, read exactly (texelFetch, nearest) by
// Equation 1 in GLSL (equation1.inc.glsl). Leaves the texture bound on that unit.
inline GlHandle uploadMapTexture(const GladGLContext& gl, GLenum unit, int columns, int rows, const float* nodes) {
    GlHandle texture = makeTexture(gl);
    gl.ActiveTexture(unit);
    gl.BindTexture(GL_TEXTURE_2D, texture.id());
    gl.TexStorage2D(GL_TEXTURE_2D, 1, GL_RG32F, columns, rows);
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
    gl.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, columns, rows, GL_RG, GL_FLOAT, nodes);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    return texture;
}

// One level of a float image for texture upload: `pixels` holds width x height pixels of
// `channels` values, interleaved.
struct TextureLevel {
    const float* pixels;
    int width, height;
};

// Allocates the texture bound to GL_TEXTURE_2D on the active unit with levels.size() mip levels
// of internalFormat and uploads each from `format` floats; bilinear (trilinear between levels with
// more than one), clamp to edge. codec::buildPyramid's levels after the image make the mip chain
// that equation1.inc.glsl's trilinearFiltered reads.
inline void storeLevels(const GladGLContext& gl, GLenum internalFormat, GLenum format,
                        const std::vector<TextureLevel>& levels) {
    gl.TexStorage2D(GL_TEXTURE_2D, static_cast<GLsizei>(levels.size()), internalFormat, levels[0].width,
                    levels[0].height);
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
    for (std::size_t k = 0; k < levels.size(); ++k)
        gl.TexSubImage2D(GL_TEXTURE_2D, static_cast<GLint>(k), 0, 0, levels[k].width, levels[k].height, format,
                         GL_FLOAT, levels[k].pixels);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, levels.size() > 1 ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}

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

// An RGBA32F colour attachment of width x height, bound for drawing with the viewport set to it
// (what a pass reads back as float).
struct FloatTarget {
    GlHandle texture, framebuffer;
    FloatTarget(const GladGLContext& gl, int width, int height, const char* what)
        : texture(makeTexture(gl)), framebuffer(makeFramebuffer(gl)) {
        gl.BindTexture(GL_TEXTURE_2D, texture.id());
        gl.TexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, width, height);
        gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer.id());
        gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, texture.id(), 0);
        checkGl(gl, what);
        if (gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
            throw Error(ErrorCode::Unsupported, std::string(what) + ": the driver cannot render to a " +
                                                    std::to_string(width) + "x" + std::to_string(height) +
                                                    " RGBA32F framebuffer");
        gl.Viewport(0, 0, width, height);
    }
};

// Stage timings of the GPU paths: the milliseconds since `start`, which then moves to now.
using Clock = std::chrono::steady_clock;
inline double millisecondsSince(Clock::time_point& start) {
    const Clock::time_point now = Clock::now();
    const double ms = std::chrono::duration<double, std::milli>(now - start).count();
    start = now;
    return ms;
}

// Fills a vertex array's interleaved float vertices and its triangle indices (static draw); the
// caller then describes the attributes.
inline void uploadIndexedMesh(const GladGLContext& gl, GLuint vertexArray, GLuint vertexBuffer, GLuint indexBuffer,
                              const std::vector<float>& vertices, const std::vector<std::uint32_t>& indices) {
    gl.BindVertexArray(vertexArray);
    gl.BindBuffer(GL_ARRAY_BUFFER, vertexBuffer);
    gl.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(float)), vertices.data(),
                  GL_STATIC_DRAW);
    gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, indexBuffer);
    gl.BufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(indices.size() * sizeof(std::uint32_t)),
                  indices.data(), GL_STATIC_DRAW);
}

}  // namespace conus::renderers
