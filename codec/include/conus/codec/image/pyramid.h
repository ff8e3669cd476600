// The CoNUS image's mip chain for zoomed-out views, and the level of detail a footprint takes on
// it. The CPU decoder (decode.h), the GPU decoder and the viewer share the chain and the rule; the
// GLSL twin of pyramidLevel is `pyramidLevel` in renderers/shaders/equation1.inc.glsl.
#pragma once

#include <vector>

#include "conus/core/image.h"

namespace conus::codec {

// A mip chain of a CoNUS image for zoomed-out views: level k >= 1 is the exact area downsample
// of level k-1 to half its size (rounded down, at least 1 pixel), down to 1x1. Level 0 is the
// image itself and is not stored: levels[0] is level 1. Built once per image (a viewer keeps it
// for every frame); GPU decoders upload the same levels as the texture's mip chain.
struct ImagePyramid {
    std::vector<Image> levels;
};
ImagePyramid buildPyramid(const Image& conus, int threads = 0);
// Throws conus::Error(InvalidArgument) unless `pyramid` is buildPyramid's for an image of conus's
// size and channels (decoders call it before they use one).
void checkPyramid(const Image& conus, const ImagePyramid& pyramid);

// The pyramid's level of detail for a footprint whose longer edge is rho CoNUS pixels:
// lambda = max(0, log2(rho) - kDecodePyramidBias), 0 meaning level 0 alone (one bilinear tap),
// with log2 by a quadratic in the mantissa (within 0.005 of the exact log2) that the GLSL twin
// repeats. GL's own rule has no bias; a level-L texel is a 2^L box and bilinear adds a 2^L tent,
// so that blurs about 1.7x wider than the multi-tap average over rho (a box of rho plus a tent of
// 1), whose blur lambda = log2(rho) - 0.79 would match; at 0.5 a fitted zone plate keeps less
// aliasing than the multi-tap decode (tests/codec/image/pyramid_test.cpp) and stays within
// 33-37 dB of it, where GL's rule was 28-33 dB away. rhoSquared: rho^2.
inline constexpr double kDecodePyramidBias = 0.5;
float pyramidLevel(float rhoSquared);

}  // namespace conus::codec
