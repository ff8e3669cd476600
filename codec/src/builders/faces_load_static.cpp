// faceImportance in a static build: faces.cpp is linked in.
#include "conus/codec/builders/importance.h"

extern "C" conus::codec::FaceImportanceFunction conusFaceImportance();

namespace conus::codec {

Image faceImportance(const Image& shown) {
    static const FaceImportanceFunction detect = conusFaceImportance();
    return detect(shown);
}

}  // namespace conus::codec
