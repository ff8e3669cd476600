// Ray / depth-image intersection on a Context: a full-screen pass per batch of rays
// (intersect_rays.frag.glsl) and relief frames (relief.frag.glsl), both through intersect.inc.glsl.
// Window row 0 is the frame's top row, as in the other renderers, so readbacks need no flip.
#include "conus/renderers/relief.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <string>

#include <glm/gtc/type_ptr.hpp>

#include "context_pvt.h"
#include "embedded_shaders.h"
#include "frame_pvt.h"
#include "gl_objects.h"

namespace conus::gl {
namespace {

constexpr const char* kWhat = "relief";
constexpr int kRayRowLength = 1024;  // rays per row of the ray textures

// A float texture of `channels` channels from interleaved data, nearest filtering, clamped.
GlHandle floatTexture(const GladGLContext& gl, GLenum unit, int width, int height, int channels, const float* data,
                      bool linear = false) {
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

// The depth image's textures (depths on unit 0, map nodes on unit 1) and its DepthView uniforms.
struct DepthTextures {
    GlHandle depths, map;

    DepthTextures(Context& context, const GladGLContext& gl, const codec::DepthImage& image) {
        if (image.width() > context.maxTextureSize() || image.height() > context.maxTextureSize())
            throw Error(ErrorCode::LimitExceeded, std::string(kWhat) + ": depth image " + std::to_string(image.width()) +
                                                      "x" + std::to_string(image.height()) +
                                                      " exceeds GL_MAX_TEXTURE_SIZE " +
                                                      std::to_string(context.maxTextureSize()));
        depths = floatTexture(gl, GL_TEXTURE0, image.width(), image.height(), 1, image.depths().data());
        const codec::SamplingMap& sampling = image.map();
        map = uploadMapTexture(gl, GL_TEXTURE1, sampling.columns(), sampling.rows(),
                               glm::value_ptr(sampling.nodes().front()));
    }

    void bind(const GladGLContext& gl) const {
        gl.ActiveTexture(GL_TEXTURE0);
        gl.BindTexture(GL_TEXTURE_2D, depths.id());
        gl.ActiveTexture(GL_TEXTURE1);
        gl.BindTexture(GL_TEXTURE_2D, map.id());
    }
};

// One full-screen triangle into the bound width x height framebuffer, without depth test: the
// fragment shader runs once for every pixel.
void drawFullScreen(const GladGLContext& gl, Context& context, int width, int height) {
    gl.Viewport(0, 0, width, height);
    gl.Disable(GL_DEPTH_TEST);
    gl.BindVertexArray(context.impl().emptyVertexArray);
    gl.DrawArrays(GL_TRIANGLES, 0, 3);
    gl.BindVertexArray(0);
    checkGl(gl, kWhat);
}

void setDepthView(const GladGLContext& gl, GLuint program, const codec::DepthImage& image) {
    const Camera& camera = image.camera();
    const glm::dmat4 toNdc = camera.worldToNdcMatrix();
    const glm::mat4 worldToNdc(toNdc), ndcToWorld(glm::inverse(toNdc));
    const glm::vec3 eye(camera.eye()), forward(camera.forward());
    const auto at = [&](const char* name) { return gl.GetUniformLocation(program, name); };
    gl.UniformMatrix4fv(at("uView.worldToNdc"), 1, GL_FALSE, glm::value_ptr(worldToNdc));
    gl.UniformMatrix4fv(at("uView.ndcToWorld"), 1, GL_FALSE, glm::value_ptr(ndcToWorld));
    gl.Uniform3f(at("uView.eye"), eye.x, eye.y, eye.z);
    gl.Uniform3f(at("uView.forward"), forward.x, forward.y, forward.z);
    gl.Uniform1f(at("uView.near"), static_cast<float>(camera.near()));
    gl.Uniform1i(at("uView.perspective"), camera.projection() == Projection::Perspective ? 1 : 0);
    gl.Uniform1f(at("uView.minDepth"), static_cast<float>(image.minDepth()));
    gl.Uniform1f(at("uView.maxDepth"), static_cast<float>(image.maxDepth()));
    gl.Uniform1i(at("uDepths"), 0);
    gl.Uniform1i(at("uMap"), 1);
}

void setIntersectOptions(const GladGLContext& gl, GLuint program, const codec::IntersectOptions& options) {
    gl.Uniform1f(gl.GetUniformLocation(program, "uStepTexels"), static_cast<float>(options.stepTexels));
    gl.Uniform1i(gl.GetUniformLocation(program, "uRefinements"), options.refinements);
    gl.Uniform1i(gl.GetUniformLocation(program, "uMaxSteps"), options.maxSteps);
}

}  // namespace

std::vector<std::optional<codec::DepthHit>> intersectRays(Context& context, const codec::DepthImage& image,
                                                          const std::vector<Ray>& rays,
                                                          const codec::IntersectOptions& options) {
    codec::checkIntersectOptions(options);
    for (const Ray& ray : rays) codec::checkRay(ray);
    if (rays.empty()) return {};
    const int width = static_cast<int>(std::min<std::size_t>(rays.size(), kRayRowLength));
    const int height = static_cast<int>((rays.size() + kRayRowLength - 1) / kRayRowLength);
    checkFrame(context, width, height, kWhat);

    const GladGLContext& gl = makeCurrentGl(context);
    const GLuint program = cachedProgram(context, "intersect_rays", shaders::kShaderFullscreenVert,
                                         shaders::kShaderIntersectRaysFrag);
    const DepthTextures textures(context, gl, image);
    const std::size_t slots = static_cast<std::size_t>(width) * height;
    std::vector<float> origins(slots * 4, 0.0f), directions(slots * 4, 0.0f);
    for (std::size_t i = 0; i < rays.size(); ++i)
        for (int k = 0; k < 3; ++k) {
            origins[i * 4 + k] = static_cast<float>(rays[i].origin[k]);
            directions[i * 4 + k] = static_cast<float>(rays[i].direction[k]);
        }
    // Padding slots get a zero direction: they clip to nothing or walk a point, and are not read.
    const GlHandle originTexture = floatTexture(gl, GL_TEXTURE2, width, height, 4, origins.data());
    const GlHandle directionTexture = floatTexture(gl, GL_TEXTURE3, width, height, 4, directions.data());
    textures.bind(gl);

    std::array<GlHandle, 4> targets;
    const GlHandle framebuffer = makeFramebuffer(gl);
    gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer.id());
    std::array<GLenum, 4> buffers{};
    for (int k = 0; k < 4; ++k) {
        targets[k] = makeTexture(gl);
        gl.ActiveTexture(GL_TEXTURE4);
        gl.BindTexture(GL_TEXTURE_2D, targets[k].id());
        gl.TexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, width, height);
        buffers[k] = GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(k);
        gl.FramebufferTexture2D(GL_FRAMEBUFFER, buffers[k], GL_TEXTURE_2D, targets[k].id(), 0);
    }
    gl.DrawBuffers(4, buffers.data());
    if (gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        throw Error(ErrorCode::Unsupported, std::string(kWhat) + ": the driver cannot render to four RGBA32F targets");

    gl.UseProgram(program);
    setDepthView(gl, program, image);
    setIntersectOptions(gl, program, options);
    gl.Uniform1f(gl.GetUniformLocation(program, "uTMax"), static_cast<float>(std::min(options.tMax, 1e30)));
    gl.Uniform1i(gl.GetUniformLocation(program, "uOrigins"), 2);
    gl.Uniform1i(gl.GetUniformLocation(program, "uDirections"), 3);
    drawFullScreen(gl, context, width, height);

    std::array<std::vector<float>, 4> out;
    gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
    for (int k = 0; k < 4; ++k) {
        out[k].resize(slots * 4);
        gl.ReadBuffer(buffers[k]);
        gl.ReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, out[k].data());
    }
    gl.ReadBuffer(GL_COLOR_ATTACHMENT0);
    gl.DrawBuffer(GL_COLOR_ATTACHMENT0);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    checkGl(gl, kWhat);

    std::vector<std::optional<codec::DepthHit>> hits(rays.size());
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const float* h = &out[0][i * 4];
        if (h[0] < 0.5f) continue;
        codec::DepthHit hit;
        hit.t = h[1];
        hit.depth = h[2];
        hit.steps = static_cast<int>(h[3]);
        hit.position = glm::dvec3(out[1][i * 4], out[1][i * 4 + 1], out[1][i * 4 + 2]);
        hit.face = static_cast<int>(out[1][i * 4 + 3]);
        hit.point = glm::dvec2(out[2][i * 4], out[2][i * 4 + 1]);
        hit.distorted = glm::dvec2(out[2][i * 4 + 2], out[2][i * 4 + 3]);
        hit.texel = glm::ivec2(static_cast<int>(out[3][i * 4]), static_cast<int>(out[3][i * 4 + 1]));
        hits[i] = hit;
    }
    return hits;
}

struct ReliefRenderer::Impl {
    Context& context;
    const codec::DepthImage image;
    ReliefLook look;
    DepthTextures textures;
    GlHandle colour;
    int width = 0, height = 0;
    GlHandle target, framebuffer;

    Impl(Context& c, const GladGLContext& gl, const codec::DepthImage& i, const Image& rgb, const ReliefLook& l)
        : context(c), image(i), look(l), textures(c, gl, i) {
        std::vector<float> pixels(static_cast<std::size_t>(rgb.width) * rgb.height * 3, 0.7f);
        int channels[3];
        for (int k = 0; k < 3; ++k) channels[k] = rgb.channelIndex(std::string(1, "RGB"[k]));
        for (std::size_t p = 0; p < pixels.size() / 3; ++p)
            for (int k = 0; k < 3; ++k)
                if (channels[k] >= 0) pixels[p * 3 + k] = rgb.pixels[p * rgb.channels.size() + channels[k]];
        colour = floatTexture(gl, GL_TEXTURE2, rgb.width, rgb.height, 3, pixels.data(), true);
    }

    void ensureTarget(const GladGLContext& gl, int w, int h) {
        if (w == width && h == height && framebuffer) return;
        framebuffer.reset();
        target = makeTexture(gl);
        gl.ActiveTexture(GL_TEXTURE4);
        gl.BindTexture(GL_TEXTURE_2D, target.id());
        gl.TexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, w, h);
        framebuffer = makeFramebuffer(gl);
        gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer.id());
        gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, target.id(), 0);
        if (gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
            throw Error(ErrorCode::Unsupported, std::string(kWhat) + ": the driver cannot render to a " +
                                                    std::to_string(w) + "x" + std::to_string(h) + " RGBA32F target");
        width = w;
        height = h;
    }

    void drawFrame(const Camera& camera, int w, int h) {
        checkFrame(context, w, h, kWhat);
        const GladGLContext& gl = makeCurrentGl(context);
        const GLuint program =
            cachedProgram(context, "relief", shaders::kShaderFullscreenVert, shaders::kShaderReliefFrag);
        ensureTarget(gl, w, h);
        textures.bind(gl);
        gl.ActiveTexture(GL_TEXTURE2);
        gl.BindTexture(GL_TEXTURE_2D, colour.id());
        gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer.id());
        gl.UseProgram(program);
        setDepthView(gl, program, image);
        setIntersectOptions(gl, program, look.intersect);
        const glm::mat4 frameNdcToWorld(glm::inverse(camera.worldToNdcMatrix()));
        const glm::vec3 toLight = glm::normalize(look.towardLight);
        gl.UniformMatrix4fv(gl.GetUniformLocation(program, "uFrameNdcToWorld"), 1, GL_FALSE,
                            glm::value_ptr(frameNdcToWorld));
        gl.Uniform2f(gl.GetUniformLocation(program, "uFrameSize"), static_cast<float>(w), static_cast<float>(h));
        gl.Uniform3f(gl.GetUniformLocation(program, "uBackground"), look.background.r, look.background.g,
                     look.background.b);
        gl.Uniform3f(gl.GetUniformLocation(program, "uTowardLight"), toLight.x, toLight.y, toLight.z);
        gl.Uniform1f(gl.GetUniformLocation(program, "uAmbient"), look.ambient);
        gl.Uniform1i(gl.GetUniformLocation(program, "uShadows"), look.shadows ? 1 : 0);
        gl.Uniform1i(gl.GetUniformLocation(program, "uColour"), 2);
        drawFullScreen(gl, context, w, h);
    }
};

ReliefRenderer::ReliefRenderer(Context& context, const codec::DepthImage& image, const Image& colour,
                               const ReliefLook& look) {
    codec::checkIntersectOptions(look.intersect);
    checkImage(colour, "ReliefRenderer");
    if (colour.width != image.width() || colour.height != image.height())
        throw Error(ErrorCode::InvalidArgument, std::string(kWhat) + ": colour " + std::to_string(colour.width) + "x" +
                                                    std::to_string(colour.height) + " differs from the depth image's " +
                                                    std::to_string(image.width()) + "x" +
                                                    std::to_string(image.height()));
    if (!(glm::length(look.towardLight) > 0.0f))
        throw Error(ErrorCode::InvalidArgument, std::string(kWhat) + ": the light has no direction");
    const GladGLContext& gl = makeCurrentGl(context);
    m_impl = std::make_unique<Impl>(context, gl, image, colour, look);
    checkGl(gl, kWhat);
}

ReliefRenderer::~ReliefRenderer() {
    if (m_impl) makeCurrentGl(m_impl->context);  // the GL objects die in their own context
}

void ReliefRenderer::draw(const Camera& camera, int width, int height) {
    m_impl->drawFrame(camera, width, height);
    makeCurrentGl(m_impl->context).Finish();
}

Image ReliefRenderer::render(const Camera& camera, int width, int height) {
    m_impl->drawFrame(camera, width, height);
    const GladGLContext& gl = makeCurrentGl(m_impl->context);
    Image frame = readRgbFrame(gl, width, height);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    checkGl(gl, kWhat);
    return frame;
}

}  // namespace conus::gl
