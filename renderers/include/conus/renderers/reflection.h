// Reflections on the GPU (paper section 5, Figure 6): the GLSL twin of
// codec::renderReflectionFrame. A reflection asset's six cube faces (codec/depth/reflection.h) are
// uploaded as float textures (camera depths, the maps' nodes, colour + coverage); a frame draws
// the scene behind with the mesh renderer (one sample a ray, identity map) and then, in one
// fragment pass, meets each of a pixel's options.samples x options.samples eye rays (the CPU's
// rays, averaged as it averages them) with the reflector and intersects the reflected ray with the
// faces through intersect.inc.glsl, the one intersection algorithm.
//
// Shared rules as depth_frames.h; a driver with fewer than 19 fragment texture units is Unsupported.
#pragma once

#include <vector>

#include "conus/codec/depth/reflection.h"
#include "conus/core/camera.h"
#include "conus/core/image.h"
#include "conus/renderers/backend.h"
#include "conus/renderers/context.h"
#include "conus/renderers/depth_frames.h"

namespace conus::renderers {

// Keeps an asset (exactly six faces) and its scene uploaded (a frame is two draws: the scene
// behind, then the reflection pass); render() gives channels R, G, B, M as
// codec::renderReflectionFrame's.
class ReflectionRenderer : public DepthFrameRenderer {
public:
    ReflectionRenderer(Context& context, const Mesh& scene, const std::vector<codec::ReflectionFace>& faces,
                       const codec::ReflectionFrameOptions& options);
};

// A frame on a device: the renderer above, or codec::renderReflectionFrame (the CPU reference) with
// the faces (the faces' eye is the centre it needs).
Image renderReflection(const Device& device, const codec::MeshScene& scene,
                       const std::vector<codec::ReflectionFace>& faces, const Camera& camera, int width, int height,
                       const codec::ReflectionFrameOptions& options);

}  // namespace conus::renderers
