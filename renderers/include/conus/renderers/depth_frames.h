// What the renderers of frames through CoNUS depth images share (relief.h, reflection.h): the
// assets stay uploaded in one context, and a frame costs its draws (one full-screen pass through
// intersect.inc.glsl) and the readback.
//
// Shared rules: frames are float, top row first, 1 to 16384 pixels a side (and at most
// GL_MAX_TEXTURE_SIZE); bad arguments throw conus::Error(InvalidArgument), a failed GL call
// Unsupported, out of GL memory LimitExceeded. The context is made current on the calling thread.
#pragma once

#include <memory>

#include "conus/core/camera.h"
#include "conus/core/image.h"

namespace conus::renderers {

class DepthFrameRenderer {
public:
    // The uploaded assets and the draw of one frame: each renderer's own (renderers/src/depth_pvt.h).
    struct Scene;

    virtual ~DepthFrameRenderer();
    DepthFrameRenderer(const DepthFrameRenderer&) = delete;
    DepthFrameRenderer& operator=(const DepthFrameRenderer&) = delete;

    // The frame, in the renderer's channels. The camera's aspect should be the frame's (else the
    // picture is stretched).
    Image render(const Camera& camera, int width, int height);
    // Waits for a frame without reading it back (benchmarks: frames per second of the draws).
    void draw(const Camera& camera, int width, int height);

protected:
    explicit DepthFrameRenderer(std::unique_ptr<Scene> scene);

private:
    std::unique_ptr<Scene> m_scene;
};

}  // namespace conus::renderers
