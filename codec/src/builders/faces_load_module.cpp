// faceImportance in a shared build: the detector is the module libconus_faces (faces.cpp), loaded
// on the first call from <this library's folder>/CONUS_FACES_MODULE (codec/CMakeLists.txt).
#include "conus/codec/builders/importance.h"
#include "conus/core/plugin.h"

namespace conus::codec {

Image faceImportance(const Image& shown) {
    static const FaceImportanceFunction detect = reinterpret_cast<FaceImportanceFunction (*)()>(
        loadPluginSymbol(reinterpret_cast<const void*>(&faceImportance), CONUS_FACES_MODULE, "conusFaceImportance"))();
    return detect(shown);
}

}  // namespace conus::codec
