// The frame loop the relief and reflection renderers share (depth_frames.h); their scenes draw.
#include "conus/renderers/depth_frames.h"

#include "context_pvt.h"
#include "depth_pvt.h"
#include "frame_pvt.h"

namespace conus::renderers {

DepthFrameRenderer::DepthFrameRenderer(std::unique_ptr<Scene> scene) : m_scene(std::move(scene)) {}

DepthFrameRenderer::~DepthFrameRenderer() {
    if (m_scene) makeCurrentGl(m_scene->context);  // the GL objects die in their own context
}

void DepthFrameRenderer::draw(const Camera& camera, int width, int height) {
    m_scene->drawFrame(camera, width, height);
    makeCurrentGl(m_scene->context).Finish();
}

Image DepthFrameRenderer::render(const Camera& camera, int width, int height) {
    m_scene->drawFrame(camera, width, height);
    const GladGLContext& gl = makeCurrentGl(m_scene->context);
    Image frame = readFrame(gl, width, height, m_scene->channels);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    checkGl(gl, m_scene->what);
    return frame;
}

}  // namespace conus::renderers
