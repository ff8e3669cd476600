// Image files at the edges of the tool (PNG, JPEG, TIFF, EXR, ... through OpenImageIO). CoNUS
// containers go through conus::format instead. The only file of cli/ that includes OpenImageIO.
#pragma once

#include <string>

#include "conus/format/image.h"

namespace conus::cli {

// Reads any image OpenImageIO knows into float (8/16-bit values scaled to [0,1]); the size is
// checked against the library limits before pixels are allocated.
format::Image readImage(const std::string& path);

// Writes an image by the path's extension: 8-bit for PNG/JPEG, half for EXR. Channels a format
// cannot hold (a `Z` in a PNG) are dropped. Written to a temporary file and renamed.
void writeImage(const std::string& path, const format::Image& image);

// Draws `text` in white-ish `color` with its baseline-left at (x,y), `size` pixels tall (DejaVu
// Sans, from Debian's fonts-dejavu-core). Used by the demo's built-in picture.
void drawText(format::Image& image, int x, int y, int size, const std::string& text, const float color[3]);

}  // namespace conus::cli
