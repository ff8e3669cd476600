// Importance sources for automatic maps: an importance image file, the image's own detail, or the
// faces found in it. `encode --importance` and `map auto` share this.
#pragma once

#include <string>

#include "conus/core/image.h"

namespace conus::cli {

// `source` is "detail", "faces", or the path of a single-channel (or RGB) importance image.
// `image` is the picture being encoded (detail and faces are computed from it; may be empty for a
// file source).
Image importanceFrom(const std::string& source, const Image& image);

// Importance that is high on each face found in `image` (display-encoded: imageio::displayEncoded) (a soft disc over every detection), zero
// elsewhere; throws conus::Error(Unsupported: it depends on the picture, exit 1) when no face is found. The detector (OpenCV,
// faces.cpp) is a module loaded on the first call.
Image faceImportance(const Image& image);

// What the faces module (libconus_faces, extern "C" conusFaceImportance) hands out.
using FaceImportanceFunction = Image (*)(const Image& image);

}  // namespace conus::cli
