// The desktop viewer's frame shader (view_frame.frag.glsl, Equation 1 and the decoder's pyramid
// tap from equation1.inc.glsl, the shared constants) as GLSL ES 3.00 for WebGL2, so the browser
// viewer (`conus web`, `conus serve`) draws with the same source conus-view does.
#pragma once

#include <string>

namespace conus::renderers {

// The shader's text after its #version line: precision statements, the shared constants, then
// the body. A WebGL2 page prepends "#version 300 es" and its VIEW_MODE, VIEW_GRID and
// VIEW_OUTLINES defines. Local `const` declarations become plain ones (GLSL ES 3.00 takes only
// constant expressions after `const`, GLSL 4.50 any value).
std::string viewFrameShaderEs();

}  // namespace conus::renderers
