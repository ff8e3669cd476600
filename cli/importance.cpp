#include "importance.h"

#include "conus/codec/auto_map.h"
#include "conus/format/error.h"
#include "image_io.h"

namespace conus::cli {

format::Image importanceFrom(const std::string& source, const format::Image& image) {
    if (source == "detail") {
        if (image.empty()) throw Error(ErrorCode::InvalidArgument, "'detail' importance needs an input image");
        return codec::detailImportance(image);
    }
    if (source == "faces") {
        if (image.empty()) throw Error(ErrorCode::InvalidArgument, "'faces' importance needs an input image");
        return faceImportance(image);
    }
    return readImage(source);
}

}  // namespace conus::cli
