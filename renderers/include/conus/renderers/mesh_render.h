// The GPU mesh encoder (paper section 3.2, "Geometry data"): a conus::Mesh seen through a
// flexible pinhole camera (a Camera and a sampling map) rendered as a CoNUS colour + depth image.
// Each vertex is projected with the camera and moved by Equation 1 (equation1.inc.glsl: the map's
// nodes fetched exactly, manual bilinear weights). The rasterizer joins distorted vertices with
// straight edges and affine insides while the map bends both, so the tessellation stages split
// each triangle where the map bends its picture by more than options.maxBend pixels
// (mesh.tesc.glsl; nothing is split for an affine map such as the identity); the mesh uploaded
// stays as it is. codec/mesh/subdivide.h's uniform split (`--max-edge`) is the CPU alternative.
// Shading is codec/mesh/shading.h's.
// The CPU path is codec's Embree reference (codec/mesh/raycast.h), which casts each CoNUS pixel's
// exact ray; renderMesh(Device, ...) registers both.
//
// Output (the agreed channels of a mesh render): R, G, B, A, Z, float, top row first. A is the
// coverage (1 hit, 0 miss; with multisampling the fraction of samples covered, and RGB the mean
// over samples with misses counting as 0, as the reference averages its sub-pixel rays). Z is
// camera depth (Camera::project(...).z, the spec's cameraDepth) where hit and the camera's far
// where missed; with multisampling Z is the NEAREST sample's depth (the minimum over the pixel's
// samples), never a mean, which across a silhouette would be a depth on neither surface.
//
// Shared rules: frames are 1 to 16384 pixels a side and at most GL_MAX_TEXTURE_SIZE (not tiled:
// conus::Error LimitExceeded beyond); the mesh passes core's checkMesh (else InvalidArgument) and
// gets area-weighted normals when it has none; a failed GL call throws Unsupported, out of GL
// memory LimitExceeded. The context is made current on the calling
// thread.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "conus/codec/map/sampling_map.h"
#include "conus/core/camera.h"
#include "conus/core/mesh.h"
#include "conus/renderers/backend.h"
#include "conus/renderers/context.h"
#include "conus/renderers/gpu_image.h"

namespace conus::renderers {

inline constexpr double kDefaultMaxBend = 0.5;   // CoNUS pixels: `conus render mesh`'s --max-bend

struct MeshRenderOptions {
    int samples = 4;  // multisampling per pixel (1: one sample at the centre); the driver's maximum caps it
    // Split triangles on the GPU until the map bends no edge or inside more than this many CoNUS
    // pixels away from what the rasterizer draws (0: draw the triangles as they are).
    double maxBend = kDefaultMaxBend;
};

// Keeps a mesh uploaded, so that frames of one mesh (another camera, another map) cost only the draw
// and the readback. Refuses (LimitExceeded) a mesh whose triangles overlap too deeply for any
// view (codec::checkMeshOverdraw) before uploading it.
class MeshRenderer {
public:
    MeshRenderer(Context& context, const Mesh& mesh);
    ~MeshRenderer();
    MeshRenderer(const MeshRenderer&) = delete;
    MeshRenderer& operator=(const MeshRenderer&) = delete;

    // The camera's aspect should be width / height (else the picture is stretched). `timings`, if
    // given, receives the phases (upload: the map; draw; readback); `trianglesDrawn` the triangles
    // the rasterizer was given (after the split). Throws InvalidArgument for samples < 1 or a
    // negative or non-finite maxBend.
    Image render(const Camera& camera, const codec::SamplingMap& map, int width, int height,
                 const MeshRenderOptions& options = {}, GpuTimings* timings = nullptr,
                 std::int64_t* trianglesDrawn = nullptr);

    // Depth peeling: `layers` frames, frame k the k-th surface along each pixel (the first more
    // than codec::kPeelGap of its depth behind frame k - 1's; A = 0 and the far depth where there
    // is none), one sample a pixel (options.samples is ignored), as codec::renderMeshLayers casts
    // its rays. Throws InvalidArgument for layers < 1.
    std::vector<Image> renderLayers(const Camera& camera, const codec::SamplingMap& map, int width, int height,
                                    int layers, const MeshRenderOptions& options = {});

private:
    Image frame(const Camera& camera, const codec::SamplingMap& map, int width, int height,
                const MeshRenderOptions& options, GpuTimings* timings, std::int64_t* trianglesDrawn,
                const Image* behind);

    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

// One frame on the GPU: upload, draw, read back.
Image renderMeshGpu(Context& context, const Mesh& mesh, const Camera& camera, const codec::SamplingMap& map,
                    int width, int height, const MeshRenderOptions& options = {});

// One frame on a device: the GPU path above, or the Embree reference (each pixel's exact ray;
// options.samples > 1 becomes the reference's round(sqrt(samples))^2 stratified rays).
Image renderMesh(const Device& device, const Mesh& mesh, const Camera& camera, const codec::SamplingMap& map,
                 int width, int height, const MeshRenderOptions& options = {});

}  // namespace conus::renderers
