// GPU image encode and decode (paper section 3.2 and section 4), the GL counterparts of
// codec::encodeImage and codec::decodeImage, and meant to agree with them (the tests hold them to
// PSNR >= 45 dB for encode, linear or as 8-bit sRGB codes, and >= 50 dB for decode).
//
// Encode rasterizes the mesh of distorted map nodes carrying undistorted texture coordinates and
// each vertex's footprint, each map cell subdivided so the piecewise-linear mesh follows the
// bilinear cells to a small fraction of a pixel; the fragment shader filters the source over the
// pixel's footprint by the CPU kernel's rule (GpuEncodeKernel below: the anisotropic kernel on GL's
// mipmaps, or the EWA filter on a pyramid built on the GPU at the CPU's level sizes with exact area
// weights). Decode is one full-screen pass that evaluates
// Equation 1 per pixel from the map's nodes and samples the CoNUS image bilinearly (several taps
// where zoomed out).
//
// Shared rules: images are float with any number of channels, processed four per pass (float
// textures, or the mipmapped encoder's 8-bit sRGB or half ones; an RGBA32F target); progress is
// ignored (the GPU runs the whole image at once), threads convert the mipmapped encoder's uploads
// and read-backs; sizes are checked like the CPU paths (conus::Error InvalidArgument /
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

#include <string>

#include "conus/codec/image/decode.h"
#include "conus/codec/image/encode.h"
#include "conus/codec/map/sampling_map.h"
#include "conus/core/image.h"
#include "conus/renderers/backend.h"
#include "conus/renderers/context.h"

namespace conus::renderers {

// Where the time of one call went, in milliseconds; each phase ends with glFinish, so the phases
// add up to the call (minus CPU-side argument checks). Upload includes building the source pyramid
// and the mesh or map upload; readback includes the copy into the returned image. `path` says how
// an encode ran: "mipmapped (srgb8, anisotropy 4)", "ewa", "ewa, tiled".
struct GpuTimings {
    double uploadMs = 0, drawMs = 0, readbackMs = 0;
    std::string path;
};

// The GL encoders.
//  - Mipmapped: the twin of the CPU's anisotropic kernel (codec::EncodeFilter::Anisotropic) on GL's
//    own mipmaps (glGenerateMipmap): each pass of up to four channels is converted by threads into
//    a pixel buffer object as 8-bit sRGB (GL_SRGB8_ALPHA8, which the sampler linearises) or half
//    floats (GL_RGBA16F), uploaded, mipmapped on the GPU, filtered in one draw (trilinear taps along
//    the footprint's major axis on the level its minor axis picks, or the sampler's anisotropic
//    filter for a few taps at once) and read back through a pixel buffer object. GL's mip levels
//    halve with rounding down where the CPU's round up: odd sizes differ slightly (within the
//    tests' 8-bit sRGB bound). Sources over the texture limit take the EWA encoder (tiled).
//  - Ewa: the EWA filter's twin (codec::EncodeFilter::Ewa) on a pyramid built on the GPU at the
//    CPU's level sizes, from float textures; tiled past the texture limit (above).
// Auto takes the kernel the CPU takes for the same options: Mipmapped for the anisotropic filter,
// Ewa for the EWA filter and under a uniform map (encode.h says why).
enum class GpuEncodeKernel { Auto, Mipmapped, Ewa };
// How the mipmapped encoder uploads a pass: Auto as 8-bit sRGB where the pass is R, G, B (and A)
// and every value is exactly an 8-bit code's (an opaque 8-bit picture, read as linear light), else
// half floats; Srgb8 8-bit sRGB for every R, G, B (, A) pass (other values rounded to the nearest
// code, clamped to [0, 1]; other passes half floats); Half always half floats (finite values above
// 65504 become infinite).
enum class GpuUpload { Auto, Srgb8, Half };
struct GpuEncodeOptions {
    GpuEncodeKernel kernel = GpuEncodeKernel::Auto;
    GpuUpload upload = GpuUpload::Auto;
    // Taps along the major axis that one sample of the sampler's anisotropic filter stands for
    // (GL 4.6's or EXT_texture_filter_anisotropic's GL_TEXTURE_MAX_ANISOTROPY; at most the driver's
    // limit; 1 where it has none). 1 (the default): a bilinear sample per tap, the CPU kernel's own
    // taps. Within the footprint of one sample the driver filters as it likes: llvmpipe's
    // elliptical Gaussian lands 31-35 dB (8-bit sRGB) from the CPU kernel and costs it more, not less
    // (bench/notes/2026-12-07-gl-encode.md), so it is asked for by name until hardware shows it
    // closer and faster.
    int anisotropy = 1;
};

Image encodeImageGpu(Context& context, const Image& source, const codec::SamplingMap& map,
                     const codec::EncodeOptions& options, GpuTimings* timings = nullptr,
                     const GpuEncodeOptions& gpu = {});

Image decodeImageGpu(Context& context, const Image& conus, const codec::SamplingMap& map,
                             const codec::DecodeOptions& options, GpuTimings* timings = nullptr);

// Whether GL encodes faster than the CPU here, measured once per process (later calls return the
// first answer, whatever the context): a 1024x1024 RGB picture encoded to 256x256 through a focus
// map with the default options, on the context (the mipmapped kernel, after a first call that
// compiles its shader) and on the CPU (every core), the better of two runs each: about 10 s on
// llvmpipe (2 loaded cores), where GL took 2.6 s an encode against the CPU's 0.16 s.
struct EncodeSpeed {
    double glMs = 0, cpuMs = 0;
    bool glFaster() const { return glMs < cpuMs; }
};
EncodeSpeed measureEncodeSpeed(Context& context);
// The probe Device::choose takes for CpuPath::Measured encodes: measureEncodeSpeed's answer on a
// hardware GPU; the CPU, unmeasured, on a software rasterizer (prefersCpu).
SpeedProbe encodeSpeedProbe();

// Encode and decode on a device: the GPU paths above, or codec's CPU reference.
Image encodeImage(const Device& device, const Image& source, const codec::SamplingMap& map,
                          const codec::EncodeOptions& options);
Image decodeImage(const Device& device, const Image& conus, const codec::SamplingMap& map,
                          const codec::DecodeOptions& options);

}  // namespace conus::renderers
