#include "importance.h"

#include "conus/codec/build/auto_map.h"
#include "conus/core/error.h"
#include "conus/core/plugin.h"
#include "conus/imageio/image_file.h"
#include "image_files.h"

namespace conus::cli {

Image faceImportance(const Image& image) {
    // CONUS_FACES_MODULE: the module's path relative to this program (cli/CMakeLists.txt).
    static const FaceImportanceFunction detect = reinterpret_cast<FaceImportanceFunction (*)()>(
        loadPluginSymbol(reinterpret_cast<const void*>(&faceImportance), CONUS_FACES_MODULE, "conusFaceImportance"))();
    return detect(image);
}

Image importanceFrom(const std::string& source, const Image& image) {
    if (source == "detail") {
        if (image.empty()) throw Error(ErrorCode::InvalidArgument, "'detail' importance needs an input image");
        // Detail as people see it: on the display-encoded picture, where NaN cannot reach.
        return codec::detailImportance(imageio::displayEncoded(image));
    }
    if (source == "faces") {
        if (image.empty()) throw Error(ErrorCode::InvalidArgument, "'faces' importance needs an input image");
        return faceImportance(imageio::displayEncoded(image));
    }
    return readData(source);
}

}  // namespace conus::cli
