// Image files at the viewer's edge (PNG screenshots, the --edit source image) through
// OpenImageIO; the only file of viewer/ that includes it. CoNUS files go through conus::format.
#pragma once

#include <string>

#include "conus/format/image.h"

namespace conus::viewer {

// Any image OpenImageIO reads, as float (8/16-bit values scaled to [0,1]); conus::Error(Io) when
// it cannot be read, LimitExceeded beyond the library's image limits.
format::Image readImage(const std::string& path);

// The first three channels (or one grey channel) as an 8-bit PNG/JPEG, or float EXR/TIFF by
// extension; values are clamped to [0,1] for 8-bit formats. conus::Error(Io) on failure.
void writeImage(const std::string& path, const format::Image& image);

}  // namespace conus::viewer
