#include "controller.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "conus/imageio/image_file.h"
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
    : m_options(options), m_display(options.display), m_showHelp(options.helpOverlay), m_showStatus(options.statusBar) {}

bool Controller::load() {
    if (!m_options.edit.empty()) {
        try {
            imageio::ImageFile source = imageio::readImageFile(m_options.edit);
            m_editor.emplace(std::move(source.image), source.info.encoding);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "conus-view: %s: %s\n", m_options.edit.c_str(), e.what());
            return false;
        }
        // The source, shown raw (it is undistorted), with the live map's grid over it.
        m_state.setImageSize(m_editor->source().width, m_editor->source().height);
        m_display.mode = gl::ViewMode::Raw;
        m_display.grid = true;
        if (m_display.gridEvery == 0) m_display.gridEvery = std::max(1, m_editor->source().width / 64);
        ++m_imageVersion;
        std::printf("conus-view --edit %s: paint with the left button; H lists the keys\n", m_options.edit.c_str());
        return true;
    }
    for (const std::string& path : m_options.files) {
        m_docs.push_back(loadDocument(path));
        if (!m_docs.back().ok()) {
            std::fprintf(stderr, "conus-view: %s: %s\n", path.c_str(), m_docs.back().error.c_str());
            m_exitCode = 1;
        }
    }
    showDocument(0, true);
    std::printf("conus-view: %zu file(s); H lists the keys\n", m_docs.size());
    return true;
}

void Controller::setWindowSize(int width, int height) { m_state.setWindowSize(width, height); }

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
    const Document* doc = current();
    if (doc && doc->ok()) return *doc->file;
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
    const Document* doc = current();
    if (!doc) return {};
    std::string text = fileName(doc->path);
    if (m_docs.size() > 1) text += " [" + std::to_string(m_current + 1) + "/" + std::to_string(m_docs.size()) + "]";
    if (!doc->ok()) return text + sep + "ERROR: " + doc->error;
    char zoom[32];
    std::snprintf(zoom, sizeof zoom, "zoom %.3g", m_state.zoom());
    text += sep + modeName(m_display.mode) + sep + zoom;
    if (m_display.exposure != 0) text += sep + "ev " + std::to_string(m_display.exposure).substr(0, 4);
    if (m_display.toneMap != ToneMap::None) text += sep + toString(m_display.toneMap);
    if (m_display.gamma == 1.0) text += sep + "linear";
    return text;
}

std::string Controller::title() const {
    std::string title = "conus-view";
    const std::string text = summary(" - ");
    if (m_editor) return title + " " + text;
    if (text.empty()) return title;
    title += " - " + text;
    if (!m_probe.empty() && current() && current()->ok()) title += " - " + m_probe;
    return title;
}

std::string Controller::statusText() const {
    std::string text = summary(" | ");
    if (m_editor || !current() || !current()->ok()) return text;
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
    if (m_editor) {
        m_editor->moveTo(m_state.windowToImage(pixel));
    } else if (const Document* doc = current(); doc && doc->ok()) {
        m_probe = formatProbe(probe(*doc->file, *doc->map, m_state.windowToImage(pixel)));
    }
}

void Controller::button(MouseButton button, bool press, Modifiers modifiers) {
    if (!press) {
        m_panning = m_wiping = false;
        if (m_editor) m_editor->release();
        return;
    }
    if (button == MouseButton::Left && m_editor && !modifiers.ctrl) {
        m_editor->press(m_state.windowToImage(m_cursor));  // undistorted: the source is shown undistorted
    } else if (button == MouseButton::Left && modifiers.shift && m_display.mode == gl::ViewMode::Wipe) {
        m_wiping = true;
        m_display.wipeX = std::clamp(m_cursor.x / m_state.windowWidth(), 0.0, 1.0);
    } else {
        m_panning = true;  // left drag in the viewer; right / middle (or Ctrl-left) drag in the editor
    }
}

void Controller::scroll(double notches, bool shift) {
    if (m_editor && shift) m_editor->scaleRadius(std::pow(kWheelStep, notches));
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
        std::fprintf(stderr, "conus-view: %s: %s\n", path.c_str(), e.what());
    }
    std::fflush(stdout);
}

void Controller::doAction(Action action) {
    const glm::dvec2 centre = 0.5 * glm::dvec2(m_state.windowWidth(), m_state.windowHeight());
    const glm::dvec2 panStep = kKeyPanFraction * glm::dvec2(m_state.windowWidth(), m_state.windowHeight());
    switch (action) {
    case Action::None: return;
    case Action::Help:
        m_showHelp = !m_showHelp;
        if (m_showHelp) {
            std::fputs(helpText(editing()).c_str(), stdout);
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
    case Action::ModeReconstructed: m_display.mode = gl::ViewMode::Reconstructed; break;
    case Action::ModeRaw: m_display.mode = gl::ViewMode::Raw; break;
    case Action::ModeUniform: m_display.mode = gl::ViewMode::Uniform; break;
    case Action::ModeWipe: m_display.mode = gl::ViewMode::Wipe; break;
    case Action::ModeDensity:
        m_display.mode = m_display.mode == gl::ViewMode::Density && editing() ? gl::ViewMode::Raw : gl::ViewMode::Density;
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
            *doc = loadDocument(doc->path);
            if (!doc->ok()) std::fprintf(stderr, "conus-view: %s: %s\n", doc->path.c_str(), doc->error.c_str());
            else std::printf("reloaded %s\n", doc->path.c_str());
            showDocument(m_current, doc->sourceWidth() != w || doc->sourceHeight() != h);
        }
        break;
    case Action::Inspect:
        if (const Document* doc = current(); doc && doc->ok())
            std::printf("%s\n", formatProbe(probe(*doc->file, *doc->map, m_state.windowToImage(m_cursor))).c_str());
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
        if (const Document* doc = current(); doc && doc->ok())
            std::printf("%s\n", formatProbe(probe(*doc->file, *doc->map, m_state.windowToImage({n[0], n[1]}))).c_str());
        else if (const Document* bad = current()) std::printf("error: %s\n", bad->error.c_str());
        std::fflush(stdout);
    } else if (c.name == "wait") {
        m_waitFrames = static_cast<int>(n[0]);
    } else if (c.name == "screenshot") {
        m_screenshot = c.text;
    } else if (c.name == "quit") {
        m_quit = true;
    }
}

}  // namespace conus::viewer
