// conus-view's drawing: a frame of what the controller describes, through the renderers'
// ViewRenderer on the window's context, with the text overlays (help, error, status bar) over it.
#pragma once

#include <string>

#include "controller.h"
#include "conus/renderers/view_renderer.h"
#include "scene.h"

namespace conus::viewer {

class Drawing {
public:
    explicit Drawing(renderers::Context& context);

    // Draws into the bound framebuffer (fw x fh): uploads the image or map first when the
    // controller's versions moved.
    void frame(Controller& controller, int fw, int fh);
    // The frame just drawn, display values, top row first.
    Image readFramebuffer(int fw, int fh) { return m_renderer.readFramebuffer(fw, fh); }
    renderers::ViewRenderer& renderer() { return m_renderer; }
    // Shows `uniform` as the uniform image whenever the file at `path` is shown (--uniform).
    void setUniform(const std::string& path, Image uniform);
    // The 3-D modes: the scene frames are rendered from (owned by the caller, outliving the drawing's use).
    void setScene(Scene* scene) { m_scene = scene; }
    // Frames the scene has rendered, and the seconds they took (the render and its readback alone).
    int sceneRenders() const { return m_sceneRenders; }
    double sceneSeconds() const { return m_sceneSeconds; }

private:
    void drawOverlays(const Controller& controller, int fw, int fh);
    // Renders a new scene frame into the controller when what it shows has changed.
    void renderScene(Controller& controller);
    // Whether the scene's frame can go to the window directly (see drawing.cpp).
    static bool showsSceneDirectly(const Controller& controller, int fw, int fh);
    // Uploads `make()`'s panel into `slot` when `key` (what the panel shows) has changed.
    template <class Make>
    bool prepareOverlay(int slot, const std::string& key, Make make);

    renderers::ViewRenderer m_renderer;
    int m_imageVersion = -1, m_mapVersion = -1;
    bool m_shown = false;  // the renderer holds an image
    std::string m_uniformPath;  // --uniform: the file it belongs to, and the image
    Image m_uniform;
    std::string m_overlayKey[renderers::ViewRenderer::kOverlaySlots];
    int m_overlayHeight[renderers::ViewRenderer::kOverlaySlots] = {};
    bool m_textBroken = false;
    Scene* m_scene = nullptr;
    int m_sceneVersion = -1, m_looksSeen = 0;
    glm::ivec2 m_sceneSize{0};
    bool m_sceneFailed = false;
    int m_directVersion = -1;  // the frame in kSceneSlot (the controller's imageVersion)
    int m_sceneRenders = 0;
    double m_sceneSeconds = 0;  // the font could not be drawn: overlays off, said once on stderr
};

}  // namespace conus::viewer
