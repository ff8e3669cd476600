// CPU reference encoder: renders a CoNUS image from a conventional image through a sampling map.
// A CoNUS pixel centred at distorted p_d takes the source at undistorted SM^-1(p_d), filtered over
// the pixel's footprint in the source: the footprint follows the local Jacobian of the map, so
// there is no aliasing where the map compresses and no blur where it magnifies.
//
// Shared rules: sources are float images with any channels (alpha and Z preserved as channels);
// threads = 0 uses every core; sizes are checked (conus::Error InvalidArgument / LimitExceeded).
#pragma once

#include "conus/codec/map/sampling_map.h"
#include "conus/core/error.h"
#include "conus/core/image.h"

namespace conus::codec {

// The encoder's footprint rule, shared with its GLSL twin (renderers inject these values): at most
// kEncodeMaxTaps sub-pixels per footprint axis, on the first pyramid level where the footprint is
// at most that long; kEncodeTapTolerance keeps integer ratios exact despite float map nodes (a
// footprint of 4.0005 source pixels is still 4 taps).
inline constexpr int kEncodeMaxTaps = 4;
inline constexpr double kEncodeTapTolerance = 1e-3;

struct EncodeOptions {
    int width = 0, height = 0;  // CoNUS image size
    int threads = 0;
    ProgressFn progress;
};

Image encodeImage(const Image& source, const SamplingMap& map, const EncodeOptions& options);

// The plain baseline: box-filter area downsample to width x height (exact area weights). It only
// shrinks: a width or height above the source's throws conus::Error(InvalidArgument).
Image areaDownsample(const Image& source, int width, int height, int threads = 0);

}  // namespace conus::codec
