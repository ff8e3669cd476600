#include "shader_constants_pvt.h"

#include "conus/codec/depth/glsl_interface.h"
#include "conus/codec/image/decode.h"
#include "conus/codec/image/encode.h"
#include "conus/codec/mesh/shading.h"
#include "conus/codec/volume/raycast.h"
#include "conus/core/display.h"

namespace conus::renderers {
namespace {

using codec::glslFloat;

std::string constantsBlock() {
    std::string s = "// shared with C++ (renderers/src/shader_constants_pvt.h)\n";
    s += codec::glslConstants();  // equation1.inc.glsl and intersect.inc.glsl's
    s += "const int kEncodeMaxTaps = " + std::to_string(codec::kEncodeMaxTaps) + ";\n";
    s += "const float kEncodeTapTolerance = " + glslFloat(codec::kEncodeTapTolerance) + ";\n";
    s += "const int kEncodeMaxAxisTaps = " + std::to_string(codec::kEncodeMaxAxisTaps) + ";\n";
    s += "const float kEncodeAnisotropicSigma = " + glslFloat(codec::kEncodeAnisotropicSigma) + ";\n";
    s += "const float kEncodeGaussianReach = " + glslFloat(codec::kEncodeGaussianReach) + ";\n";
    s += "const float kEncodeBoxAnisotropy = " + glslFloat(codec::kEncodeBoxAnisotropy) + ";\n";
    s += "const float kEncodeAnisotropicMinorTexels = " + glslFloat(codec::kEncodeAnisotropicMinorTexels) + ";\n";
    s += "const int kEncodeAnisotropicMaxTaps = " + std::to_string(codec::kEncodeAnisotropicMaxTaps) + ";\n";
    s += "const int kTransferTableSize = " + std::to_string(codec::kTransferTableSize) + ";\n";
    s += "const float kTerminationOpacity = " + glslFloat(codec::kTerminationOpacity) + ";\n";
    s += "const vec3 kBackground = vec3(" + glslFloat(kViewBackground) + ");\n";
    s += "const int kMaxFoci = " + std::to_string(kViewMaxFoci) + ";\n";
    s += "const vec3 kInferno[" + std::to_string(kInfernoRamp.size()) + "] = vec3[](";
    for (std::size_t i = 0; i < kInfernoRamp.size(); ++i)
        s += std::string(i ? ", " : "") + "vec3(" + glslFloat(kInfernoRamp[i][0]) + ", " + glslFloat(kInfernoRamp[i][1]) +
             ", " + glslFloat(kInfernoRamp[i][2]) + ")";
    s += ");\n";
    s += "const float kMeshAmbient = " + glslFloat(codec::kAmbient) + ";\n";
    s += "const float kMeshGrey = " + glslFloat(codec::kDefaultAlbedo) + ";\n";
    s += "const float kMeshMaxTessLevel = " + glslFloat(kMeshMaxTessLevel) + ";\n";
    return s;
}

}  // namespace

std::string withSharedConstants(const std::string& source) {
    static const std::string block = constantsBlock();
    const std::size_t eol = source.find('\n');
    if (source.rfind("#version", 0) != 0 || eol == std::string::npos) return block + source;
    return source.substr(0, eol + 1) + block + source.substr(eol + 1);
}

}  // namespace conus::renderers
