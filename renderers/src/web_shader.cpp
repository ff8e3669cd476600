#include "conus/renderers/web_shader.h"

#include <regex>

#include "embedded_shaders.h"
#include "shader_constants_pvt.h"

namespace conus::renderers {

std::string viewFrameShaderEs() {
    std::string source = withSharedConstants(shaders::kShaderViewFrameFrag);
    source = source.substr(source.find('\n') + 1);  // "#version 450 core": the page writes its own
    // A const inside a function (indented) takes run-time values in GLSL 4.50 only; globals (at
    // column 0) are constant expressions and keep theirs.
    source = std::regex_replace(source, std::regex("(\n[ \t]+)const "), "$1");
    return "precision highp float;\nprecision highp int;\nprecision highp sampler2D;\n" + source;
}

}  // namespace conus::renderers
