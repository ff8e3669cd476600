// What the GPU passes share (gpu_pass_pvt.h).
#include "gpu_pass_pvt.h"

#include <algorithm>

#include "context_pvt.h"
#include "conus/core/error.h"

namespace conus::renderers {
namespace {

std::string limitDescription(const Context& context, int limit) {
    std::string text = "the texture limit " + std::to_string(limit) + " (GL_MAX_TEXTURE_SIZE " +
                       std::to_string(context.maxTextureSize()) + " of " + context.renderer();
    if (limit < context.maxTextureSize()) text += std::string(", lowered by ") + kTextureLimitVariable;
    return text + ")";
}

}  // namespace

void checkTextureSize(const Context& context, int width, int height, const char* what, const char* role) {
    const int limit = context.textureLimit();
    if (width > limit || height > limit)
        throw Error(ErrorCode::LimitExceeded, std::string(what) + ": " + role + " " + std::to_string(width) + "x" +
                                                  std::to_string(height) + " exceeds " +
                                                  limitDescription(context, limit) + "; only the encoder's source is "
                                                  "tiled: use the CPU path");
}

GLenum internalFormat(int channels) {
    static constexpr GLenum kFormats[] = {GL_R32F, GL_RG32F, GL_RGB32F, GL_RGBA32F};
    return kFormats[channels - 1];
}
GLenum pixelFormat(int channels) {
    static constexpr GLenum kFormats[] = {GL_RED, GL_RG, GL_RGB, GL_RGBA};
    return kFormats[channels - 1];
}

void readBack(const GladGLContext& gl, Image& out, int first, int count) {
    gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
    const int channels = out.channelCount();
    if (first == 0 && count == channels) {
        gl.ReadPixels(0, 0, out.width, out.height, pixelFormat(count), GL_FLOAT, out.pixels.data());
        return;
    }
    const std::size_t pixels = static_cast<std::size_t>(out.width) * out.height;
    std::vector<float> buffer(pixels * count);
    gl.ReadPixels(0, 0, out.width, out.height, pixelFormat(count), GL_FLOAT, buffer.data());
    for (std::size_t i = 0; i < pixels; ++i)
        for (int c = 0; c < count; ++c) out.pixels[i * channels + first + c] = buffer[i * count + c];
}

Image readColourAndDepth(const GladGLContext& gl, int width, int height) {
    const std::size_t pixels = static_cast<std::size_t>(width) * height;
    std::vector<float> rgba(pixels * 4), z(pixels);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
    gl.ReadBuffer(GL_COLOR_ATTACHMENT0);
    gl.ReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, rgba.data());
    gl.ReadBuffer(GL_COLOR_ATTACHMENT1);
    gl.ReadPixels(0, 0, width, height, GL_RED, GL_FLOAT, z.data());
    gl.ReadBuffer(GL_COLOR_ATTACHMENT0);
    Image frame = makeImage(width, height, {"R", "G", "B", "A", "Z"});
    for (std::size_t p = 0; p < pixels; ++p) {
        std::copy_n(&rgba[p * 4], 4, &frame.pixels[p * 5]);
        frame.pixels[p * 5 + 4] = z[p];
    }
    return frame;
}

}  // namespace conus::renderers
