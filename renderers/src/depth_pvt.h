// Private: a CoNUS depth image on the GPU, as intersect.inc.glsl reads it (relief and reflection
// renderers): its textures (camera depths R32F, each carrying its cell's discontinuity flag in its
// lowest mantissa bit; the map's nodes RG32F) and its DepthView uniforms;
// and what both renderers' frames share: an RGBA32F target, one full-screen pass into it, and the
// scene a DepthFrameRenderer keeps (depth_frames.h).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <glm/gtc/type_ptr.hpp>

#include "conus/codec/depth/glsl_interface.h"
#include "conus/renderers/depth_frames.h"
#include "context_pvt.h"
#include "gl_objects_pvt.h"

namespace conus::renderers {

// A float texture of `channels` channels from interleaved data, nearest (or linear) filtering,
// clamped. Leaves it bound on `unit`.
inline GlHandle floatTexture(const GladGLContext& gl, GLenum unit, int width, int height, int channels,
                             const float* data, bool linear = false) {
    static constexpr GLenum kInternal[] = {GL_R32F, GL_RG32F, GL_RGB32F, GL_RGBA32F};
    static constexpr GLenum kFormat[] = {GL_RED, GL_RG, GL_RGB, GL_RGBA};
    GlHandle texture = makeTexture(gl);
    gl.ActiveTexture(unit);
    gl.BindTexture(GL_TEXTURE_2D, texture.id());
    gl.TexStorage2D(GL_TEXTURE_2D, 1, kInternal[channels - 1], width, height);
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
    gl.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width, height, kFormat[channels - 1], GL_FLOAT, data);
    const GLint filter = linear ? GL_LINEAR : GL_NEAREST;
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, filter);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return texture;
}

// The depth image's textures: depths on texture unit `unit`, map nodes on unit + 1. A layered
// image's layers (one camera, one map, one size) lie side by side in the depth texture.
struct DepthTextures {
    GlHandle depths, map;
    int unit = 0;

    DepthTextures(Context& context, const GladGLContext& gl, const codec::DepthImage& image, const char* what,
                  int firstUnit = 0)
        : DepthTextures(context, gl, std::vector<const codec::DepthImage*>{&image}, what, firstUnit) {}

    DepthTextures(Context& context, const GladGLContext& gl, const std::vector<const codec::DepthImage*>& layers,
                  const char* what, int firstUnit = 0)
        : unit(firstUnit) {
        const codec::DepthImage& image = *layers.front();
        const long long wide = static_cast<long long>(image.width()) * static_cast<long long>(layers.size());
        if (wide > context.maxTextureSize() || image.height() > context.maxTextureSize())
            throw Error(ErrorCode::LimitExceeded, std::string(what) + ": depth image " + std::to_string(image.width()) +
                                                      "x" + std::to_string(image.height()) +
                                                      (layers.size() > 1 ? " of " + std::to_string(layers.size()) + " layers side by side" : "") +
                                                      " exceeds GL_MAX_TEXTURE_SIZE " +
                                                      std::to_string(context.maxTextureSize()));
        std::vector<std::vector<float>> flagged;
        for (const codec::DepthImage* layer : layers) flagged.push_back(flaggedDepths(*layer));
        depths = floatTexture(gl, GL_TEXTURE0 + static_cast<GLenum>(unit), static_cast<int>(wide), image.height(), 1,
                              layers.size() == 1 ? flagged.front().data()
                                                 : codec::sideBySide(flagged, image.width(), image.height(), 1).data());
        const codec::SamplingMap& sampling = image.map();
        map = uploadMapTexture(gl, GL_TEXTURE0 + static_cast<GLenum>(unit + 1), sampling.columns(), sampling.rows(),
                               glm::value_ptr(sampling.nodes().front()));
    }

    void bind(const GladGLContext& gl) const {
        gl.ActiveTexture(GL_TEXTURE0 + static_cast<GLenum>(unit));
        gl.BindTexture(GL_TEXTURE_2D, depths.id());
        gl.ActiveTexture(GL_TEXTURE0 + static_cast<GLenum>(unit + 1));
        gl.BindTexture(GL_TEXTURE_2D, map.id());
    }
};

// The DepthView uniform `view` (e.g. "uView" or "uViews[2]") of `image`, and the samplers named
// `depths` and `map` pointed at the units of `textures`.
inline void setDepthView(const GladGLContext& gl, GLuint program, const codec::DepthImage& image,
                         const DepthTextures& textures, const std::string& view = "uView",
                         const std::string& depths = "uDepths", const std::string& map = "uMap") {
    const codec::DepthViewValues v = codec::depthViewValues(image);
    const auto at = [&](const char* field) { return gl.GetUniformLocation(program, (view + field).c_str()); };
    gl.UniformMatrix4fv(at(".worldToNdc"), 1, GL_FALSE, glm::value_ptr(v.worldToNdc));
    gl.UniformMatrix4fv(at(".ndcToWorld"), 1, GL_FALSE, glm::value_ptr(v.ndcToWorld));
    gl.Uniform3f(at(".eye"), v.eye.x, v.eye.y, v.eye.z);
    gl.Uniform3f(at(".forward"), v.forward.x, v.forward.y, v.forward.z);
    gl.Uniform1f(at(".near"), v.near);
    gl.Uniform1f(at(".far"), v.far);
    gl.Uniform1i(at(".perspective"), v.perspective ? 1 : 0);
    gl.Uniform1f(at(".minDepth"), v.minDepth);
    gl.Uniform1f(at(".maxDepth"), v.maxDepth);
    gl.Uniform1i(at(".solid"), v.solid ? 1 : 0);
    gl.Uniform1f(at(".jumpRelative"), v.jumpRelative);
    gl.Uniform1f(at(".jumpAbsolute"), v.jumpAbsolute);
    gl.Uniform1i(gl.GetUniformLocation(program, depths.c_str()), textures.unit);
    gl.Uniform1i(gl.GetUniformLocation(program, map.c_str()), textures.unit + 1);
}

inline void setIntersectOptions(const GladGLContext& gl, GLuint program, const codec::IntersectOptions& options) {
    gl.Uniform1f(gl.GetUniformLocation(program, "uStepTexels"), static_cast<float>(options.stepTexels));
    gl.Uniform1i(gl.GetUniformLocation(program, "uRefinements"), options.refinements);
    gl.Uniform1i(gl.GetUniformLocation(program, "uMaxSteps"), options.maxSteps);
}

// A float RGBA frame and its framebuffer, allocated again only when the size changes.
struct FrameTarget {
    GlHandle texture, framebuffer;
    int width = 0, height = 0;

    // Leaves the framebuffer bound. `unit` is a texture unit the pass does not sample.
    void ensure(const GladGLContext& gl, int w, int h, GLenum unit, const char* what) {
        if (w != width || h != height || !framebuffer) {
            framebuffer.reset();
            texture = makeTexture(gl);
            gl.ActiveTexture(unit);
            gl.BindTexture(GL_TEXTURE_2D, texture.id());
            gl.TexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, w, h);
            framebuffer = makeFramebuffer(gl);
            gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer.id());
            gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, texture.id(), 0);
            if (gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
                throw Error(ErrorCode::Unsupported, std::string(what) + ": the driver cannot render to a " +
                                                        std::to_string(w) + "x" + std::to_string(h) +
                                                        " RGBA32F target");
            width = w;
            height = h;
        }
        gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer.id());
    }
};

// The full-screen triangle (fullscreen.vert.glsl) over a w x h viewport with the bound program.
inline void drawFullscreen(Context& context, const GladGLContext& gl, int w, int h, const char* what) {
    gl.Viewport(0, 0, w, h);
    gl.Disable(GL_DEPTH_TEST);
    gl.BindVertexArray(context.impl().emptyVertexArray);
    gl.DrawArrays(GL_TRIANGLES, 0, 3);
    gl.BindVertexArray(0);
    checkGl(gl, what);
}

// A DepthFrameRenderer's uploaded assets and its draw: drawFrame leaves the frame in `target`,
// bound; render reads `channels` of it back (three: GL's R, G, B; four: R, G, B, A).
struct DepthFrameRenderer::Scene {
    Scene(Context& c, const char* renderer, std::vector<std::string> frameChannels)
        : context(c), what(renderer), channels(std::move(frameChannels)) {}
    virtual ~Scene() = default;
    Scene(const Scene&) = delete;
    Scene& operator=(const Scene&) = delete;

    virtual void drawFrame(const Camera& camera, int w, int h) = 0;

    Context& context;
    const char* what;  // the renderer, in errors
    std::vector<std::string> channels;
    FrameTarget target;
};

}  // namespace conus::renderers
