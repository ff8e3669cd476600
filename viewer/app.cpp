// The loop of conus-view: the window's events into the controller, a frame of the drawing, the
// title, and the requests of scripts (commands, waits, screenshots) and --benchmark-frames.
#include "app.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "controller.h"
#include "conus/imageio/image_file.h"
#include "drawing.h"
#include "scene.h"
#include "script.h"
#include "window.h"

namespace conus::viewer {
namespace {

constexpr int kBenchmarkWarmup = 3;

class Loop {
public:
    Loop(const Options& options, std::vector<ScriptCommand> script)
        : m_options(options), m_script(std::move(script)), m_controller(options) {}

    int run() {
        try {
            const bool flatOut = !m_options.script.empty() || m_options.benchmarkFrames > 0;
            m_window = std::make_unique<Window>(m_options.windowWidth, m_options.windowHeight, !flatOut, m_controller);
            m_drawing = std::make_unique<Drawing>(m_window->context());
            if (m_options.sceneKind != SceneKind::None) {
                m_scene = openScene(m_options, m_window->context());
                m_drawing->setScene(m_scene.get());
            } else if (!m_options.uniform.empty()) {
                m_drawing->setUniform(m_options.files.front(), uniformBaseline(m_options.uniform));
            }
        } catch (const std::exception& e) {
            std::fprintf(stderr, "conus-view: %s\n", e.what());
            return 1;
        }
        const auto [fw, fh] = m_window->framebufferSize();
        m_controller.setWindowSize(fw, fh);
        if (m_scene) m_controller.startScene(m_scene->centre(), m_scene->radius(), m_scene->name(), m_scene->throughMap(), m_scene->look(),
                                           m_scene->home());
        if (!m_controller.load()) return 1;
        if (m_options.benchmarkFrames > 0) return m_scene ? benchmarkScene() : benchmark();
        const bool scripted = !m_script.empty() || !m_options.script.empty();
        while (!m_window->shouldClose() && !m_controller.quitRequested()) {
            const MapEditor* editor = m_controller.editor();
            if (scripted || (editor && !editor->stable())) m_window->poll();
            else m_window->wait(0.5);  // idle: no frames burnt
            if (scripted) {
                if (m_controller.waitFrames() > 0) {
                    --m_controller.waitFrames();
                } else if (m_next < m_script.size()) {
                    m_controller.run(m_script[m_next++]);
                } else {
                    frame();  // the last command's frame has been shown; one more, then leave
                    break;
                }
            }
            frame();
        }
        return m_controller.exitCode();
    }

private:
    void frame() {
        const auto [fw, fh] = m_window->framebufferSize();
        m_controller.setWindowSize(fw, fh);
        m_controller.tick();
        m_drawing->frame(m_controller, fw, fh);
        if (const std::string path = m_controller.takeScreenshotRequest(); !path.empty()) {
            // The back buffer, before the swap (the front buffer reads as zeros under Xvfb).
            try {
                imageio::WriteOptions write;
                write.meaning = imageio::PixelMeaning::Display;  // the framebuffer: already what the screen shows
                imageio::writeImageFile(path, m_drawing->readFramebuffer(fw, fh), write);
                std::printf("wrote %s\n", path.c_str());
            } catch (const std::exception& e) {
                std::fprintf(stderr, "conus-view: %s\n", e.what());
                m_controller.failed();
            }
            std::fflush(stdout);
        }
        updateTitle();
        m_window->swap();
    }

    void updateTitle() {
        std::string title = m_controller.title();
        if (title == m_title) return;
        m_title = std::move(title);
        m_window->setTitle(m_title);
    }

    int benchmark() {
        // --script with --benchmark-frames: the commands set up the view (a key, a zoom), then the timing.
        for (const ScriptCommand& command : m_script) {
            if (command.name == "quit") break;
            m_controller.run(command);
            frame();
        }
        for (int k = 0; k < kBenchmarkWarmup; ++k) frame();
        renderers::ViewRenderer& renderer = m_drawing->renderer();
        renderer.finish();
        const auto [fw, fh] = m_window->framebufferSize();
        const int frames = m_options.benchmarkFrames;
        const auto start = std::chrono::steady_clock::now();
        double drawSeconds = 0;
        for (int k = 0; k < frames; ++k) {
            // A new view every frame (a one-pixel pan back and forth): each frame is decoded afresh.
            m_controller.run({"pan", {k % 2 ? -1.0 : 1.0, 0.0}, "", 0});
            // The draw alone (finished), then the whole frame with the swap.
            const auto drawStart = std::chrono::steady_clock::now();
            renderer.draw(m_controller.state().view(), fw, fh, m_controller.display());
            renderer.finish();
            drawSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - drawStart).count();
            m_window->swap();
            m_window->poll();
        }
        renderer.finish();
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        const int n = std::max(1, frames);
        std::printf("benchmark: draw %.1f ms/frame, present (swap to the X server) %.1f ms/frame\n", 1000.0 * drawSeconds / n,
                    1000.0 * (seconds - drawSeconds) / n);
        const Document* doc = m_controller.current();
        std::printf("benchmark: %d frames at %dx%d (%s, %dx%d CoNUS image, %s mode, %s decode): %.2f frames/s, %.1f ms/frame; %s\n",
                    frames, fw, fh, doc ? std::filesystem::path(doc->path).filename().string().c_str() : "-",
                    doc && doc->ok() ? doc->file->image.width : 0, doc && doc->ok() ? doc->file->image.height : 0,
                    enumName(m_controller.display().mode), renderer.decodesOnCpu(m_controller.display(), m_controller.state().view(), fw) ? "CPU" : "GPU",
                    frames / seconds, 1000.0 * seconds / n, m_window->context().renderer().c_str());
        return m_controller.exitCode();
    }

    // The 3-D modes: every frame a new camera (one degree of orbit, back and forth), so every frame
    // renders the scene, uploads the CoNUS frame and draws it.
    int benchmarkScene() {
        for (const ScriptCommand& command : m_script) {
            if (command.name == "quit") break;
            m_controller.run(command);
            frame();
        }
        for (int k = 0; k < kBenchmarkWarmup; ++k) {
            m_controller.run({"orbit", {k % 2 ? -1.0 : 1.0, 0.0}, "", 0});
            frame();
        }
        m_drawing->renderer().finish();
        const int frames = m_options.benchmarkFrames, rendersBefore = m_drawing->sceneRenders();
        const double renderBefore = m_drawing->sceneSeconds();
        const auto start = std::chrono::steady_clock::now();
        for (int k = 0; k < frames; ++k) {
            m_controller.run({"orbit", {k % 2 ? -1.0 : 1.0, 0.0}, "", 0});
            frame();
            m_window->poll();
        }
        m_drawing->renderer().finish();
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        const int renders = std::max(1, m_drawing->sceneRenders() - rendersBefore);
        const glm::ivec2 size = m_controller.sceneFrameSize();
        const SceneState& state = *m_controller.scene();
        std::printf("benchmark: render (scene to CoNUS image, read back) %.1f ms/frame, the rest (upload, draw, swap) %.1f ms/frame\n",
                    1000.0 * (m_drawing->sceneSeconds() - renderBefore) / renders,
                    1000.0 * (seconds - (m_drawing->sceneSeconds() - renderBefore)) / std::max(1, frames));
        std::printf("benchmark: %d frames of %s, %dx%d %s frame (%zu foci), window %dx%d: %.2f frames/s, %.1f ms/frame; %s\n",
                    frames, m_scene->name().c_str(), size.x, size.y, state.conus() ? "CoNUS" : "conventional", state.foci().size(),
                    m_controller.state().windowWidth(), m_controller.state().windowHeight(), frames / seconds,
                    1000.0 * seconds / std::max(1, frames), m_window->context().renderer().c_str());
        return m_controller.exitCode();
    }

    const Options& m_options;
    std::vector<ScriptCommand> m_script;
    std::size_t m_next = 0;
    Controller m_controller;
    std::unique_ptr<Window> m_window;
    std::unique_ptr<Scene> m_scene;      // GL objects of the window's context: destroyed before it
    std::unique_ptr<Drawing> m_drawing;  // destroyed before the window (it deletes GL objects)
    std::string m_title;
};

}  // namespace

int runWindow(const Options& options) {
    std::vector<ScriptCommand> script;
    if (!options.script.empty()) {
        try {
            script = readScript(options.script);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "conus-view: %s\n", e.what());
            return 2;
        }
    }
    Loop loop(options, std::move(script));
    return loop.run();
}

}  // namespace conus::viewer
