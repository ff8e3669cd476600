// Private: the mipmapped GL encoder's transfers (gpu_upload.cpp). A pass of up to four channels
// is converted by threads straight into a mapped pixel buffer object in a layout the driver takes
// as it is (RGBA: 8-bit sRGB or half floats, never float RGB, which drivers convert on one
// thread), and read back through a pixel buffer object the same way.
#pragma once

#include <glad/gl.h>

#include "conus/core/image.h"
#include "conus/renderers/gpu_image.h"

namespace conus::renderers {

// Allocates the texture bound to GL_TEXTURE_2D on the active unit (`levels` mip levels) and fills
// level 0 with channels [first, first + count) of `image` as RGBA (missing channels 0, alpha 1 for
// an R,G,B pass). `upload` says how (gpu_image.h: GpuUpload); returns what was used: Srgb8 or Half.
// Auto converts to 8-bit sRGB while every value is exactly a code's and starts over in half floats
// at the first that is not.
GpuUpload uploadPass(const GladGLContext& gl, const Image& image, int first, int count, GpuUpload upload, int levels,
                     int threads);

// Reads the bound framebuffer (RGBA float, out's size) into channels [first, first + count) of out.
void readBackPass(const GladGLContext& gl, Image& out, int first, int count, int threads);

}  // namespace conus::renderers
