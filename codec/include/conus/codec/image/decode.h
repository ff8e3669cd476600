// The CPU decoder: reconstructs a conventional frame from a CoNUS image. A view is a
// rectangle of the undistorted image plane rendered at width x height; each output pixel at (u,v)
// takes the CoNUS image at SM(u,v) (Equation 1), bilinearly. Where the output is coarser than the
// CoNUS image there (zoomed out), several taps over the pixel's footprint are averaged, or one
// trilinear tap is taken from the image's pyramid (pyramid.h). Output pixels whose centre lies
// outside the image show the background (0 in every channel). The GPU decoder (renderers/) gives
// the same frames and is tested against this one.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "conus/codec/image/pyramid.h"
#include "conus/codec/map/sampling_map.h"
#include "conus/core/error.h"
#include "conus/core/image.h"

namespace conus::codec {

// The decoder's footprint rule, shared with its GLSL twins (renderers inject these values): an
// output pixel whose footprint in the CoNUS image is at most kDecodeMultiTap pixels long on both
// axes takes one bilinear tap; a longer axis takes ceil(length) taps, at most kDecodeMaxTaps.
inline constexpr double kDecodeMultiTap = 1.5;
inline constexpr int kDecodeMaxTaps = 8;

struct View {
    double u0 = 0, v0 = 0, u1 = 1, v1 = 1;  // undistorted rectangle; may extend past [0,1]^2 (background there)
};

// Refuses (InvalidArgument) a view that is empty or inverted (it needs u0 < u1 and v0 < v1), not
// finite, absurdly far from the image, or wholly outside it (a view partly outside shows the
// background there); `shown` is the view as the caller wrote it.
void checkView(const View& view, const std::string& shown);

// Whether some output pixel of `view` decoded at width x height has a footprint in `conus` longer
// than the pyramid decode's one bilinear tap (2^kDecodePyramidBias CoNUS pixels): there a pyramid
// changes the decode (and stops its aliasing); elsewhere the decode is the same with or without
// one, so a caller may skip building it. Reads the map's cells the view covers.
bool viewZoomsOut(const Image& conus, const SamplingMap& map, const View& view, int width, int height);

struct DecodeOptions {
    View view;
    int width = 0, height = 0;  // output size
    int threads = 0;
    ProgressFn progress;
    // Zoomed-out pixels: nullptr averages up to kDecodeMaxTaps^2 bilinear taps over the pixel's
    // footprint; a pyramid of the CoNUS image (buildPyramid) takes one trilinear tap instead, at
    // pyramidLevel of the footprint's longer edge (no aliasing along it; blurrier across a long,
    // thin footprint than the taps). Magnified pixels take the same bilinear tap either way.
    const ImagePyramid* pyramid = nullptr;
};

// Throws conus::Error(LimitExceeded) when decoding `conus` (only its size and channels are read)
// to a width x height frame would hold more than `maxBytes` of pixels, the CoNUS image's and the
// frame's together, as float (limits.h: kMaxDecodeBytes), plus a third of the image again for its
// pyramid when `withPyramid`, plus `extraBytes` the caller holds beside them (a picture writer's
// copies of the frame). decodeImage checks this before it allocates; other decoders (the GPU
// one) and `conus decode` (before it builds the pyramid) call it too.
void checkDecodeMemory(const Image& conus, int width, int height, std::int64_t maxBytes = kMaxDecodeBytes,
                       bool withPyramid = false, std::int64_t extraBytes = 0);

Image decodeImage(const Image& conus, const SamplingMap& map, const DecodeOptions& options);

// The plain baseline: the same view of a uniform image by bilinear resampling.
Image resizeBilinear(const Image& image, const View& view, int width, int height, int threads = 0);

}  // namespace conus::codec
