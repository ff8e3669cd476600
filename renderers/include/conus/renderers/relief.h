// Rays against CoNUS depth images on the GPU (paper section 5): the GLSL twin of
// codec::intersect (renderers/shaders/intersect.inc.glsl) run on a batch of rays, and relief
// texture mapping: a frame of a relief asset (an orthographic CoNUS height field, `conus bake
// relief`) drawn as its box, each eye ray intersected with the CoNUS height texture in a fragment
// shader, shaded by the stored colour and the surface's normal, optionally self-shadowed (a second
// ray toward the light through the same intersection).
//
// Shared rules: the depth image is uploaded once per renderer (camera depths R32F, the map's
// nodes RG32F, colour RGB32F); frames are float RGB, top row first, 1 to 16384 pixels a side (and
// at most GL_MAX_TEXTURE_SIZE); bad arguments throw conus::Error(InvalidArgument), a failed GL
// call Unsupported, out of GL memory LimitExceeded. The context is made current on the calling
// thread.
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "conus/codec/depth/intersect.h"
#include "conus/core/camera.h"
#include "conus/core/image.h"
#include "conus/renderers/context.h"

namespace conus::gl {

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

// Keeps an asset uploaded so that frames cost only the draw and the readback.
class ReliefRenderer {
public:
    // `colour` is the asset's CoNUS image (R, G, B channels; grey when it has none), the size of
    // the depth image.
    ReliefRenderer(Context& context, const codec::DepthImage& image, const Image& colour, const ReliefLook& look = {});
    ~ReliefRenderer();
    ReliefRenderer(const ReliefRenderer&) = delete;
    ReliefRenderer& operator=(const ReliefRenderer&) = delete;

    // The camera's aspect should be the frame's (else the picture is stretched).
    Image render(const Camera& camera, int width, int height);
    // Waits for a frame without reading it back (benchmarks: frames per second of the draw).
    void draw(const Camera& camera, int width, int height);

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

}  // namespace conus::gl
