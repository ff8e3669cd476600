// What the GPU image encoder and decoder share (gpu_pass_pvt.h).
#include "gpu_pass_pvt.h"

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

}  // namespace conus::renderers
