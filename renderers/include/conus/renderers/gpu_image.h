// GPU image encode and decode (paper section 3.2 and section 4), the GL counterparts of
// codec::encodeImage and codec::decodeImage, and meant to agree with them (the tests hold them to
// PSNR >= 45 dB for encode and >= 50 dB for decode).
//
// Encode rasterizes the mesh of distorted map nodes carrying undistorted texture coordinates, each
// map cell subdivided so the piecewise-linear mesh follows the bilinear cells to a small fraction
// of a pixel; the fragment shader averages bilinear taps over the pixel's footprint in the source
// (from the screen-space derivatives of the texture coordinates) on a pyramid level chosen like
// the CPU reference's, in a pyramid built on the GPU at the CPU's level sizes with exact area
// weights (GL's own mipmaps differ for odd sizes). Decode is one full-screen pass that evaluates
// Equation 1 per pixel from the map's nodes and samples the CoNUS image bilinearly (several taps
// where zoomed out).
//
// Shared rules: images are float with any number of channels, processed four per pass (32-bit
// float textures, an RGBA32F target); the options' threads and progress are ignored (the GPU runs
// the whole image at once); sizes are checked like the CPU paths (conus::Error InvalidArgument /
// LimitExceeded). The context is made current on the calling thread; a GL failure throws
// conus::Error(Unsupported), a GL out-of-memory LimitExceeded.
//
// Texture limit: the textures stay within the context's GL_MAX_TEXTURE_SIZE, or within the lower
// limit that the environment variable CONUS_GL_MAX_TEXTURE asks for (texels, read on every call,
// clamped to [64, GL_MAX_TEXTURE_SIZE]; not a positive whole number: InvalidArgument), which lets
// tests exercise tiling on drivers with a large limit. An encoder source wider or taller than the
// limit (or whose pyramid atlas would be) is tiled: it is cut into tiles whose core plus a margin of
// 6 texels on every pyramid level fits the limit; the pyramid's levels 1.. are built once for the
// whole image on the CPU (codec::areaDownsample, the reference's own filter, at its level sizes)
// and each tile uploads crops of them, so a crop's texels are the full pyramid's; each tile draws
// the mesh triangles that reach its core, and the shader keeps only the pixels whose interpolated
// undistorted centre lies in that core, so every CoNUS pixel is drawn once and reads what the
// untiled encoder would. Not tiled (they throw conus::Error(LimitExceeded) past the limit): the
// encoder's output, and the decoder's CoNUS image and output.
#pragma once

#include "conus/codec/image/decode.h"
#include "conus/codec/image/encode.h"
#include "conus/codec/map/sampling_map.h"
#include "conus/core/image.h"
#include "conus/renderers/backend.h"
#include "conus/renderers/context.h"

namespace conus::renderers {

// Where the time of one call went, in milliseconds; each phase ends with glFinish, so the phases
// add up to the call (minus CPU-side argument checks). Upload includes building the source pyramid
// and the mesh or map upload; readback includes the copy into the returned image.
struct GpuTimings {
    double uploadMs = 0, drawMs = 0, readbackMs = 0;
};

Image encodeImageGpu(Context& context, const Image& source, const codec::SamplingMap& map,
                             const codec::EncodeOptions& options, GpuTimings* timings = nullptr);

Image decodeImageGpu(Context& context, const Image& conus, const codec::SamplingMap& map,
                             const codec::DecodeOptions& options, GpuTimings* timings = nullptr);

// Encode and decode on a device: the GPU paths above, or codec's CPU reference.
Image encodeImage(const Device& device, const Image& source, const codec::SamplingMap& map,
                          const codec::EncodeOptions& options);
Image decodeImage(const Device& device, const Image& conus, const codec::SamplingMap& map,
                          const codec::DecodeOptions& options);

}  // namespace conus::renderers
