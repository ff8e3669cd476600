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
#include "scene_state.h"
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
    void key(const KeyChord& chord) override { doAction(actionFor(chord, keyTable())); }
    void doAction(Action action);
    void run(const ScriptCommand& command);

    // What a frame shows.
    const ViewState& state() const { return m_state; }
    const renderers::ViewOptions& display() const { return m_display; }
    bool editing() const { return m_editor.has_value(); }
    KeyTable keyTable() const { return m_scene ? KeyTable::Scene : editing() ? KeyTable::Edit : KeyTable::View; }

    // The 3-D modes (scene_state.h, scene.h): the window opened the scene and says what it holds;
    // from then on the controller orbits, drags foci and toggles, and the drawing renders a frame
    // whenever sceneVersion() moves and hands it back with setSceneFrame.
    void startScene(glm::dvec3 centre, double radius, std::string name, bool throughMap, std::string look,
                    std::optional<Orbit> home = std::nullopt);
    const SceneState* scene() const { return m_scene ? &*m_scene : nullptr; }
    bool sceneThroughMap() const { return m_sceneThroughMap; }
    int sceneVersion() const { return m_scene ? m_scene->version() : 0; }
    // The frame's size: --size, else the window's.
    glm::ivec2 sceneFrameSize() const;
    // T pressed this many times: the drawing asks the scene for its next look and reports it.
    int lookRequests() const { return m_lookRequests; }
    void setLook(std::string look);
    // The frame just rendered (a CoNUS file: the image, its map and foci, the camera and, when the
    // renderer gave Z, its depth), shown from now on and probed by the inspector.
    void setSceneFrame(format::ConusFile frame);
    const format::ConusFile* sceneFrame() const { return m_sceneFrame ? &*m_sceneFrame : nullptr; }
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
    // Z: the current document's Z channel shown as a picture (depth_view.h) instead of its colour.
    bool depthPicture() const { return m_depthPicture; }
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
    bool sceneAction(Action action);
    // The inspector's line for window pixel `pixel` (the current document or the scene's frame).
    std::string probeAt(glm::dvec2 pixel) const;

    const Options& m_options;
    std::vector<Document> m_docs;
    int m_current = 0;
    std::optional<MapEditor> m_editor;
    std::optional<SceneState> m_scene;
    std::string m_sceneName, m_sceneLook;
    bool m_sceneThroughMap = true;
    std::optional<format::ConusFile> m_sceneFrame;
    std::optional<codec::SamplingMap> m_sceneMap;
    int m_lookRequests = 0;
    int m_draggedFocus = -1;
    bool m_orbiting = false;
    std::string m_editorMessage;
    ViewState m_state;
    renderers::ViewOptions m_display;
    glm::dvec2 m_cursor{0.0};
    bool m_panning = false, m_wiping = false;
    std::string m_probe;
    bool m_showHelp = false, m_showStatus = false;
    bool m_depthPicture = false;
    int m_imageVersion = 0, m_mapVersion = 0;
    std::string m_screenshot;
    int m_waitFrames = 0;
    bool m_quit = false;
    int m_exitCode = 0;
};

}  // namespace conus::viewer
