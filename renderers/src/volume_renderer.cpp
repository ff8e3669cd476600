// GPU CoNUS volume ray casting: one full-screen pass into an RGBA32F + R32F framebuffer (colour
// and Z), read back into an R, G, B, A, Z image. volume_renderer.h says why the undistorted
// positions come as a per-pixel table rather than from a rasterized sampling mesh.
#include "conus/renderers/volume_renderer.h"

#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include <glm/gtc/type_ptr.hpp>

#include "conus/codec/depth/glsl_interface.h"
#include "context_pvt.h"
#include "embedded_shaders.h"
#include "gl_objects_pvt.h"
#include "gpu_pass_pvt.h"

namespace conus::renderers {
namespace {

constexpr const char* kWhat = "renderVolumeGpu";

void setFilter(const GladGLContext& gl, GLenum target, GLint filter) {
    gl.TexParameteri(target, GL_TEXTURE_MIN_FILTER, filter);
    gl.TexParameteri(target, GL_TEXTURE_MAG_FILTER, filter);
    gl.TexParameteri(target, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    gl.TexParameteri(target, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    gl.TexParameteri(target, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
}

}  // namespace

struct VolumeRendererGpu::Impl {
    Context& context;
    Volume volume;  // sizes, spacing and the value range; the samples live in the 3-D texture
    glm::vec2 fullRange{0.0f, 1.0f};
    GlHandle volumeTexture, transferTexture;
};

VolumeRendererGpu::VolumeRendererGpu(Context& context, const Volume& volume, const codec::TransferFunction& tf) {
    checkVolume(volume, kWhat);
    const GladGLContext& gl = makeCurrentGl(context);
    GLint max3d = 0;
    gl.GetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &max3d);
    if (volume.width > max3d || volume.height > max3d || volume.depth > max3d)
        throw Error(ErrorCode::LimitExceeded, std::string(kWhat) + ": volume " + std::to_string(volume.width) + "x" +
                                                  std::to_string(volume.height) + "x" + std::to_string(volume.depth) +
                                                  " exceeds GL_MAX_3D_TEXTURE_SIZE " + std::to_string(max3d));
    m_impl = std::make_unique<Impl>(Impl{context, Volume{}, codec::valueRange(volume), makeTexture(gl), makeTexture(gl)});
    m_impl->volume.width = volume.width;
    m_impl->volume.height = volume.height;
    m_impl->volume.depth = volume.depth;
    m_impl->volume.spacing = volume.spacing;
    gl.ActiveTexture(GL_TEXTURE0);
    gl.BindTexture(GL_TEXTURE_3D, m_impl->volumeTexture.id());
    gl.TexStorage3D(GL_TEXTURE_3D, 1, GL_R32F, volume.width, volume.height, volume.depth);
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
    gl.TexSubImage3D(GL_TEXTURE_3D, 0, 0, 0, 0, volume.width, volume.height, volume.depth, GL_RED, GL_FLOAT,
                     volume.values.data());
    setFilter(gl, GL_TEXTURE_3D, GL_LINEAR);
    checkGl(gl, kWhat);
    setTransferFunction(tf);
}

VolumeRendererGpu::~VolumeRendererGpu() {
    if (m_impl) makeCurrentGl(m_impl->context);  // the textures are deleted in this context
}

void VolumeRendererGpu::setTransferFunction(const codec::TransferFunction& tf) {
    const GladGLContext& gl = makeCurrentGl(m_impl->context);
    m_impl->transferTexture = makeTexture(gl);
    gl.ActiveTexture(GL_TEXTURE1);
    gl.BindTexture(GL_TEXTURE_1D, m_impl->transferTexture.id());
    gl.TexStorage1D(GL_TEXTURE_1D, 1, GL_RGBA32F, codec::kTransferTableSize);
    gl.TexSubImage1D(GL_TEXTURE_1D, 0, 0, codec::kTransferTableSize, GL_RGBA, GL_FLOAT, glm::value_ptr(tf.table()[0]));
    setFilter(gl, GL_TEXTURE_1D, GL_LINEAR);
    checkGl(gl, kWhat);
}

Image VolumeRendererGpu::render(const Fpc& fpc, int width, int height, const codec::VolumeRenderOptions& options,
                                GpuTimings* timings) {
    Impl& impl = *m_impl;
    codec::checkVolumeRenderOptions(width, height, options);  // the volume was checked on upload
    codec::checkRaySteps(impl.volume, options.stepVoxels);
    Context& context = impl.context;
    if (width > context.textureLimit() || height > context.textureLimit())
        throw Error(ErrorCode::LimitExceeded, std::string(kWhat) + ": output " + std::to_string(width) + "x" +
                                                  std::to_string(height) + " exceeds the texture limit " +
                                                  std::to_string(context.textureLimit()));
    GpuTimings t;
    Clock::time_point start = Clock::now();
    const GladGLContext& gl = makeCurrentGl(context);
    const GLuint program = cachedProgram(context, "volume", shaders::kShaderFullscreenVert, shaders::kShaderVolumeFrag);

    // The exact inverse per pixel (see the header), computed on all cores.
    GlHandle undistorted;
    const Distortion* distortion = fpc.distortion();
    if (distortion) {
        const std::vector<float> table = codec::undistortedTable(*distortion, width, height, options.threads);
        undistorted = makeTexture(gl);
        gl.ActiveTexture(GL_TEXTURE2);
        gl.BindTexture(GL_TEXTURE_2D, undistorted.id());
        gl.TexStorage2D(GL_TEXTURE_2D, 1, GL_RG32F, width, height);
        gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
        gl.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width, height, GL_RG, GL_FLOAT, table.data());
        setFilter(gl, GL_TEXTURE_2D, GL_NEAREST);
    }

    // Colour (RGBA32F) and Z (R32F) targets.
    GlHandle colour = makeTexture(gl), depth = makeTexture(gl), framebuffer = makeFramebuffer(gl);
    gl.BindTexture(GL_TEXTURE_2D, colour.id());
    gl.TexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, width, height);
    gl.BindTexture(GL_TEXTURE_2D, depth.id());
    gl.TexStorage2D(GL_TEXTURE_2D, 1, GL_R32F, width, height);
    gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer.id());
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, colour.id(), 0);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, depth.id(), 0);
    const GLenum buffers[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    gl.DrawBuffers(2, buffers);
    checkGl(gl, kWhat);
    if (gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        throw Error(ErrorCode::Unsupported, std::string(kWhat) + ": the driver cannot render to a " +
                                                std::to_string(width) + "x" + std::to_string(height) +
                                                " RGBA32F + R32F framebuffer");
    gl.Finish();
    t.uploadMs += millisecondsSince(start);

    const Camera& camera = fpc.camera();
    const glm::vec2 range = options.rangeLo < options.rangeHi ? glm::vec2(options.rangeLo, options.rangeHi) : impl.fullRange;
    const float rangeHi = range.y > range.x ? range.y : range.x + 1.0f;  // codec::renderRange's rule
    const glm::mat4 ndcToWorld(glm::inverse(camera.worldToNdcMatrix()));
    const glm::vec3 forward(camera.forward());
    const glm::vec3 extent(impl.volume.extent()), spacing(impl.volume.spacing);
    const double step = options.stepVoxels * std::min({impl.volume.spacing.x, impl.volume.spacing.y, impl.volume.spacing.z});

    gl.Viewport(0, 0, width, height);
    gl.Disable(GL_DEPTH_TEST);
    gl.Disable(GL_BLEND);
    gl.UseProgram(program);
    gl.ActiveTexture(GL_TEXTURE0);
    gl.BindTexture(GL_TEXTURE_3D, impl.volumeTexture.id());
    gl.ActiveTexture(GL_TEXTURE1);
    gl.BindTexture(GL_TEXTURE_1D, impl.transferTexture.id());
    if (undistorted) {
        gl.ActiveTexture(GL_TEXTURE2);
        gl.BindTexture(GL_TEXTURE_2D, undistorted.id());
    }
    const auto at = [&](const char* name) { return gl.GetUniformLocation(program, name); };
    gl.Uniform1i(at("uVolume"), 0);
    gl.Uniform1i(at("uTransfer"), 1);
    gl.Uniform1i(at("uUndistorted"), 2);
    gl.Uniform1i(at("uIdentity"), distortion ? 0 : 1);
    gl.Uniform2f(at("uOutputSize"), float(width), float(height));
    gl.UniformMatrix4fv(at("uNdcToWorld"), 1, GL_FALSE, glm::value_ptr(ndcToWorld));
    gl.Uniform3f(at("uForward"), forward.x, forward.y, forward.z);
    gl.Uniform1f(at("uNear"), float(camera.near()));
    gl.Uniform1f(at("uFar"), float(camera.far()));
    gl.Uniform3f(at("uExtent"), extent.x, extent.y, extent.z);
    gl.Uniform3f(at("uSpacing"), spacing.x, spacing.y, spacing.z);
    gl.Uniform1f(at("uStep"), float(step));
    gl.Uniform1f(at("uStepVoxels"), float(options.stepVoxels));
    gl.Uniform1i(at("uJitter"), options.jitter ? 1 : 0);
    gl.Uniform1f(at("uRangeLo"), range.x);
    gl.Uniform1f(at("uRangeScale"), 1.0f / (rangeHi - range.x));
    gl.Uniform1f(at("uDepthOpacity"), options.depthOpacity);
    gl.BindVertexArray(context.impl().emptyVertexArray);
    gl.DrawArrays(GL_TRIANGLES, 0, 3);
    gl.BindVertexArray(0);
    checkGl(gl, kWhat);
    gl.Finish();
    t.drawMs += millisecondsSince(start);

    // GL's row 0 is the image's top row (the pass writes pixel (x, y) at window (x, y)).
    Image out = readColourAndDepth(gl, width, height);  // codec::kVolumeChannels
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    checkGl(gl, kWhat);
    t.readbackMs += millisecondsSince(start);
    if (timings) *timings = t;
    if (options.progress) options.progress(1.0);
    return out;
}

Image renderVolume(const Device& device, const Volume& volume, const codec::TransferFunction& tf, const Fpc& fpc,
                   int width, int height, const codec::VolumeRenderOptions& options) {
    return device.run([&] { return codec::renderVolumeReference(volume, tf, fpc, width, height, options); },
                      [&](Context& context) {
                          VolumeRendererGpu renderer(context, volume, tf);
                          return renderer.render(fpc, width, height, options);
                      });
}

}  // namespace conus::renderers
