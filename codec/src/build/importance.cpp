#include "conus/codec/build/importance.h"

#include "conus/core/plugin.h"

#ifdef CONUS_FACES_LINKED
extern "C" conus::codec::FaceImportanceFunction conusFaceImportance();
#endif

namespace conus::codec {

const char* toString(ImportanceRule rule) { return kImportanceRuleNames[static_cast<std::size_t>(rule)]; }

std::optional<ImportanceRule> parseImportanceRule(std::string_view text) {
    for (std::size_t i = 0; i < kImportanceRuleNames.size(); ++i)
        if (text == kImportanceRuleNames[i]) return static_cast<ImportanceRule>(i);
    return std::nullopt;
}

Image faceImportance(const Image& shown) {
#ifdef CONUS_FACES_LINKED
    static const FaceImportanceFunction detect = conusFaceImportance();
#else
    // CONUS_FACES_MODULE: the module's path relative to this library (codec/CMakeLists.txt).
    static const FaceImportanceFunction detect = reinterpret_cast<FaceImportanceFunction (*)()>(
        loadPluginSymbol(reinterpret_cast<const void*>(&faceImportance), CONUS_FACES_MODULE, "conusFaceImportance"))();
#endif
    return detect(shown);
}

Image ruleImportance(ImportanceRule rule, const Image& shown) {
    return rule == ImportanceRule::Faces ? faceImportance(shown) : detailImportance(shown);
}

}  // namespace conus::codec
