// Private: the constants C++ and GLSL share, defined once on the C++ side and injected into every
// shader's source after its #version line when a program is built (context.cpp's cachedProgram),
// so a shader never types one of these values again.
#pragma once

#include <string>

#include "conus/renderers/view_renderer.h"  // kViewBackground (GLSL: kBackground)

namespace conus::renderers {

inline constexpr int kViewMaxFoci = 16;          // focus outlines conus-view draws (GLSL: kMaxFoci)
inline constexpr int kMeshMaxTessLevel = 64;     // mesh.tesc.glsl's largest level, GL_MAX_TESS_GEN_LEVEL's least

// `source` with the shared constants declared after its first line (#version):
// kDecodeMultiTap, kDecodeMaxTaps, kDecodePyramidBias (codec/decode.h), kEncodeMaxTaps, kEncodeTapTolerance,
// kEncodeMaxAxisTaps, kEncodeAnisotropicSigma, kEncodeGaussianReach, kEncodeBoxAnisotropy
// (codec/encode.h), kBackground (view_renderer.h), kMaxFoci (above), kInferno[6] (core/display.h), and the mesh
// shading's kMeshAmbient, kMeshGrey (codec/mesh/shading.h: kAmbient, kDefaultAlbedo), and
// kIntersectDepthMargin, kSilhouetteStep and kSideRuleFarMargin (codec/depth/intersect.h), and
// kMeshMaxTessLevel (above).
std::string withSharedConstants(const std::string& source);

}  // namespace conus::renderers
