#include "drawing.h"

#include <chrono>
#include <cstdio>
#include <filesystem>

#include "overlay.h"

namespace conus::viewer {

Drawing::Drawing(gl::Context& context) : m_renderer(context) {}

void Drawing::setUniform(const std::string& path, Image uniform) {
    m_uniformPath = path;
    m_uniform = std::move(uniform);
}

void Drawing::renderScene(Controller& controller) {
    const SceneState& state = *controller.scene();
    bool changed = false;
    for (; m_looksSeen < controller.lookRequests(); ++m_looksSeen) {
        controller.setLook(m_scene->nextLook());
        changed = true;
    }
    const glm::ivec2 size = controller.sceneFrameSize();
    if (!changed && state.version() == m_sceneVersion && size == m_sceneSize) return;
    m_sceneVersion = state.version();
    m_sceneSize = size;
    const double aspect = double(size.x) / size.y;
    try {
        const Camera camera = state.camera(aspect);
        const codec::SamplingMap map = m_scene->throughMap() ? state.map(aspect) : codec::SamplingMap::identity(2, 2);
        const auto start = std::chrono::steady_clock::now();
        Image image = m_scene->render(camera, map, state.conus(), size.x, size.y);
        m_sceneSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        ++m_sceneRenders;
        const bool live = m_scene->throughMap() && state.conus();
        controller.setSceneFrame(sceneFrameFile(std::move(image), map, camera, live ? state.foci() : std::vector<codec::Focus>{}));
        m_sceneFailed = false;
    } catch (const std::exception& e) {
        if (!m_sceneFailed) std::fprintf(stderr, "conus-view: %s: %s\n", m_scene->name().c_str(), e.what());
        m_sceneFailed = true;
        controller.failed();
    }
}

void Drawing::frame(Controller& controller, int fw, int fh) {
    if (m_scene && controller.scene()) renderScene(controller);
    if (m_imageVersion != controller.imageVersion()) {
        m_imageVersion = controller.imageVersion();
        m_mapVersion = controller.mapVersion();
        m_shown = false;
        if (const std::optional<format::ConusFile> file = controller.shownFile()) {
            try {
                m_renderer.setImage(*file);
                const Document* shown = controller.current();
                if (!m_uniformPath.empty() && shown && shown->path == m_uniformPath) m_renderer.setUniform(m_uniform);
                m_shown = true;
            } catch (const std::exception& e) {
                controller.cannotDisplay(e.what());
            }
        }
    } else if (m_mapVersion != controller.mapVersion()) {
        m_mapVersion = controller.mapVersion();
        if (const MapEditor* editor = controller.editor()) m_renderer.setMap(editor->map());
    }
    const Document* doc = controller.current();
    if (!controller.editing() && (!m_shown || (doc && !doc->ok()) || (controller.scene() && m_sceneFailed))) {
        // The window turns dark red with the error written over it (also in the title and on stderr).
        m_renderer.clear(fw, fh, 0.35f, 0.05f, 0.05f);
    } else {
        m_renderer.draw(controller.state().view(), fw, fh, controller.display());
    }
    drawOverlays(controller, fw, fh);
}

template <class Make>
bool Drawing::prepareOverlay(int slot, const std::string& key, Make make) {
    if (m_textBroken) return false;
    if (m_overlayKey[slot] == key && m_renderer.hasOverlay(slot)) return true;
    try {
        const Image panel = make();
        m_renderer.setOverlay(slot, panel);
        m_overlayKey[slot] = key;
        m_overlayHeight[slot] = panel.height;
        return true;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "conus-view: no text in the window: %s\n", e.what());
        m_textBroken = true;
        return false;
    }
}

void Drawing::drawOverlays(const Controller& controller, int fw, int fh) {
    const Document* doc = controller.current();
    if (!controller.editing() && doc && !doc->ok()) {
        const std::string name = std::filesystem::path(doc->path).filename().string();
        if (prepareOverlay(kErrorSlot, name + "\n" + doc->error + "\n" + std::to_string(fw),
                           [&] { return errorPanel(name, doc->error, fw); }))
            m_renderer.drawOverlay(kErrorSlot, kOverlayMargin, kOverlayMargin, fw, fh);
    }
    if (controller.showStatus()) {
        const std::string text = controller.statusText();
        if (prepareOverlay(kStatusSlot, text + "\n" + std::to_string(fw), [&] { return statusPanel(text, fw); }))
            m_renderer.drawOverlay(kStatusSlot, 0, fh - m_overlayHeight[kStatusSlot], fw, fh);
    }
    const KeyTable table = controller.keyTable();
    if (controller.showHelp() && prepareOverlay(kHelpSlot, std::to_string(int(table)), [&] { return helpPanel(table); }))
        m_renderer.drawOverlay(kHelpSlot, kOverlayMargin, kOverlayMargin, fw, fh);
}

}  // namespace conus::viewer
