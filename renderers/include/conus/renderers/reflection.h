// Reflections on the GPU (paper section 5, Figure 6): the GLSL twin of
// codec::renderReflectionFrame. A reflection asset's six cube faces (codec/depth/reflection.h) are
// uploaded as float textures (camera depths, the maps' nodes, colour + coverage); a frame draws
// the scene behind with the mesh renderer (one sample a pixel, identity map) and then, in one
// fragment pass, meets each pixel's eye ray with the reflector and intersects the reflected ray
// with the faces through intersect.inc.glsl, the one intersection algorithm.
//
// Shared rules as relief.h: frames are float, top row first, 1 to 16384 pixels a side (and at most
// GL_MAX_TEXTURE_SIZE); bad arguments throw conus::Error(InvalidArgument), a failed GL call or a
// driver with fewer than 19 fragment texture units Unsupported, out of GL memory LimitExceeded.
#pragma once

#include <memory>
#include <vector>

#include "conus/codec/depth/reflection.h"
#include "conus/core/camera.h"
#include "conus/core/image.h"
#include "conus/renderers/backend.h"
#include "conus/renderers/context.h"

namespace conus::gl {

// Keeps an asset (exactly six faces) and its scene uploaded so that frames cost the two draws and
// the readback.
class ReflectionRenderer {
public:
    ReflectionRenderer(Context& context, const Mesh& scene, const std::vector<codec::ReflectionFace>& faces,
                       const codec::ReflectionFrameOptions& options);
    ~ReflectionRenderer();
    ReflectionRenderer(const ReflectionRenderer&) = delete;
    ReflectionRenderer& operator=(const ReflectionRenderer&) = delete;

    // Channels R, G, B, M as codec::renderReflectionFrame's. The camera's aspect should be the frame's.
    Image render(const Camera& camera, int width, int height);
    // Waits for a frame without reading it back (benchmarks: frames per second of the draws).
    void draw(const Camera& camera, int width, int height);

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

// A frame on a device: the renderer above, or codec::renderReflectionFrame (the CPU reference) with
// the faces (the faces' eye is the centre it needs).
Image renderReflection(const Device& device, const codec::MeshScene& scene,
                       const std::vector<codec::ReflectionFace>& faces, const Camera& camera, int width, int height,
                       const codec::ReflectionFrameOptions& options);

}  // namespace conus::gl
