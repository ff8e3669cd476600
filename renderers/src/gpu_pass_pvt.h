// Private: what the GPU image encoder and decoder share: passes of up to four channels, their
// float texture formats, the texture-size check and the read-back (gpu_pass.cpp); and the
// colour + depth read-back of the mesh and volume passes.
//
// Images travel to and from GL in memory order, top row first, so texture row 0 and window row 0
// are the image's top row: GL's y axis is the spec's v (downward) and no flip is needed anywhere;
// the only place one would appear, NDC, is written y = 2v - 1 (encode.vert.glsl).
#pragma once

#include <string>
#include <vector>

#include <glad/gl.h>

#include "conus/core/image.h"
#include "conus/renderers/context.h"

namespace conus::renderers {

constexpr int kChannelsPerPass = 4;

// Throws LimitExceeded, naming `what` and `role`, when width x height exceeds the context's
// texture limit (only the encoder's source is tiled).
void checkTextureSize(const Context& context, int width, int height, const char* what, const char* role);

// The float texture format of 1..4 channels (R32F .. RGBA32F), and its pixel format.
GLenum internalFormat(int channels);
GLenum pixelFormat(int channels);

// Channels [first, first + count) of an image, interleaved; the image's own array when it is all.
// Uploads keep the image's channel count (R32F .. RGBA32F): measured on llvmpipe, padding RGB to
// RGBA on the CPU made the upload slower, not faster.
class PassPixels {
public:
    PassPixels(const Image& image, int first, int count) {
        const int channels = image.channelCount();
        if (first == 0 && count == channels) {
            m_data = image.pixels.data();
            return;
        }
        const std::size_t pixels = static_cast<std::size_t>(image.width) * image.height;
        m_copy.resize(pixels * count);
        for (std::size_t i = 0; i < pixels; ++i)
            for (int c = 0; c < count; ++c) m_copy[i * count + c] = image.pixels[i * channels + first + c];
        m_data = m_copy.data();
    }
    const float* data() const { return m_data; }

private:
    std::vector<float> m_copy;
    const float* m_data = nullptr;
};

// Reads the bound framebuffer's first `count` channels into channels [first, first + count).
void readBack(const GladGLContext& gl, Image& out, int first, int count);

// The bound framebuffer's colour (attachment 0, RGBA) and camera depth (attachment 1, one channel)
// as one width x height image of R, G, B, A, Z: what the mesh and volume passes draw. Leaves
// attachment 0 the read buffer.
Image readColourAndDepth(const GladGLContext& gl, int width, int height);

}  // namespace conus::renderers
