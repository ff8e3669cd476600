#include "controller.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "conus/imageio/image_file.h"
#include "depth_view.h"
#include "inspector.h"

namespace conus::viewer {
namespace {

constexpr double kExposureStep = 0.5;
constexpr double kStrengthStep = 1.25;

std::string fileName(const std::string& path) { return std::filesystem::path(path).filename().string(); }

ToneMap nextToneMap(ToneMap t) {
    return t == ToneMap::None ? ToneMap::Reinhard : t == ToneMap::Reinhard ? ToneMap::Aces : ToneMap::None;
}

}  // namespace

Controller::Controller(const Options& options)
    : m_options(options), m_display(options.display), m_showHelp(options.helpOverlay), m_showStatus(options.statusBar),
      m_depthPicture(options.depthPicture) {}

bool Controller::load() {
    if (m_options.sceneKind != SceneKind::None) return true;  // the window opens the scene (startScene)
    if (!m_options.edit.empty()) {
        try {
            imageio::ImageFile source = imageio::readImageFile(m_options.edit);
            m_editor.emplace(std::move(source.image), source.info.encoding);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "conus-view: %s\n", aboutFile(m_options.edit, e.what()).c_str());
            return false;
        }
        // The source, shown raw (it is undistorted), with the live map's grid over it.
        m_state.setImageSize(m_editor->source().width, m_editor->source().height);
        m_display.mode = renderers::ViewMode::Raw;
        m_display.grid = true;
        if (m_display.gridEvery == 0) m_display.gridEvery = std::max(1, m_editor->source().width / 64);
        ++m_imageVersion;
        std::printf("conus-view --edit %s: paint with the left button; H lists the keys\n", m_options.edit.c_str());
        return true;
    }
    for (const std::string& path : m_options.files) {
        m_docs.push_back(loadDocument(path, m_options.foci));
        if (!m_docs.back().ok()) {
            std::fprintf(stderr, "conus-view: %s\n", m_docs.back().error.c_str());
            m_exitCode = 1;
        }
    }
    showDocument(0, true);
    std::printf("conus-view: %zu file(s); H lists the keys\n", m_docs.size());
    return true;
}

void Controller::setWindowSize(int width, int height) { m_state.setWindowSize(width, height); }

void Controller::startScene(glm::dvec3 centre, double radius, std::string name, bool throughMap, std::string look,
                            std::optional<Orbit> home) {
    m_scene.emplace(centre, radius, m_options.foci, home);
    m_sceneName = std::move(name);
    m_sceneThroughMap = throughMap;
    m_sceneLook = std::move(look);
    m_display.mode = renderers::ViewMode::Raw;  // the CoNUS image itself: the paper's focus-plus-context display
    const glm::ivec2 size = sceneFrameSize();
    m_state.setImageSize(size.x, size.y);
    std::printf("conus-view: %s%s%s; H lists the keys\n", m_sceneName.c_str(), m_sceneLook.empty() ? "" : ", ",
                m_sceneLook.c_str());
    std::fflush(stdout);
}

void Controller::setLook(std::string look) {
    m_sceneLook = std::move(look);
    std::printf("conus-view: %s\n", m_sceneLook.c_str());
    std::fflush(stdout);
}

glm::ivec2 Controller::sceneFrameSize() const {
    if (m_options.width > 0 && m_options.height > 0) return {m_options.width, m_options.height};
    return {std::max(1, m_state.windowWidth()), std::max(1, m_state.windowHeight())};
}

void Controller::setSceneFrame(format::ConusFile frame) {
    m_sceneMap.emplace(codec::SamplingMap::fromGrid(frame.map));
    if (!m_sceneFrame || m_sceneFrame->image.width != frame.image.width || m_sceneFrame->image.height != frame.image.height)
        m_state.setImageSize(frame.image.width, frame.image.height);
    m_sceneFrame = std::move(frame);
    ++m_imageVersion;
    m_probe = probeAt(m_cursor);
}

std::string Controller::probeAt(glm::dvec2 pixel) const {
    const glm::dvec2 shown = m_state.windowToImage(pixel);
    if (m_scene) {
        if (!m_sceneFrame) return {};
        // Raw shows the CoNUS image itself: the cursor is at a distorted position.
        const glm::dvec2 uv = m_display.mode == renderers::ViewMode::Raw
                                  ? m_sceneMap->undistort(glm::clamp(shown, glm::dvec2(0.0), glm::dvec2(1.0)))
                                  : shown;
        return formatProbe(probe(*m_sceneFrame, *m_sceneMap, uv));
    }
    if (const Document* doc = current(); doc && doc->ok()) return formatProbe(probe(*doc->file, *doc->map, shown));
    return {};
}

void Controller::tick() {
    if (m_editor && !m_editor->stable()) {
        m_editor->step();
        ++m_mapVersion;
    }
}

std::optional<format::ConusFile> Controller::shownFile() const {
    if (m_editor) {
        format::ConusFile shown;
        shown.image = m_editor->source();
        shown.sourceWidth = shown.image.width;
        shown.sourceHeight = shown.image.height;
        shown.map = m_editor->map().toGrid();
        return shown;
    }
    if (m_scene) {
        if (!m_sceneFrame) return std::nullopt;
        return m_depthPicture && hasDepth(*m_sceneFrame) ? viewer::depthPicture(*m_sceneFrame) : *m_sceneFrame;
    }
    const Document* doc = current();
    if (doc && doc->ok()) return m_depthPicture && hasDepth(*doc->file) ? viewer::depthPicture(*doc->file) : *doc->file;
    return std::nullopt;
}

void Controller::cannotDisplay(const std::string& error) {
    Document* doc = currentDocument();
    if (!doc) return;
    doc->error = "cannot display: " + error;
    doc->file.reset();
    std::fprintf(stderr, "conus-view: %s: %s\n", doc->path.c_str(), doc->error.c_str());
    m_exitCode = 1;
}

void Controller::showDocument(int index, bool refit) {
    m_current = index;
    ++m_imageVersion;
    const Document& doc = m_docs[index];
    if (doc.ok() && refit) {
        m_state.setImageSize(doc.sourceWidth(), doc.sourceHeight());
        if (m_options.view) m_state.showView(*m_options.view);
    }
}

std::string Controller::summary(const char* separator) const {
    const std::string sep = separator;
    if (m_editor) {
        char line[160];
        std::snprintf(line, sizeof line, "[edit] %s | brush r %.3f strength %.2f | %d strokes%s", fileName(m_options.edit).c_str(),
                      m_editor->brush().radius, m_editor->brush().strength, m_editor->strokes(),
                      m_editor->stable() ? " | stable" : " | relaxing");
        return line + (m_editorMessage.empty() ? std::string() : " | " + m_editorMessage);
    }
    if (m_scene) {
        std::string text = m_sceneName + sep + (m_scene->conus() ? "CoNUS" : "conventional");
        if (m_sceneThroughMap && m_scene->conus())
            text += " (" + std::to_string(m_scene->foci().size()) + (m_scene->foci().size() == 1 ? " focus)" : " foci)");
        if (!m_sceneLook.empty()) text += sep + m_sceneLook;
        if (m_depthPicture) text += sep + kDepthPictureMode;
        return text + sep + enumName(m_display.mode);
    }
    const Document* doc = current();
    if (!doc) return {};
    std::string text = fileName(doc->path);
    if (m_docs.size() > 1) text += " [" + std::to_string(m_current + 1) + "/" + std::to_string(m_docs.size()) + "]";
    if (!doc->ok()) return text + sep + "ERROR: " + doc->error;
    char zoom[32];
    std::snprintf(zoom, sizeof zoom, "zoom %.3g", m_state.zoom());
    if (m_depthPicture && !hasDepth(*doc->file)) text += sep + "no Z channel";
    else if (m_depthPicture) text += sep + kDepthPictureMode;
    text += sep + enumName(m_display.mode) + sep + zoom;
    if (m_display.exposure != 0) text += sep + "ev " + std::to_string(m_display.exposure).substr(0, 4);
    if (m_display.toneMap != ToneMap::None) text += sep + enumName(m_display.toneMap);
    if (m_display.gamma == 1.0) text += sep + "linear";
    return text;
}

std::string Controller::title() const {
    std::string title = "conus-view";
    const std::string text = summary(" - ");
    if (m_editor) return title + " " + text;
    if (text.empty()) return title;
    title += " - " + text;
    if (!m_probe.empty() && ((current() && current()->ok()) || m_sceneFrame)) title += " - " + m_probe;
    return title;
}

std::string Controller::statusText() const {
    std::string text = summary(" | ");
    if (m_editor || ((!current() || !current()->ok()) && !m_sceneFrame)) return text;
    if (m_display.grid) text += " | grid";
    if (m_display.outlines) text += " | outlines";
    if (!m_probe.empty()) text += " | " + m_probe;
    return text;
}

std::string Controller::takeScreenshotRequest() {
    std::string path;
    std::swap(path, m_screenshot);
    return path;
}

void Controller::cursor(glm::dvec2 pixel) {
    const glm::dvec2 delta = pixel - m_cursor;
    m_cursor = pixel;
    if (m_panning) m_state.pan(delta);
    if (m_wiping) m_display.wipeX = std::clamp(pixel.x / m_state.windowWidth(), 0.0, 1.0);
    if (m_scene && m_draggedFocus >= 0) m_scene->moveFocus(m_draggedFocus, m_state.windowToImage(pixel));
    if (m_scene && m_orbiting) m_scene->rotate(-kOrbitDegreesPerPixel * delta.x, kOrbitDegreesPerPixel * delta.y);
    if (m_editor) m_editor->moveTo(m_state.windowToImage(pixel));
    else m_probe = probeAt(pixel);
}

void Controller::button(MouseButton button, bool press, Modifiers modifiers) {
    if (!press) {
        m_panning = m_wiping = m_orbiting = false;
        m_draggedFocus = -1;
        if (m_editor) m_editor->release();
        return;
    }
    if (m_scene) {
        // A press on a focus grabs it (a live map only); anywhere else the drag orbits.
        const glm::ivec2 size = sceneFrameSize();
        const int focus = m_sceneThroughMap && button == MouseButton::Left
                              ? m_scene->focusNear(m_state.windowToImage(m_cursor), double(size.x) / size.y)
                              : -1;
        if (focus >= 0) m_draggedFocus = focus;
        else m_orbiting = true;
    } else if (button == MouseButton::Left && m_editor && !modifiers.ctrl) {
        m_editor->press(m_state.windowToImage(m_cursor));  // undistorted: the source is shown undistorted
    } else if (button == MouseButton::Left && modifiers.shift && m_display.mode == renderers::ViewMode::Wipe) {
        m_wiping = true;
        m_display.wipeX = std::clamp(m_cursor.x / m_state.windowWidth(), 0.0, 1.0);
    } else {
        m_panning = true;  // left drag in the viewer; right / middle (or Ctrl-left) drag in the editor
    }
}

void Controller::scroll(double notches, bool shift) {
    if (m_scene) m_scene->dolly(std::pow(kWheelStep, -notches));
    else if (m_editor && shift) m_editor->scaleRadius(std::pow(kWheelStep, notches));
    else m_state.scroll(notches, m_cursor);
}

void Controller::saveFromEditor(bool mapOnly) {
    const std::filesystem::path base = m_options.output.empty() ? std::filesystem::path(m_options.edit).replace_extension("")
                                                                : std::filesystem::path(m_options.output);
    const std::string path = base.string() + (mapOnly ? ".map.exr" : ".conus.exr");
    try {
        const Image& source = m_editor->source();
        const int w = m_options.width > 0 ? m_options.width : source.width;
        const int h = m_options.height > 0 ? m_options.height : source.height;
        format::writeConusFile(path, mapOnly ? m_editor->mapFile() : m_editor->encode(w, h));
        m_editorMessage = "wrote " + path;
        std::printf("wrote %s\n", path.c_str());
    } catch (const std::exception& e) {
        m_editorMessage = std::string("ERROR: ") + e.what();
        std::fprintf(stderr, "conus-view: %s\n", aboutFile(path, e.what()).c_str());
    }
    std::fflush(stdout);
}

bool Controller::sceneAction(Action action) {
    const glm::ivec2 size = sceneFrameSize();
    const double aspect = double(size.x) / size.y;
    const glm::dvec2 at = m_state.windowToImage(m_cursor);
    switch (action) {
    case Action::OrbitLeft: m_scene->rotate(-kOrbitStepDegrees, 0); return true;
    case Action::OrbitRight: m_scene->rotate(kOrbitStepDegrees, 0); return true;
    case Action::OrbitUp: m_scene->rotate(0, kOrbitStepDegrees); return true;
    case Action::OrbitDown: m_scene->rotate(0, -kOrbitStepDegrees); return true;
    case Action::DollyIn: m_scene->dolly(1.0 / kDollyStep); return true;
    case Action::DollyOut: m_scene->dolly(kDollyStep); return true;
    case Action::HomeCamera: m_scene->home(); return true;
    case Action::ToggleConus: m_scene->toggleConus(); return true;
    case Action::AddFocus:
        if (m_sceneThroughMap && !m_scene->addFocus(at)) std::printf("conus-view: at most %d foci\n", kMaxSceneFoci);
        return true;
    case Action::RemoveFocus: if (m_sceneThroughMap) m_scene->removeFocusNear(at, aspect); return true;
    case Action::FocusSmaller: m_scene->scaleFocusRadius(1.0 / kStrengthStep); return true;
    case Action::FocusLarger: m_scene->scaleFocusRadius(kStrengthStep); return true;
    case Action::NextLook: ++m_lookRequests; return true;
    default: return false;
    }
}

void Controller::doAction(Action action) {
    if (m_scene && sceneAction(action)) return;
    const glm::dvec2 centre = 0.5 * glm::dvec2(m_state.windowWidth(), m_state.windowHeight());
    const glm::dvec2 panStep = kKeyPanFraction * glm::dvec2(m_state.windowWidth(), m_state.windowHeight());
    switch (action) {
    case Action::None: return;
    case Action::Help:
        m_showHelp = !m_showHelp;
        if (m_showHelp) {
            std::fputs(helpText(keyTable()).c_str(), stdout);
            std::fflush(stdout);
        }
        break;
    case Action::ToggleStatusBar: m_showStatus = !m_showStatus; break;
    case Action::Fit: m_state.fit(); break;
    case Action::SourceResolution: m_state.sourceResolution(); break;
    case Action::ZoomIn: m_state.zoomAbout(kKeyZoomStep, centre); break;
    case Action::ZoomOut: m_state.zoomAbout(1.0 / kKeyZoomStep, centre); break;
    // Arrows move the view over the image: the content moves the other way.
    case Action::PanLeft: m_state.pan({panStep.x, 0}); break;
    case Action::PanRight: m_state.pan({-panStep.x, 0}); break;
    case Action::PanUp: m_state.pan({0, panStep.y}); break;
    case Action::PanDown: m_state.pan({0, -panStep.y}); break;
    case Action::ModeReconstructed: m_display.mode = renderers::ViewMode::Reconstructed; break;
    case Action::ModeRaw: m_display.mode = renderers::ViewMode::Raw; break;
    case Action::ModeUniform: m_display.mode = renderers::ViewMode::Uniform; break;
    case Action::ModeWipe: m_display.mode = renderers::ViewMode::Wipe; break;
    case Action::ModeDensity:
        m_display.mode = m_display.mode == renderers::ViewMode::Density && editing() ? renderers::ViewMode::Raw : renderers::ViewMode::Density;
        break;
    case Action::ToggleDepth:
        m_depthPicture = !m_depthPicture;
        ++m_imageVersion;
        break;
    case Action::ToggleGrid: m_display.grid = !m_display.grid; break;
    case Action::ToggleOutlines: m_display.outlines = !m_display.outlines; break;
    case Action::ExposureUp: m_display.exposure += kExposureStep; break;
    case Action::ExposureDown: m_display.exposure -= kExposureStep; break;
    case Action::ResetExposure: m_display.exposure = 0; break;
    case Action::ToggleGamma: m_display.gamma = m_display.gamma == 1.0 ? 0.0 : 1.0; break;
    case Action::NextToneMap: m_display.toneMap = nextToneMap(m_display.toneMap); break;
    case Action::NextFile:
    case Action::PreviousFile:
        if (m_docs.size() > 1) {
            const int n = static_cast<int>(m_docs.size());
            showDocument((m_current + (action == Action::NextFile ? 1 : n - 1)) % n, true);
        }
        break;
    case Action::Reload:
        if (Document* doc = currentDocument()) {
            const int w = doc->sourceWidth(), h = doc->sourceHeight();
            *doc = loadDocument(doc->path, m_options.foci);
            if (!doc->ok()) std::fprintf(stderr, "conus-view: %s: %s\n", doc->path.c_str(), doc->error.c_str());
            else std::printf("reloaded %s\n", doc->path.c_str());
            showDocument(m_current, doc->sourceWidth() != w || doc->sourceHeight() != h);
        }
        break;
    case Action::Inspect:
        if (const std::string line = probeAt(m_cursor); !line.empty()) std::printf("%s\n", line.c_str());
        std::fflush(stdout);
        break;
    case Action::Quit: m_quit = true; break;
    case Action::StrengthDown: if (m_editor) m_editor->scaleStrength(1.0 / kStrengthStep); break;
    case Action::StrengthUp: if (m_editor) m_editor->scaleStrength(kStrengthStep); break;
    case Action::ResetMap:
        if (m_editor) {
            m_editor->reset();
            ++m_mapVersion;
        }
        break;
    case Action::SaveMap:
    case Action::EncodeImage:
        if (m_editor) saveFromEditor(action == Action::SaveMap);
        break;
    // The 3-D modes' own (sceneAction); nothing outside them.
    case Action::OrbitLeft: case Action::OrbitRight: case Action::OrbitUp: case Action::OrbitDown:
    case Action::DollyIn: case Action::DollyOut: case Action::HomeCamera: case Action::ToggleConus:
    case Action::AddFocus: case Action::RemoveFocus: case Action::FocusSmaller: case Action::FocusLarger:
    case Action::NextLook:
        break;
    }
}

void Controller::run(const ScriptCommand& c) {
    const auto& n = c.numbers;
    const glm::dvec2 centre = 0.5 * glm::dvec2(m_state.windowWidth(), m_state.windowHeight());
    if (c.name == "zoom") {
        m_state.zoomAbout(n[0], n.size() == 3 ? glm::dvec2(n[1], n[2]) : centre);
    } else if (c.name == "wheel") {
        cursor({n[1], n[2]});
        scroll(n[0], false);
    } else if (c.name == "pan") {
        m_state.pan({n[0], n[1]});
    } else if (c.name == "drag") {
        cursor({n[0], n[1]});
        button(MouseButton::Left, true, {});
        constexpr int kSteps = 16;
        for (int k = 1; k <= kSteps; ++k) cursor(glm::mix(glm::dvec2(n[0], n[1]), glm::dvec2(n[2], n[3]), double(k) / kSteps));
        button(MouseButton::Left, false, {});
    } else if (c.name == "mouse") {
        cursor({n[0], n[1]});
    } else if (c.name == "key") {
        key(*parseChord(c.text));
    } else if (c.name == "inspect") {
        if (const std::string line = probeAt({n[0], n[1]}); !line.empty()) std::printf("%s\n", line.c_str());
        else if (const Document* bad = current()) std::printf("error: %s\n", bad->error.c_str());
        std::fflush(stdout);
    } else if (c.name == "wait") {
        m_waitFrames = static_cast<int>(n[0]);
    } else if (c.name == "screenshot") {
        m_screenshot = c.text;
    } else if (c.name == "orbit") {
        if (m_scene) m_scene->rotate(n[0], n[1]);
    } else if (c.name == "dolly") {
        if (m_scene) m_scene->dolly(n[0]);
    } else if (c.name == "quit") {
        m_quit = true;
    }
}

}  // namespace conus::viewer
