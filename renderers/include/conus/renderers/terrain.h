// Client-side rendering of height-field meshes (paper section 4, Figure 5): the mesh that
// codec::undistortHeightField makes from a CoNUS (or uniform) height field, rasterized with a
// perspective camera, per-vertex normals lit by one directional light plus ambient, a depth test
// and a sky-coloured background, into an RGBA32F framebuffer read back as an RGB Image
// (top row first, the image-plane convention; the flip from GL's bottom-up rows happens here).
//
// Shared rules: the world frame is Mesh's (x right, y up, z toward the viewer, metres);
// frames are float RGB, 1 to 16384 pixels a side (and at most GL_MAX_TEXTURE_SIZE); a failed GL
// call throws conus::Error(Unsupported), out of GL memory LimitExceeded, bad arguments
// InvalidArgument. The context is made current on the calling thread.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include <glm/glm.hpp>

#include "conus/codec/builders/ground_map.h"
#include "conus/core/camera.h"
#include "conus/codec/depth/heightfield.h"
#include "conus/core/image.h"
#include "conus/format/container.h"
#include "conus/renderers/context.h"

namespace conus::renderers {

struct TerrainLook {
    glm::vec3 sky{0.62f, 0.74f, 0.88f};
    glm::vec3 towardSun{-0.45f, 0.75f, -0.35f};  // need not be unit
    float ambient = 0.35f;
    int samples = 4;  // multisampling (1: none); the driver's maximum caps it
};

// A camera near the ground map's viewer: above the middle of the near edge's line at z = depth +
// near, `eyeHeight` above `groundHeight` (the terrain under it), looking across the field toward
// -z, pitched so the field's near edge lands on the bottom row (or, for a field deeper than the
// frame, so the far edge stays in the top half). `sideways` moves it along
// x (metres) and `turnDegrees` turns it (positive to the left), for nearby poses.
// `aspect` is the frame's width / height.
Camera viewerCamera(const codec::GroundParams& ground, double groundHeight, double aspect, double sideways = 0.0,
                    double turnDegrees = 0.0, double fovYDegrees = 50.0);

// Keeps a mesh uploaded so that frames cost only the draw and the readback (the client's loop).
class TerrainRenderer {
public:
    TerrainRenderer(Context& context, const Mesh& mesh, const TerrainLook& look = {});
    ~TerrainRenderer();
    TerrainRenderer(const TerrainRenderer&) = delete;
    TerrainRenderer& operator=(const TerrainRenderer&) = delete;

    // The camera's aspect should be the frame's (else the picture is stretched).
    Image render(const Camera& camera, int width, int height);

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

// One frame: upload, draw, read back.
Image renderTerrain(Context& context, const Mesh& mesh, const Camera& camera, int width,
                            int height, const TerrainLook& look = {});

// ---- Frames of a CoNUS height field (`conus render heightfield`, `conus decode --camera`) ----

// The ground map of a CoNUS height field, from its analytic parameters; throws
// conus::Error(InvalidArgument), naming the file as `name`, unless `file` is a height field with them.
codec::GroundParams heightFieldGround(const format::ConusFile& file, const std::string& name = "the file");

// Where a frame is seen from: the eye, the point it looks at, the vertical field of view (degrees).
struct TerrainView {
    glm::dvec3 eye{0.0}, target{0.0};
    double fovYDegrees = 50;
};

// The ground map's own viewer of `file` (viewerCamera, standing on the height at the middle of the
// near edge), or `view` with that viewer's clip distances. `aspect` is the frame's width / height.
Camera heightFieldCamera(const format::ConusFile& file, double aspect,
                         const std::optional<TerrainView>& view = std::nullopt);

// A frame of the CoNUS height field `file`: undistorted to a mesh over the field's extent
// (codec::undistortHeightField) and rendered from `camera` (renderTerrain).
Image renderHeightFieldFrame(Context& context, const format::ConusFile& file, const Camera& camera, int width, int height);

}  // namespace conus::renderers
