// The mipmapped GL encoder (gpu_image.h): the anisotropic kernel's twin on GL's own mipmaps
// (encode_mip.frag.glsl), and the one-time measurement that lets `auto` choose it.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <mutex>
#include <optional>
#include <string>

#include "context_pvt.h"
#include "conus/codec/builders/foci.h"
#include "embedded_shaders.h"
#include "gpu_encode_pvt.h"
#include "gpu_pass_pvt.h"
#include "gpu_upload_pvt.h"

namespace conus::renderers {
namespace {

constexpr const char* kWhat = "encodeImageGpu";
// GL 4.6 core and ARB/EXT_texture_filter_anisotropic share these values (the loader is GL 4.5).
constexpr GLenum kTextureMaxAnisotropy = 0x84FE;
constexpr GLenum kMaxTextureMaxAnisotropy = 0x84FF;

// The driver's largest anisotropy, 1 where it has no anisotropic filter.
float maxAnisotropy(const GladGLContext& gl) {
    GLint major = 0, minor = 0, count = 0;
    gl.GetIntegerv(GL_MAJOR_VERSION, &major);
    gl.GetIntegerv(GL_MINOR_VERSION, &minor);
    bool has = major > 4 || (major == 4 && minor >= 6);
    gl.GetIntegerv(GL_NUM_EXTENSIONS, &count);
    for (GLint i = 0; i < count && !has; ++i) {
        const auto* name = reinterpret_cast<const char*>(gl.GetStringi(GL_EXTENSIONS, static_cast<GLuint>(i)));
        has = name && (std::strcmp(name, "GL_ARB_texture_filter_anisotropic") == 0 ||
                       std::strcmp(name, "GL_EXT_texture_filter_anisotropic") == 0);
    }
    if (!has) return 1.0f;
    GLfloat limit = 1.0f;
    gl.GetFloatv(kMaxTextureMaxAnisotropy, &limit);
    return std::max(1.0f, limit);
}

// Taps per sample along the major axis (gpu_image.h: GpuEncodeOptions::anisotropy).
int segmentTaps(const GladGLContext& gl, int asked) {
    if (asked <= 1) return 1;
    return std::clamp(asked, 1, static_cast<int>(maxAnisotropy(gl)));
}

int mipLevels(int width, int height) {
    int levels = 1;
    for (int side = std::max(width, height); side > 1; side /= 2) ++levels;
    return levels;
}

}  // namespace

void encodeMipmapped(Context& context, const Image& source, const codec::SamplingMap& map, const codec::EncodeOptions& options,
                     const GpuEncodeOptions& gpu, Image& out, GpuTimings& t, Clock::time_point& start) {
    const GladGLContext& gl = makeCurrentGl(context);
    const Mesh mesh = buildMesh(map, out.width, out.height);
    GlHandle vertexArray = makeVertexArray(gl), vertexBuffer = makeBuffer(gl), indexBuffer = makeBuffer(gl);
    uploadMesh(gl, mesh, vertexArray.id(), vertexBuffer.id(), indexBuffer.id());
    FloatTarget target(gl, out.width, out.height, kWhat);
    const GLuint program = cachedProgram(context, "encode-mip", shaders::kShaderEncodeVert, shaders::kShaderEncodeMipFrag);
    const int segment = segmentTaps(gl, gpu.anisotropy);
    const int levels = mipLevels(source.width, source.height);
    std::string uploads;
    for (int first = 0; first < source.channelCount(); first += kChannelsPerPass) {
        const int count = std::min(kChannelsPerPass, source.channelCount() - first);
        GlHandle texture = makeTexture(gl);
        gl.ActiveTexture(GL_TEXTURE0);
        gl.BindTexture(GL_TEXTURE_2D, texture.id());
        const GpuUpload used = uploadPass(gl, source, first, count, gpu.upload, levels, options.threads);
        uploads += std::string(uploads.empty() ? "" : "+") + (used == GpuUpload::Srgb8 ? "srgb8" : "half");
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        if (segment > 1) gl.TexParameterf(GL_TEXTURE_2D, kTextureMaxAnisotropy, static_cast<float>(segment));
        gl.GenerateMipmap(GL_TEXTURE_2D);
        checkGl(gl, kWhat);
        gl.Finish();
        t.uploadMs += millisecondsSince(start);

        gl.BindFramebuffer(GL_FRAMEBUFFER, target.framebuffer.id());
        gl.Viewport(0, 0, out.width, out.height);
        gl.UseProgram(program);
        gl.Uniform1i(gl.GetUniformLocation(program, "uSource"), 0);
        gl.Uniform1f(gl.GetUniformLocation(program, "uUniform"),
                     static_cast<float>(codec::uniformSpacing(source.width, source.height, out.width, out.height)));
        gl.Uniform1i(gl.GetUniformLocation(program, "uSegment"), segment);
        gl.BindVertexArray(vertexArray.id());
        drawMeshTimed(gl, mesh, t, start);

        readBackPass(gl, out, first, count, options.threads);
        checkGl(gl, kWhat);
        t.readbackMs += millisecondsSince(start);
    }
    gl.BindVertexArray(0);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    t.path = "mipmapped (" + uploads + ", anisotropy " + std::to_string(segment) + ")";
}

EncodeSpeed measureEncodeSpeed(Context& context) {
    static std::mutex mutex;
    static std::optional<EncodeSpeed> measured;
    const std::lock_guard lock(mutex);
    if (measured) return *measured;
    // A photograph's stand-in: smooth gradients and fine detail in each channel, 8-bit sRGB values.
    constexpr int kSide = 1024, kOut = 256;
    Image source = makeImage(kSide, kSide, {"R", "G", "B"});
    for (int y = 0; y < kSide; ++y)
        for (int x = 0; x < kSide; ++x)
            for (int c = 0; c < 3; ++c) {
                const double v = 0.5 + 0.25 * std::sin(0.013 * x * (c + 1) + 0.007 * y) + 0.2 * std::sin(0.9 * x * y / kSide);
                const double code = std::round(std::clamp(v, 0.0, 1.0) * 255.0) / 255.0;
                source.at(x, y, c) = static_cast<float>(code <= 0.04045 ? code / 12.92 : std::pow((code + 0.055) / 1.055, 2.4));
            }
    const std::array<codec::Focus, 1> foci{codec::Focus{0.4, 0.45, 0.12, 4.0}};
    const codec::SamplingMap map = codec::buildFociMap(foci);
    codec::EncodeOptions options;
    options.width = options.height = kOut;
    const auto best = [](auto&& run) {
        double ms = 1e300;
        for (int i = 0; i < 2; ++i) {
            Clock::time_point start = Clock::now();
            run();
            ms = std::min(ms, millisecondsSince(start));
        }
        return ms;
    };
    encodeImageGpu(context, source, map, options);  // compiles the shader
    EncodeSpeed speed;
    speed.glMs = best([&] { encodeImageGpu(context, source, map, options); });
    speed.cpuMs = best([&] { codec::encodeImage(source, map, options); });
    measured = speed;
    return speed;
}

SpeedProbe encodeSpeedProbe() {
    // A software rasterizer is not measured: on llvmpipe (2 loaded cores) the probe's GL encode took
    // 2.6 s against the CPU's 0.16 s, and measuring costs ~10 s (bench/notes/2026-12-07-gl-encode.md).
    return {[](Context& context) { return !prefersCpu(context) && measureEncodeSpeed(context).glFaster(); }, false};
}

}  // namespace conus::renderers
