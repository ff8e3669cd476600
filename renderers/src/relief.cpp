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
#include "depth_pvt.h"
#include "embedded_shaders.h"
#include "frame_pvt.h"
#include "gl_objects_pvt.h"

namespace conus::renderers {
namespace {

constexpr const char* kWhat = "relief";
constexpr int kRayRowLength = 1024;  // rays per row of the ray textures

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
    const DepthTextures textures(context, gl, image, kWhat);
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
    setDepthView(gl, program, image, textures);
    setIntersectOptions(gl, program, options);
    gl.Uniform1f(gl.GetUniformLocation(program, "uTMax"), static_cast<float>(std::min(options.tMax, 1e30)));
    gl.Uniform1i(gl.GetUniformLocation(program, "uOrigins"), 2);
    gl.Uniform1i(gl.GetUniformLocation(program, "uDirections"), 3);
    drawFullscreen(context, gl, width, height, kWhat);

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
        hit.hidden = out[3][i * 4 + 2] > 0.5f;
        hits[i] = hit;
    }
    return hits;
}

namespace {

struct ReliefScene : DepthFrameRenderer::Scene {
    const codec::DepthImage image;
    ReliefLook look;
    DepthTextures textures;
    GlHandle colour;

    ReliefScene(Context& c, const GladGLContext& gl, const codec::DepthImage& i, const Image& rgb, const ReliefLook& l)
        : Scene(c, kWhat, {"R", "G", "B"}), image(i), look(l), textures(c, gl, i, kWhat) {
        std::vector<float> pixels(static_cast<std::size_t>(rgb.width) * rgb.height * 3, 0.7f);
        int channels[3];
        for (int k = 0; k < 3; ++k) channels[k] = rgb.channelIndex(std::string(1, "RGB"[k]));
        for (std::size_t p = 0; p < pixels.size() / 3; ++p)
            for (int k = 0; k < 3; ++k)
                if (channels[k] >= 0) pixels[p * 3 + k] = rgb.pixels[p * rgb.channels.size() + channels[k]];
        colour = floatTexture(gl, GL_TEXTURE2, rgb.width, rgb.height, 3, pixels.data(), true);
    }

    void drawFrame(const Camera& camera, int w, int h) override {
        checkFrame(context, w, h, kWhat);
        const GladGLContext& gl = makeCurrentGl(context);
        const GLuint program =
            cachedProgram(context, "relief", shaders::kShaderFullscreenVert, shaders::kShaderReliefFrag);
        target.ensure(gl, w, h, GL_TEXTURE4, kWhat);
        textures.bind(gl);
        gl.ActiveTexture(GL_TEXTURE2);
        gl.BindTexture(GL_TEXTURE_2D, colour.id());
        gl.UseProgram(program);
        setDepthView(gl, program, image, textures);
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
        drawFullscreen(context, gl, w, h, kWhat);
    }
};

std::unique_ptr<DepthFrameRenderer::Scene> reliefScene(Context& context, const codec::DepthImage& image,
                                                       const Image& colour, const ReliefLook& look) {
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
    auto scene = std::make_unique<ReliefScene>(context, gl, image, colour, look);
    checkGl(gl, kWhat);
    return scene;
}

}  // namespace

ReliefRenderer::ReliefRenderer(Context& context, const codec::DepthImage& image, const Image& colour,
                               const ReliefLook& look)
    : DepthFrameRenderer(reliefScene(context, image, colour, look)) {}

}  // namespace conus::renderers
