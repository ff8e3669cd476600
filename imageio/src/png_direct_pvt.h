// Private: plain PNG files read with libpng directly, without loading OpenImageIO (its ~260
// libraries cost ~0.7 s of CPU and ~170 MiB before the first pixel).
#pragma once

#include <optional>
#include <string>

#include "conus/imageio/image_file.h"

namespace conus::imageio {

// Reads `path` when it is a PNG whose reading this reader reproduces exactly as the OpenImageIO
// path does (the same pixels, channel names, ICC profile, chromaticities and carried metadata): a
// regular file, 8 or 16 bits, grey or RGB without alpha, palette or interlace, no eXIf or sBIT
// chunk, no XMP or raw-profile text, within the read limits, with the first part asked for.
// nullopt for anything else, and for a file libpng finds damaged: the OpenImageIO path then
// reads it or words the error as it always has.
std::optional<ImageFile> readPngDirect(const std::string& path, const ReadOptions& options);

// The linear value of an sRGB-encoded value in [0, 1] (IEC 61966-2-1), computed in double and
// rounded once.
float srgbToLinear(double encoded);

}  // namespace conus::imageio
