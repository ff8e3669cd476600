// The importance rules by name (importance.h). Detail's body lies in auto_map.cpp, beside the
// luminance it shares; faces' in faces.cpp, reached through faces_load_module.cpp or _static.cpp.
#include "conus/codec/builders/importance.h"

namespace conus::codec {

Image ruleImportance(ImportanceRule rule, const Image& shown) {
    return rule == ImportanceRule::Faces ? faceImportance(shown) : detailImportance(shown);
}

}  // namespace conus::codec
