// Depth in CoNUS depth images (a mesh render's Z, camera depth), decoded to conventional views.
// A Z value is the depth of one surface; interpolating Z across a silhouette would invent a depth
// between the two surfaces (a "flying pixel"), so depth decodes NEAREST: the output pixel at
// undistorted (u, v) takes the Z of the CoNUS pixel whose area holds Equation 1's SM(u, v). Colour
// and coverage decode as any image (decode.h), bilinearly. Shared rules: decode.h's (view, size,
// threads, memory check; this one is cheap and reports no progress).
#pragma once

#include "conus/codec/image/decode.h"
#include "conus/codec/map/sampling_map.h"
#include "conus/core/image.h"

namespace conus::codec {

// One channel "Z": the nearest CoNUS pixel's `Z` for every output pixel whose undistorted
// position lies in [0,1]^2, `background` elsewhere. conus::Error(InvalidArgument) when `conus`
// has no Z channel.
Image decodeDepthNearest(const Image& conus, const SamplingMap& map, const DecodeOptions& options, float background);

}  // namespace conus::codec
