// Private: what every renderer that draws a frame of its own (terrain, mesh, relief) checks before
// it allocates a target, and how it reads an RGB frame back.
#pragma once

#include <string>
#include <vector>

#include <glad/gl.h>

#include "conus/core/error.h"
#include "conus/core/image.h"
#include "conus/renderers/context.h"

namespace conus::renderers {

constexpr int kMaxFrameSide = 16384;

// Throws conus::Error, naming `what`: InvalidArgument outside [1, kMaxFrameSide] a side,
// LimitExceeded beyond the context's GL_MAX_TEXTURE_SIZE.
inline void checkFrame(const Context& context, int width, int height, const char* what) {
    const std::string frame = std::string(what) + ": frame " + std::to_string(width) + "x" + std::to_string(height);
    if (width < 1 || height < 1 || width > kMaxFrameSide || height > kMaxFrameSide)
        throw Error(ErrorCode::InvalidArgument, frame + " is outside [1, " + std::to_string(kMaxFrameSide) + "] per side");
    if (width > context.maxTextureSize() || height > context.maxTextureSize())
        throw Error(ErrorCode::LimitExceeded,
                    frame + " exceeds GL_MAX_TEXTURE_SIZE " + std::to_string(context.maxTextureSize()));
}

// The bound read framebuffer's colour as a float image of three channels (GL's R, G, B) or four
// (R, G, B, A) named `channels`, rows in GL's order.
inline Image readFrame(const GladGLContext& gl, int width, int height, const std::vector<std::string>& channels) {
    Image frame = makeImage(width, height, channels);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
    gl.ReadPixels(0, 0, width, height, channels.size() == 4 ? GL_RGBA : GL_RGB, GL_FLOAT, frame.pixels.data());
    return frame;
}

inline Image readRgbFrame(const GladGLContext& gl, int width, int height) {
    return readFrame(gl, width, height, {"R", "G", "B"});
}

}  // namespace conus::renderers
