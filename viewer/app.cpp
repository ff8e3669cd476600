#include "app.h"

#include <GLFW/glfw3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "actions.h"
#include "conus/format/container.h"
#include "conus/renderers/view_renderer.h"
#include "document.h"
#include "editor.h"
#include "conus/imageio/image_file.h"
#include "inspector.h"
#include "overlay.h"
#include "script.h"
#include "view_state.h"

namespace conus::viewer {
namespace {

constexpr double kExposureStep = 0.5;
constexpr double kStrengthStep = 1.25;
constexpr int kBenchmarkWarmup = 3;

// GLFW key + modifiers -> the key table's chord; nullopt for keys the table does not name.
std::optional<KeyChord> chordOf(int key, int mods) {
    KeyChord chord;
    chord.shift = (mods & GLFW_MOD_SHIFT) != 0;
    chord.ctrl = (mods & GLFW_MOD_CONTROL) != 0;
    if (key >= GLFW_KEY_A && key <= GLFW_KEY_Z) chord.key = std::string(1, char('A' + key - GLFW_KEY_A));
    else if (key >= GLFW_KEY_0 && key <= GLFW_KEY_9) chord.key = std::string(1, char('0' + key - GLFW_KEY_0));
    else if (key == GLFW_KEY_EQUAL && chord.shift) { chord.key = "+"; chord.shift = false; }
    else if (key == GLFW_KEY_EQUAL) chord.key = "=";
    else if (key == GLFW_KEY_KP_ADD) chord.key = "+";
    else if (key == GLFW_KEY_MINUS || key == GLFW_KEY_KP_SUBTRACT) chord.key = "-";
    else if (key == GLFW_KEY_LEFT_BRACKET) chord.key = "[";
    else if (key == GLFW_KEY_RIGHT_BRACKET) chord.key = "]";
    else if (key == GLFW_KEY_TAB) chord.key = "Tab";
    else if (key == GLFW_KEY_F5) chord.key = "F5";
    else if (key == GLFW_KEY_LEFT) chord.key = "Left";
    else if (key == GLFW_KEY_RIGHT) chord.key = "Right";
    else if (key == GLFW_KEY_UP) chord.key = "Up";
    else if (key == GLFW_KEY_DOWN) chord.key = "Down";
    else if (key == GLFW_KEY_PAGE_UP) chord.key = "PageUp";
    else if (key == GLFW_KEY_PAGE_DOWN) chord.key = "PageDown";
    else if (key == GLFW_KEY_ESCAPE) chord.key = "Escape";
    else return std::nullopt;
    return chord;
}

std::string fileName(const std::string& path) { return std::filesystem::path(path).filename().string(); }

class App {
public:
    explicit App(const Options& options)
        : m_options(options), m_display(options.display), m_showHelp(options.helpOverlay), m_showStatus(options.statusBar) {}
    ~App() {
        // The renderer and its adopted Context delete GL objects: the window's context must live.
        m_renderer.reset();
        m_context.reset();
        if (m_window) glfwDestroyWindow(m_window);
        glfwTerminate();
    }

    int run();

private:
    bool openWindow();
    bool loadInputs();
    void showDocument(int index, bool refit);
    void doAction(Action action);
    void runScriptCommand(const ScriptCommand& command);
    void frame();
    int benchmark();
    void updateTitle();
    std::string statusText() const;
    void drawOverlays(int width, int height);
    // Uploads `make()`'s panel into `slot` when `key` (what the panel shows) has changed.
    template <class Make>
    bool prepareOverlay(int slot, const std::string& key, Make make);

    // Input, shared by GLFW's callbacks and the script.
    void onCursor(glm::dvec2 pixel);
    void onButton(int button, bool press, int mods);
    void onScroll(double notches, bool shift);
    void onKey(const KeyChord& chord) { doAction(actionFor(chord, m_editor.has_value())); }

    bool editing() const { return m_editor.has_value(); }
    Document* current() { return m_docs.empty() ? nullptr : &m_docs[m_current]; }
    glm::dvec2 framebufferScale() const;

    const Options& m_options;
    GLFWwindow* m_window = nullptr;
    std::unique_ptr<gl::Context> m_context;
    std::unique_ptr<gl::ViewRenderer> m_renderer;
    std::vector<Document> m_docs;
    int m_current = 0;
    std::optional<MapEditor> m_editor;
    std::string m_editorMessage;
    ViewState m_state;
    gl::ViewOptions m_display;
    glm::dvec2 m_cursor{0.0};
    bool m_panning = false, m_wiping = false;
    std::string m_probe;
    std::vector<ScriptCommand> m_script;
    std::size_t m_scriptNext = 0;
    int m_waitFrames = 0;
    std::string m_pendingScreenshot;
    int m_exitCode = 0;
    bool m_showHelp = false, m_showStatus = false;
    std::string m_overlayKey[gl::ViewRenderer::kOverlaySlots];
    int m_overlayHeight[gl::ViewRenderer::kOverlaySlots] = {};
    bool m_textBroken = false;  // the font could not be drawn: overlays off, said once on stderr
};

// GLFW calls back with the window's user pointer; everything forwards to App.
App& appOf(GLFWwindow* window) { return *static_cast<App*>(glfwGetWindowUserPointer(window)); }

glm::dvec2 App::framebufferScale() const {
    int ww = 1, wh = 1, fw = 1, fh = 1;
    glfwGetWindowSize(m_window, &ww, &wh);
    glfwGetFramebufferSize(m_window, &fw, &fh);
    return {double(fw) / std::max(ww, 1), double(fh) / std::max(wh, 1)};
}

bool App::openWindow() {
    glfwSetErrorCallback([](int, const char* text) { std::fprintf(stderr, "conus-view: GLFW: %s\n", text); });
    if (!glfwInit()) {
        std::fprintf(stderr, "conus-view: cannot open a window (no display? run under xvfb-run, or use --screenshot)\n");
        return false;
    }
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    m_window = glfwCreateWindow(m_options.windowWidth, m_options.windowHeight, "conus-view", nullptr, nullptr);
    if (!m_window) {
        std::fprintf(stderr, "conus-view: cannot create a GL 4.5 core window\n");
        return false;
    }
    glfwMakeContextCurrent(m_window);
    // Scripts and benchmarks run flat out; people get vsync.
    glfwSwapInterval(m_options.script.empty() && m_options.benchmarkFrames == 0 ? 1 : 0);
    glfwSetWindowUserPointer(m_window, this);
    glfwSetCursorPosCallback(m_window, [](GLFWwindow* w, double x, double y) {
        App& app = appOf(w);
        app.onCursor(glm::dvec2(x, y) * app.framebufferScale());
    });
    glfwSetMouseButtonCallback(m_window, [](GLFWwindow* w, int button, int action, int mods) {
        appOf(w).onButton(button, action == GLFW_PRESS, mods);
    });
    glfwSetScrollCallback(m_window, [](GLFWwindow* w, double, double dy) {
        appOf(w).onScroll(dy, glfwGetKey(w, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS ||
                                  glfwGetKey(w, GLFW_KEY_RIGHT_SHIFT) == GLFW_PRESS);
    });
    glfwSetKeyCallback(m_window, [](GLFWwindow* w, int key, int, int action, int mods) {
        if (action == GLFW_RELEASE) return;
        if (const auto chord = chordOf(key, mods)) appOf(w).onKey(*chord);
    });
    try {
        m_context = gl::adoptCurrentContext(glfwGetProcAddress);
        m_renderer = std::make_unique<gl::ViewRenderer>(*m_context);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "conus-view: %s\n", e.what());
        return false;
    }
    int fw = 0, fh = 0;
    glfwGetFramebufferSize(m_window, &fw, &fh);
    m_state.setWindowSize(fw, fh);
    return true;
}

bool App::loadInputs() {
    if (!m_options.edit.empty()) {
        try {
            imageio::ImageFile source = imageio::readImageFile(m_options.edit);
            m_editor.emplace(std::move(source.image), source.info.encoding);
            format::ConusFile shown;  // the source, shown raw, with the live map's grid over it
            shown.image = m_editor->source();
            shown.sourceWidth = shown.image.width;
            shown.sourceHeight = shown.image.height;
            shown.map = m_editor->map().toGrid();
            m_renderer->setImage(shown);
            m_state.setImageSize(shown.image.width, shown.image.height);
            m_display.mode = gl::ViewMode::Raw;
            m_display.grid = true;
            if (m_display.gridEvery == 0) m_display.gridEvery = std::max(1, shown.image.width / 64);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "conus-view: %s: %s\n", m_options.edit.c_str(), e.what());
            return false;
        }
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

void App::showDocument(int index, bool refit) {
    m_current = index;
    Document& doc = m_docs[index];
    if (doc.ok()) {
        try {
            m_renderer->setImage(*doc.file);
        } catch (const std::exception& e) {
            doc.error = std::string("cannot display: ") + e.what();
            doc.file.reset();
            std::fprintf(stderr, "conus-view: %s: %s\n", doc.path.c_str(), doc.error.c_str());
            m_exitCode = 1;
        }
    }
    if (doc.ok() && refit) {
        m_state.setImageSize(doc.sourceWidth(), doc.sourceHeight());
        if (m_options.view) m_state.showView(*m_options.view);
    }
    updateTitle();
}

void App::updateTitle() {
    std::string title = "conus-view";
    if (editing()) {
        char text[160];
        std::snprintf(text, sizeof text, " [edit] %s | brush r %.3f strength %.2f | %d strokes%s", fileName(m_options.edit).c_str(),
                      m_editor->brush().radius, m_editor->brush().strength, m_editor->strokes(),
                      m_editor->stable() ? " | stable" : " | relaxing");
        title += text;
        if (!m_editorMessage.empty()) title += " | " + m_editorMessage;
    } else if (Document* doc = current()) {
        title += " - " + fileName(doc->path);
        if (m_docs.size() > 1) title += " [" + std::to_string(m_current + 1) + "/" + std::to_string(m_docs.size()) + "]";
        if (!doc->ok()) {
            title += " - ERROR: " + doc->error;
        } else {
            char text[96];
            std::snprintf(text, sizeof text, " - %s - zoom %.3g%s%s", modeName(m_display.mode), m_state.zoom(),
                          m_display.exposure != 0 ? (" ev " + std::to_string(m_display.exposure).substr(0, 4)).c_str() : "",
                          m_display.gamma == 1.0 ? " linear" : "");
            title += text;
            if (!m_probe.empty()) title += " - " + m_probe;
        }
    }
    glfwSetWindowTitle(m_window, title.c_str());
}

std::string App::statusText() const {
    std::string text;
    if (editing()) {
        char line[160];
        std::snprintf(line, sizeof line, "[edit] %s | brush r %.3f strength %.2f | %d strokes%s", fileName(m_options.edit).c_str(),
                      m_editor->brush().radius, m_editor->brush().strength, m_editor->strokes(),
                      m_editor->stable() ? " | stable" : " | relaxing");
        text = line;
        if (!m_editorMessage.empty()) text += " | " + m_editorMessage;
        return text;
    }
    if (m_docs.empty()) return text;
    const Document& doc = m_docs[m_current];
    text = fileName(doc.path);
    if (m_docs.size() > 1) text += " [" + std::to_string(m_current + 1) + "/" + std::to_string(m_docs.size()) + "]";
    if (!doc.ok()) return text + " | ERROR: " + doc.error;
    char line[96];
    std::snprintf(line, sizeof line, " | %s | zoom %.3g%s%s%s%s", modeName(m_display.mode), m_state.zoom(),
                  m_display.exposure != 0 ? (" | ev " + std::to_string(m_display.exposure).substr(0, 4)).c_str() : "",
                  m_display.gamma == 1.0 ? " | linear" : "", m_display.grid ? " | grid" : "", m_display.outlines ? " | outlines" : "");
    text += line;
    if (!m_probe.empty()) text += " | " + m_probe;
    return text;
}

template <class Make>
bool App::prepareOverlay(int slot, const std::string& key, Make make) {
    if (m_textBroken) return false;
    if (m_overlayKey[slot] == key && m_renderer->hasOverlay(slot)) return true;
    try {
        const format::Image panel = make();
        m_renderer->setOverlay(slot, panel);
        m_overlayKey[slot] = key;
        m_overlayHeight[slot] = panel.height;
        return true;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "conus-view: no text in the window: %s\n", e.what());
        m_textBroken = true;
        return false;
    }
}

void App::drawOverlays(int fw, int fh) {
    const Document* doc = current();
    if (!editing() && doc && !doc->ok()) {
        const std::string name = fileName(doc->path);
        if (prepareOverlay(kErrorSlot, name + "\n" + doc->error + "\n" + std::to_string(fw),
                           [&] { return errorPanel(name, doc->error, fw); }))
            m_renderer->drawOverlay(kErrorSlot, kOverlayMargin, kOverlayMargin, fw, fh);
    }
    if (m_showStatus) {
        const std::string text = statusText();
        if (prepareOverlay(kStatusSlot, text + "\n" + std::to_string(fw), [&] { return statusPanel(text, fw); }))
            m_renderer->drawOverlay(kStatusSlot, 0, fh - m_overlayHeight[kStatusSlot], fw, fh);
    }
    if (m_showHelp && prepareOverlay(kHelpSlot, editing() ? "edit" : "view", [&] { return helpPanel(editing()); }))
        m_renderer->drawOverlay(kHelpSlot, kOverlayMargin, kOverlayMargin, fw, fh);
}

void App::onCursor(glm::dvec2 pixel) {
    const glm::dvec2 delta = pixel - m_cursor;
    m_cursor = pixel;
    if (m_panning) m_state.pan(delta);
    if (m_wiping) m_display.wipeX = std::clamp(pixel.x / m_state.windowWidth(), 0.0, 1.0);
    if (editing()) {
        m_editor->moveTo(m_state.windowToImage(pixel));
    } else if (Document* doc = current(); doc && doc->ok()) {
        m_probe = formatProbe(probe(*doc->file, *doc->map, m_state.windowToImage(pixel)));
    }
    updateTitle();
}

void App::onButton(int button, bool press, int mods) {
    if (!press) {
        m_panning = m_wiping = false;
        if (editing()) m_editor->release();
        return;
    }
    if (button == GLFW_MOUSE_BUTTON_LEFT && editing() && !(mods & GLFW_MOD_CONTROL)) {
        m_editor->press(m_state.windowToImage(m_cursor));  // undistorted: the source is shown undistorted
    } else if (button == GLFW_MOUSE_BUTTON_LEFT && (mods & GLFW_MOD_SHIFT) && m_display.mode == gl::ViewMode::Wipe) {
        m_wiping = true;
        m_display.wipeX = std::clamp(m_cursor.x / m_state.windowWidth(), 0.0, 1.0);
    } else {
        m_panning = true;  // left drag in the viewer; right / middle (or Ctrl-left) drag in the editor
    }
    updateTitle();
}

void App::onScroll(double notches, bool shift) {
    if (editing() && shift) m_editor->scaleRadius(std::pow(kWheelStep, notches));
    else m_state.scroll(notches, m_cursor);
    updateTitle();
}

void App::doAction(Action action) {
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
    case Action::ModeDensity: m_display.mode = m_display.mode == gl::ViewMode::Density && editing() ? gl::ViewMode::Raw : gl::ViewMode::Density; break;
    case Action::ToggleGrid: m_display.grid = !m_display.grid; break;
    case Action::ToggleOutlines: m_display.outlines = !m_display.outlines; break;
    case Action::ExposureUp: m_display.exposure += kExposureStep; break;
    case Action::ExposureDown: m_display.exposure -= kExposureStep; break;
    case Action::ResetExposure: m_display.exposure = 0; break;
    case Action::ToggleGamma: m_display.gamma = m_display.gamma == 1.0 ? 0.0 : 1.0; break;
    case Action::NextToneMap:
        m_display.toneMap = m_display.toneMap == ToneMap::None       ? ToneMap::Reinhard
                            : m_display.toneMap == ToneMap::Reinhard ? ToneMap::Aces
                                                                     : ToneMap::None;
        break;
    case Action::NextFile:
    case Action::PreviousFile:
        if (m_docs.size() > 1) {
            const int n = static_cast<int>(m_docs.size());
            showDocument((m_current + (action == Action::NextFile ? 1 : n - 1)) % n, true);
        }
        break;
    case Action::Reload:
        if (Document* doc = current()) {
            const int w = doc->sourceWidth(), h = doc->sourceHeight();
            *doc = loadDocument(doc->path);
            if (!doc->ok()) std::fprintf(stderr, "conus-view: %s: %s\n", doc->path.c_str(), doc->error.c_str());
            else std::printf("reloaded %s\n", doc->path.c_str());
            showDocument(m_current, doc->sourceWidth() != w || doc->sourceHeight() != h);
        }
        break;
    case Action::Inspect:
        if (Document* doc = current(); doc && doc->ok())
            std::printf("%s\n", formatProbe(probe(*doc->file, *doc->map, m_state.windowToImage(m_cursor))).c_str());
        std::fflush(stdout);
        break;
    case Action::Quit: glfwSetWindowShouldClose(m_window, GLFW_TRUE); break;
    case Action::StrengthDown: if (editing()) m_editor->scaleStrength(1.0 / kStrengthStep); break;
    case Action::StrengthUp: if (editing()) m_editor->scaleStrength(kStrengthStep); break;
    case Action::ResetMap: if (editing()) m_editor->reset(); break;
    case Action::SaveMap:
    case Action::EncodeImage:
        if (editing()) {
            const std::filesystem::path base = m_options.output.empty()
                                                   ? std::filesystem::path(m_options.edit).replace_extension("")
                                                   : std::filesystem::path(m_options.output);
            const bool save = action == Action::SaveMap;
            const std::string path = base.string() + (save ? ".map.exr" : ".conus.exr");
            try {
                const format::Image& source = m_editor->source();
                const int w = m_options.width > 0 ? m_options.width : source.width;
                const int h = m_options.height > 0 ? m_options.height : source.height;
                format::writeConusFile(path, save ? m_editor->mapFile() : m_editor->encode(w, h));
                m_editorMessage = "wrote " + path;
                std::printf("wrote %s\n", path.c_str());
            } catch (const std::exception& e) {
                m_editorMessage = std::string("ERROR: ") + e.what();
                std::fprintf(stderr, "conus-view: %s: %s\n", path.c_str(), e.what());
            }
            std::fflush(stdout);
        }
        break;
    }
    updateTitle();
}

void App::runScriptCommand(const ScriptCommand& c) {
    const auto& n = c.numbers;
    const glm::dvec2 centre = 0.5 * glm::dvec2(m_state.windowWidth(), m_state.windowHeight());
    if (c.name == "zoom") {
        m_state.zoomAbout(n[0], n.size() == 3 ? glm::dvec2(n[1], n[2]) : centre);
    } else if (c.name == "wheel") {
        onCursor({n[1], n[2]});
        onScroll(n[0], false);
    } else if (c.name == "pan") {
        m_state.pan({n[0], n[1]});
    } else if (c.name == "drag") {
        onCursor({n[0], n[1]});
        onButton(GLFW_MOUSE_BUTTON_LEFT, true, 0);
        constexpr int kSteps = 16;
        for (int k = 1; k <= kSteps; ++k)
            onCursor(glm::mix(glm::dvec2(n[0], n[1]), glm::dvec2(n[2], n[3]), double(k) / kSteps));
        onButton(GLFW_MOUSE_BUTTON_LEFT, false, 0);
    } else if (c.name == "mouse") {
        onCursor({n[0], n[1]});
    } else if (c.name == "key") {
        onKey(*parseChord(c.text));
    } else if (c.name == "inspect") {
        if (Document* doc = current(); doc && doc->ok())
            std::printf("%s\n", formatProbe(probe(*doc->file, *doc->map, m_state.windowToImage({n[0], n[1]}))).c_str());
        else if (Document* bad = current()) std::printf("error: %s\n", bad->error.c_str());
        std::fflush(stdout);
    } else if (c.name == "wait") {
        m_waitFrames = static_cast<int>(n[0]);
    } else if (c.name == "screenshot") {
        m_pendingScreenshot = c.text;
    } else if (c.name == "quit") {
        m_scriptNext = m_script.size();
        glfwSetWindowShouldClose(m_window, GLFW_TRUE);
    }
    updateTitle();
}

void App::frame() {
    int fw = 0, fh = 0;
    glfwGetFramebufferSize(m_window, &fw, &fh);
    m_state.setWindowSize(fw, fh);
    if (editing()) {
        if (!m_editor->stable()) {
            m_editor->step();
            m_renderer->setMap(m_editor->map());
            updateTitle();
        }
    }
    const Document* doc = current();
    if (doc && !doc->ok()) {
        // The window turns dark red with the error written over it (also in the title and on stderr).
        m_renderer->clear(fw, fh, 0.35f, 0.05f, 0.05f);
    } else {
        m_renderer->draw(m_state.view(), fw, fh, m_display);
    }
    drawOverlays(fw, fh);
    if (!m_pendingScreenshot.empty()) {
        // The back buffer, before the swap (the front buffer reads as zeros under Xvfb).
        try {
            imageio::WriteOptions write;
            write.meaning = imageio::PixelMeaning::Display;  // the framebuffer: already what the screen shows
            imageio::writeImageFile(m_pendingScreenshot, m_renderer->readFramebuffer(fw, fh), write);
            std::printf("wrote %s\n", m_pendingScreenshot.c_str());
        } catch (const std::exception& e) {
            std::fprintf(stderr, "conus-view: %s\n", e.what());
            m_exitCode = std::max(m_exitCode, 1);
        }
        std::fflush(stdout);
        m_pendingScreenshot.clear();
    }
    glfwSwapBuffers(m_window);
}

int App::benchmark() {
    int fw = 0, fh = 0;
    glfwGetFramebufferSize(m_window, &fw, &fh);
    // --script with --benchmark-frames: the commands set up the view (a key, a zoom), then the timing.
    for (const ScriptCommand& command : m_script) {
        if (command.name == "quit") break;
        runScriptCommand(command);
        frame();
    }
    for (int k = 0; k < kBenchmarkWarmup; ++k) frame();
    m_renderer->finish();
    const auto start = std::chrono::steady_clock::now();
    double drawSeconds = 0;
    for (int k = 0; k < m_options.benchmarkFrames; ++k) {
        // A new view every frame (a one-pixel pan back and forth): each frame is decoded afresh.
        m_state.pan({k % 2 ? -1.0 : 1.0, 0.0});
        // The draw alone (finished), then the whole frame with the swap.
        const auto drawStart = std::chrono::steady_clock::now();
        m_renderer->draw(m_state.view(), fw, fh, m_display);
        m_renderer->finish();
        drawSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - drawStart).count();
        glfwSwapBuffers(m_window);
        glfwPollEvents();
    }
    m_renderer->finish();
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("benchmark: draw %.1f ms/frame, present (swap to the X server) %.1f ms/frame\n",
                1000.0 * drawSeconds / std::max(1, m_options.benchmarkFrames),
                1000.0 * (seconds - drawSeconds) / std::max(1, m_options.benchmarkFrames));
    const Document* doc = current();
    std::printf("benchmark: %d frames at %dx%d (%s, %dx%d CoNUS image, %s mode, %s decode): %.2f frames/s, %.1f ms/frame; %s\n",
                m_options.benchmarkFrames, fw, fh, doc ? fileName(doc->path).c_str() : "-",
                doc && doc->ok() ? doc->file->image.width : 0, doc && doc->ok() ? doc->file->image.height : 0,
                modeName(m_display.mode), m_renderer->decodesOnCpu(m_display) ? "CPU" : "GPU", m_options.benchmarkFrames / seconds,
                1000.0 * seconds / std::max(1, m_options.benchmarkFrames), m_context->renderer().c_str());
    return m_exitCode;
}

int App::run() {
    if (!m_options.script.empty()) {
        try {
            m_script = readScript(m_options.script);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "conus-view: %s\n", e.what());
            return 2;
        }
    }
    if (!openWindow()) return 1;
    if (!loadInputs()) return 1;
    if (m_options.benchmarkFrames > 0) return benchmark();
    const bool scripted = !m_options.script.empty();
    while (!glfwWindowShouldClose(m_window)) {
        const bool busy = scripted || (editing() && !m_editor->stable());
        if (busy) glfwPollEvents();
        else glfwWaitEventsTimeout(0.5);  // idle: no frames burnt
        if (scripted) {
            if (m_waitFrames > 0) {
                --m_waitFrames;
            } else if (m_scriptNext < m_script.size()) {
                runScriptCommand(m_script[m_scriptNext++]);
            } else {
                frame();  // the last command's frame has been shown; one more, then leave
                break;
            }
        }
        frame();
    }
    return m_exitCode;
}

}  // namespace

int runWindow(const Options& options) {
    App app(options);
    return app.run();
}

}  // namespace conus::viewer
