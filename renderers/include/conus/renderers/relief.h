// Rays against CoNUS depth images on the GPU (paper section 5): the GLSL twin of
// codec::intersect (renderers/shaders/intersect.inc.glsl) run on a batch of rays, and relief
// texture mapping: a frame of a relief asset (an orthographic CoNUS height field, `conus bake
// relief`) drawn as its box, each eye ray intersected with the CoNUS height texture in a fragment
// shader, shaded by the stored colour and the surface's normal, optionally self-shadowed (a second
// ray toward the light through the same intersection).
//
// Shared rules as depth_frames.h: the depth image is uploaded once per renderer (camera depths
// R32F, the map's nodes RG32F, colour RGB32F); frames are float RGB.
#pragma once

#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "conus/codec/depth/intersect.h"
#include "conus/core/camera.h"
#include "conus/core/image.h"
#include "conus/renderers/context.h"
#include "conus/renderers/depth_frames.h"

namespace conus::renderers {

// codec::intersect for each ray, on the GPU (float precision): for tests of the GLSL against the
// CPU reference and for benchmarks.
std::vector<std::optional<codec::DepthHit>> intersectRays(Context& context, const codec::DepthImage& image,
                                                          const std::vector<Ray>& rays,
                                                          const codec::IntersectOptions& options = {});

struct ReliefLook {
    glm::vec3 background{0.16f, 0.17f, 0.19f};
    glm::vec3 towardLight{-0.4f, 0.8f, -0.45f};  // world direction, need not be unit
    float ambient = 0.3f;
    bool shadows = false;  // self-shadowing: a second intersection toward the light
    codec::IntersectOptions intersect;
};

// Keeps an asset uploaded; render() gives frames of channels R, G, B.
class ReliefRenderer : public DepthFrameRenderer {
public:
    // `colour` is the asset's CoNUS image (R, G, B channels; grey when it has none), the size of
    // the depth image.
    ReliefRenderer(Context& context, const codec::DepthImage& image, const Image& colour, const ReliefLook& look = {});
};

}  // namespace conus::renderers
