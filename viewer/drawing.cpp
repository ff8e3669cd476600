#include "drawing.h"

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "conus/core/display.h"

#include "overlay.h"

namespace conus::viewer {
namespace {

// Linear light to display values through the sRGB curve, tabulated (a frame has a million values).
constexpr int kCurveEntries = 1 << 14;
float displayValue(float linear) {
    static const std::array<float, kCurveEntries + 1> table = [] {
        std::array<float, kCurveEntries + 1> t{};
        for (int i = 0; i <= kCurveEntries; ++i) t[i] = linearToSrgbDisplay(float(i) / kCurveEntries);
        return t;
    }();
    if (!(linear > 0.0f)) return 0.0f;
    if (linear >= 1.0f) return 1.0f;
    const float x = linear * kCurveEntries;
    const int i = static_cast<int>(x);
    return table[i] + (table[i + 1] - table[i]) * (x - float(i));
}

// The frame's colour as the display shows it, opaque RGBA (an overlay's format).
Image displayRgba(const Image& frame) {
    Image rgba = makeImage(frame.width, frame.height, {"R", "G", "B", "A"});
    const int channel[3] = {frame.channelIndex("R"), frame.channelIndex("G"), frame.channelIndex("B")};
    const int n = frame.channelCount();
    for (std::size_t p = 0; p < std::size_t(frame.width) * frame.height; ++p) {
        for (int c = 0; c < 3; ++c) rgba.pixels[4 * p + c] = channel[c] < 0 ? 0.0f : displayValue(frame.pixels[n * p + channel[c]]);
        rgba.pixels[4 * p + 3] = 1.0f;
    }
    return rgba;
}

}  // namespace

Drawing::Drawing(renderers::Context& context) : m_renderer(context) {}

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

// A 3-D mode's usual display (raw, one frame pixel per window pixel, no grid, outlines, depth,
// exposure or tone map, the sRGB curve) is the CoNUS frame itself: it goes to the window as an
// overlay, one texel a pixel, without ViewRenderer::setImage, whose uniform image (a decode of the
// whole frame) nobody would look at. Any other display goes through setImage as a file would.
bool Drawing::showsSceneDirectly(const Controller& controller, int fw, int fh) {
    const format::ConusFile* frame = controller.sceneFrame();
    const renderers::ViewOptions& o = controller.display();
    const codec::View v = controller.state().view();
    constexpr double kExact = 1e-9;
    return frame && frame->image.width == fw && frame->image.height == fh && o.mode == renderers::ViewMode::Raw && !o.grid &&
           !o.outlines && o.exposure == 0 && o.toneMap == ToneMap::None && o.gamma == 0 && !controller.depthPicture() &&
           std::abs(v.u0) < kExact && std::abs(v.v0) < kExact && std::abs(v.u1 - 1) < kExact && std::abs(v.v1 - 1) < kExact;
}

void Drawing::frame(Controller& controller, int fw, int fh) {
    if (m_scene && controller.scene()) {
        renderScene(controller);
        if (!m_sceneFailed && showsSceneDirectly(controller, fw, fh)) {
            if (m_directVersion != controller.imageVersion()) {
                m_renderer.setOverlay(kSceneSlot, displayRgba(controller.sceneFrame()->image));
                m_directVersion = controller.imageVersion();
            }
            m_renderer.clear(fw, fh, 0.0f, 0.0f, 0.0f);
            m_renderer.drawOverlay(kSceneSlot, 0, 0, fw, fh);
            drawOverlays(controller, fw, fh);
            return;
        }
    }
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
