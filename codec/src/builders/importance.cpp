// The importance rules by name (importance.h). Detail's body lies in auto_map.cpp, beside the
// luminance it shares; faces' in faces.cpp, reached through faces_load_module.cpp or _static.cpp.
#include "conus/codec/builders/importance.h"

namespace conus::codec {

const char* toString(ImportanceRule rule) { return kImportanceRuleNames[static_cast<std::size_t>(rule)]; }

std::optional<ImportanceRule> parseImportanceRule(std::string_view text) {
    for (std::size_t i = 0; i < kImportanceRuleNames.size(); ++i)
        if (text == kImportanceRuleNames[i]) return static_cast<ImportanceRule>(i);
    return std::nullopt;
}

Image ruleImportance(ImportanceRule rule, const Image& shown) {
    return rule == ImportanceRule::Faces ? faceImportance(shown) : detailImportance(shown);
}

}  // namespace conus::codec
