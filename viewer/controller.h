// What conus-view's input does, without GLFW or GL: the open documents, the map editor, the
// navigation state, the display options, the pixel inspector, and the requests of keys and
// scripts (screenshot, wait, quit). The window feeds it events (window.h's InputSink); the drawing
// (drawing.h) reads it to draw a frame; app.cpp runs the loop between them.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "actions.h"
#include "conus/renderers/view_renderer.h"
#include "document.h"
#include "editor.h"
#include "options.h"
#include "script.h"
#include "view_state.h"
#include "input.h"

namespace conus::viewer {

class Controller final : public InputSink {
public:
    explicit Controller(const Options& options);

    // Opens the files (errors become documents that show them) or the editor's image. False,
    // with the reason on stderr, when the editor's image cannot be read.
    bool load();
    void setWindowSize(int width, int height);
    // Once per frame: the editor's solver relaxes the map.
    void tick();

    void cursor(glm::dvec2 pixel) override;
    void button(MouseButton button, bool press, Modifiers modifiers) override;
    void scroll(double notches, bool shift) override;
    void key(const KeyChord& chord) override { doAction(actionFor(chord, editing())); }
    void doAction(Action action);
    void run(const ScriptCommand& command);

    // What a frame shows.
    const ViewState& state() const { return m_state; }
    const gl::ViewOptions& display() const { return m_display; }
    bool editing() const { return m_editor.has_value(); }
    const MapEditor* editor() const { return m_editor ? &*m_editor : nullptr; }
    const Document* current() const { return m_docs.empty() ? nullptr : &m_docs[m_current]; }
    // The file the renderer shows: the current document's, or the editor's source with its map.
    std::optional<format::ConusFile> shownFile() const;
    // Change counters: the renderer uploads the image (or only the map) again when they move.
    int imageVersion() const { return m_imageVersion; }
    int mapVersion() const { return m_mapVersion; }
    // The renderer could not show the current document (too large for its textures, say).
    void cannotDisplay(const std::string& error);
    bool showHelp() const { return m_showHelp; }
    bool showStatus() const { return m_showStatus; }
    std::string title() const;
    std::string statusText() const;

    // Requests for the loop.
    std::string takeScreenshotRequest();
    int& waitFrames() { return m_waitFrames; }
    bool quitRequested() const { return m_quit; }
    int exitCode() const { return m_exitCode; }
    void failed() { m_exitCode = std::max(m_exitCode, 1); }

private:
    void showDocument(int index, bool refit);
    Document* currentDocument() { return m_docs.empty() ? nullptr : &m_docs[m_current]; }
    std::string summary(const char* separator) const;  // the title's and the status bar's text
    void saveFromEditor(bool mapOnly);

    const Options& m_options;
    std::vector<Document> m_docs;
    int m_current = 0;
    std::optional<MapEditor> m_editor;
    std::string m_editorMessage;
    ViewState m_state;
    gl::ViewOptions m_display;
    glm::dvec2 m_cursor{0.0};
    bool m_panning = false, m_wiping = false;
    std::string m_probe;
    bool m_showHelp = false, m_showStatus = false;
    int m_imageVersion = 0, m_mapVersion = 0;
    std::string m_screenshot;
    int m_waitFrames = 0;
    bool m_quit = false;
    int m_exitCode = 0;
};

}  // namespace conus::viewer
